#include "plate/study.hpp"

#include "engine.hpp"
#include "models.hpp"

#include "plate/field.hpp"
#include "plate/random_scene.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <sstream>

namespace plate {

std::string Solver::label() const {
    if (engine) return "engine: dopri5 + events";
    std::ostringstream s;
    s << method_info(method).name;
    if (law != FrictionLaw::Coulomb) s << " / " << friction_law_name(law) << " " << law_eps;
    return s.str();
}

std::vector<Solver> study_solvers(bool full) {
    std::vector<Solver> out;
    Solver e;
    e.engine = true;
    out.push_back(e);
    for (const auto& m : all_methods()) {
        Solver s;
        s.method = m.method;
        out.push_back(s);
    }
    const std::vector<Method> regularised =
        full ? std::vector<Method>{Method::Dopri5, Method::Fehlberg78, Method::Rosenbrock4, Method::GslMsbdf}
             : std::vector<Method>{Method::Dopri5, Method::Rosenbrock4};
    for (Method m : regularised)
        for (FrictionLaw law : {FrictionLaw::Tanh, FrictionLaw::Linear})
            for (double eps : full ? std::vector<double>{1e-2, 1e-3, 1e-4} : std::vector<double>{1e-3}) {
                Solver s;
                s.method = m;
                s.law = law;
                s.law_eps = eps;
                out.push_back(s);
            }
    return out;
}

std::vector<double> study_knobs(const Solver& s, bool full) {
    std::vector<double> k;
    if (!s.engine && s.method == Method::RK4) {
        for (double n = 50; n <= (full ? 51200 : 12800); n *= 2) k.push_back(n);
        return k;
    }
    for (double t = 1e-3; t >= (full ? 1e-12 : 1e-11) * 0.999; t /= full ? std::sqrt(10.0) : 10) k.push_back(t);
    return k;
}

namespace {

using Clock = std::chrono::steady_clock;

// A model wrapped as an OdeSystem in scaled coordinates, watching the normal forces (the general
// methods do not: a contact loss they integrate through is found here and reported as a failure).
template <class Model>
struct Wrapped {
    Model model;
    typename Model::State scale{};
    double min_n = std::numeric_limits<double>::infinity();
    int contacts = 1;
    template <class... A>
    explicit Wrapped(const Scene& sc, A&&... a) : model(sc, std::forward<A>(a)...) {
        scale = model.scale();
        contacts = sc.part.contacts();
    }
    void f(double t, const double* ys, double* dys) {
        typename Model::State y, dy;
        for (std::size_t i = 0; i < y.size(); ++i) y[i] = ys[i] * scale[i];
        model.rhs(t, y, dy);
        for (std::size_t i = 0; i < y.size(); ++i) dys[i] = dy[i] / scale[i];
        min_n = std::min(min_n, model.ws.n.head(contacts).minCoeff());
    }
    // Forward differences, for the models without a generated Jacobian (full dynamics).
    void fd_jacobian(double t, const double* ys, double* J, double* dfdt, double T) {
        const int n = static_cast<int>(scale.size());
        std::vector<double> f0(n), f1(n), y(ys, ys + n);
        f(t, ys, f0.data());
        for (int j = 0; j < n; ++j) {
            const double h = 1e-7 * std::max(1.0, std::abs(y[j]));
            y[j] += h;
            f(t, y.data(), f1.data());
            y[j] = ys[j];
            for (int i = 0; i < n; ++i) J[i * n + j] = (f1[i] - f0[i]) / h;
        }
        const double ht = 1e-7 * T;
        f(t + ht, ys, f1.data());
        for (int i = 0; i < n; ++i) dfdt[i] = (f1[i] - f0[i]) / ht;
    }
};

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

MethodOptions method_options(const Solver& s, double knob, double T, long max_evals) {
    MethodOptions mo;
    mo.max_evals = max_evals;
    mo.h_min = 1e-13 * T;
    if (s.method == Method::RK4)
        mo.h = T / knob;
    else {
        mo.tol = knob;
        mo.h = 1e-3 * T;
    }
    return mo;
}

}   // namespace

namespace {

using ReducedW = Wrapped<detail::ReducedModel>;

OdeSystem reduced_from(const std::shared_ptr<ReducedW>& w, const Scene& sc) {
    OdeSystem sys;
    sys.n = 6;
    sys.f = [w](double t, const double* y, double* f) { w->f(t, y, f); };
    // y = [q'/sv, Q/sQ]: d(q'')/d(q') from the generated factors, dQ'/dq' = identity (scaled).
    sys.jac = [w, &sc](double t, const double* ys, double* J, double* dfdt) {
        const auto& s = w->scale;
        const Vec3 qd(ys[0] * s[0], ys[1] * s[1], ys[2] * s[2]);
        Mat3 Jq;
        twist_jacobian(sc, Dynamics::ReducedU, w->model.q0, qd, plate_state(sc.plate, t, Dynamics::ReducedU), w->model.ws, Jq);
        for (int i = 0; i < 36; ++i) J[i] = 0;
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j) J[i * 6 + j] = Jq(i, j) * s[j] / s[i];
            J[(3 + i) * 6 + i] = s[i] / s[3 + i];
        }
        // d f/d t: the plate's acceleration changes in time; by a central difference of f.
        double fp[6], fm[6];
        const double ht = 1e-6 * sc.plate.T;
        w->f(t + ht, ys, fp);
        w->f(t - ht, ys, fm);
        for (int i = 0; i < 6; ++i) dfdt[i] = (fp[i] - fm[i]) / (2 * ht);
    };
    return sys;
}

// Period by period on the scaled reduced state y = [q'/s, Q/s] (Q reset at each period's start) until
// the contraction estimate r c / (1 - c) is at most cycle_tol (r: the change of q' over a period, in
// v_ref). Returns the periods integrated when converged -- y then holds the last period's end and
// *start its start -- or 0 (run.ok says whether the method failed).
int periods_to_cycle(Method m, const OdeSystem& sys, double T, const MethodOptions& mo, MethodRun& run, double cycle_tol,
                     int max_periods, std::vector<double>& y, Vec3* start = nullptr) {
    Vec3 prev(y[0], y[1], y[2]);
    double r_prev = 0;
    for (int k = 1; k <= max_periods; ++k) {
        y[3] = y[4] = y[5] = 0;
        if (!integrate(m, sys, (k - 1) * T, k * T, y, mo, run)) return 0;
        const Vec3 qd(y[0], y[1], y[2]);   // scaled: relative to v_ref (angular: times rho)
        const double res = (qd - prev).cwiseAbs().maxCoeff();
        const double c = r_prev > 0 ? std::min(res / r_prev, 0.99) : 0.99;
        if (k >= 2 && (res == 0 || (r_prev > 0 && res * c / (1 - c) <= cycle_tol))) {
            if (start) *start = prev;
            return k;
        }
        prev = qd;
        r_prev = res;
    }
    return 0;
}

std::shared_ptr<ReducedW> reduced_wrapped(const Scene& sc, const Vec3& q0, FrictionLaw law, double eps) {
    if (law != FrictionLaw::Coulomb) sc.part.friction().require_single("a regularised friction law");
    auto w = std::make_shared<ReducedW>(sc, q0);
    w->model.ws.law = law;
    w->model.ws.law_eps = eps;
    return w;
}

}   // namespace

OdeSystem reduced_system(const Scene& sc, const Vec3& q0, FrictionLaw law, double eps, std::vector<double>& scale) {
    auto w = reduced_wrapped(sc, q0, law, eps);
    scale.assign(w->scale.begin(), w->scale.end());
    return reduced_from(w, sc);
}

RunResult twist_run(const Scene& sc, const Vec3& q0, const Solver& s, double knob, double cycle_tol, long max_evals) {
    RunResult r;
    r.knob = knob;
    const auto t0 = Clock::now();
    const double T = sc.plate.T;
    if (s.engine) {
        LimitCycleOptions o;
        o.integration.rtol = knob;
        o.tol = cycle_tol;
        o.solver = CycleSolver::PeriodByPeriod;
        const LimitCycleSummary lc = limit_cycle(sc, q0, o);
        r.seconds = seconds_since(t0);
        r.rhs_evals = lc.stats.rhs_evals;
        r.ok = lc.converged;
        if (!r.ok)
            r.failure = lc.stop.reason != StopReason::None ? lc.stop.describe() : "not converged";
        else
            r.value = {lc.twist[0], lc.twist[1], lc.twist[2]};
        return r;
    }
    // The same start and restart rule as the engine's (limit_cycle): from rest, and where the run
    // loses contact (a method integrates through it; the engine stops), again from the same other
    // twists -- slip speed v_ref along x, then y, then a spin (a point part: the diagonal) -- up to
    // LimitCycleOptions::restarts times; contact lost from every start is what is reported.
    const double v = sc.v_ref(), wz = v / sc.part.rho();
    const Vec3 starts[] = {Vec3::Zero(), Vec3(v, 0, 0), Vec3(0, v, 0), sc.part.point ? Vec3(-v, -v, 0) : Vec3(0, 0, wz)};
    const int n_starts = 1 + std::min(LimitCycleOptions{}.restarts, 3);
    const MethodOptions mo = method_options(s, knob, T, max_evals);
    for (int k = 0; k < n_starts; ++k) {
        const auto w = reduced_wrapped(sc, q0, s.law, s.law_eps * sc.v_ref());
        const OdeSystem sys = reduced_from(w, sc);
        MethodRun run;
        std::vector<double> y(6, 0.0);
        for (int i = 0; i < 3; ++i) y[i] = starts[k][i] / w->scale[i];
        r.ok = false;
        r.failure.clear();
        if (periods_to_cycle(s.method, sys, T, mo, run, cycle_tol, 400, y) > 0) {
            r.ok = true;
            r.value = {y[3] * w->scale[3] / T, y[4] * w->scale[4] / T, y[5] * w->scale[5] / T};
        } else if (run.ok) {
            run.failure = "not converged in 400 periods";
        }
        r.rhs_evals += w->model.ws.evals;
        r.jac_evals += run.jac_evals;
        if (!run.ok || !run.failure.empty()) {
            r.ok = false;
            r.failure = run.failure;
        }
        if (r.ok && w->min_n < 0) {
            r.ok = false;
            r.failure = "contact lost (a normal force went negative; the method integrated through it)";
            if (k + 1 < n_starts) continue;   // the engine's rule: start again from another twist
            r.failure += k > 0 ? " from every start" : "";
        }
        break;
    }
    r.seconds = seconds_since(t0);
    return r;
}

RunResult trajectory_run(const Scene& sc, const Vec3& q0, double duration, double sample_dt, const Solver& s, double knob,
                         long max_evals) {
    RunResult r;
    r.knob = knob;
    const auto t0 = Clock::now();
    const double tb = breakaway_time(sc, q0, 0);
    if (std::isnan(tb)) {
        r.failure = "the part never breaks away";
        return r;
    }
    Vec3 p, phi;
    sc.plate.displacement(tb, p, phi);
    const detail::FullModel::State y0{q0[0], q0[1], q0[2], 0, 0, 0, phi[0], phi[1], phi[2]};
    std::vector<double> times;
    for (long k = static_cast<long>(std::floor(tb / sample_dt)) + 1; k * sample_dt < duration - 1e-12; ++k)
        times.push_back(k * sample_dt);
    times.push_back(duration);
    if (s.engine) {
        detail::FullModel model(sc);
        IntegrationOptions io;
        io.rtol = knob;
        detail::Engine<detail::FullModel> e(model, sc, io);
        bool ok = e.start(tb, y0);
        for (double t : times) {
            if (!ok) break;
            ok = e.advance(t, [](double, const auto&, const Vec3&) {});
            if (ok) {
                const auto y = e.y();
                r.value.insert(r.value.end(), {y[0], y[1], y[2]});
            }
        }
        r.ok = ok;
        if (!ok) r.failure = e.stop.describe();
        r.rhs_evals = e.stats.rhs_evals;
        r.seconds = seconds_since(t0);
        return r;
    }
    if (s.law != FrictionLaw::Coulomb) sc.part.friction().require_single("a regularised friction law");
    auto w = std::make_shared<Wrapped<detail::FullModel>>(sc);
    w->model.ws.law = s.law;
    w->model.ws.law_eps = s.law_eps * sc.v_ref();
    OdeSystem sys;
    sys.n = 9;
    sys.f = [w](double t, const double* y, double* f) { w->f(t, y, f); };
    const double T = sc.plate.T;
    // No generated Jacobian for the full dynamics (b depends on the twist there): forward differences.
    sys.jac = [w, T](double t, const double* y, double* J, double* dfdt) { w->fd_jacobian(t, y, J, dfdt, T); };
    const MethodOptions mo = method_options(s, knob, T, max_evals);
    MethodRun run;
    std::vector<double> y(9);
    for (int i = 0; i < 9; ++i) y[i] = y0[i] / w->scale[i];
    double t = tb;
    for (double t1 : times) {
        MethodOptions m1 = mo;
        if (s.method == Method::RK4) m1.h = T / knob;   // the same step, the segment's last one shortened
        if (!integrate(s.method, sys, t, t1, y, m1, run)) break;
        t = t1;
        r.value.insert(r.value.end(), {y[0] * w->scale[0], y[1] * w->scale[1], y[2] * w->scale[2]});
    }
    r.ok = run.ok;
    r.failure = run.failure;
    if (r.ok && w->min_n < 0) {
        r.ok = false;
        r.failure = "contact lost (a normal force went negative; the method integrated through it)";
    }
    r.rhs_evals = w->model.ws.evals;
    r.jac_evals = run.jac_evals;
    r.seconds = seconds_since(t0);
    return r;
}

double twist_error(const Scene& sc, const std::vector<double>& a, const std::vector<double>& b) {
    if (a.size() != 3 || b.size() != 3) return std::numeric_limits<double>::infinity();
    const double v = sc.v_ref(), w = v / sc.part.rho();
    return std::max({std::abs(a[0] - b[0]) / v, std::abs(a[1] - b[1]) / v, std::abs(a[2] - b[2]) / w});
}

double field_max_error(const Scene& sc, const Field& f, const Field& ref, int* missing) {
    double e = 0;
    int miss = 0;
    for (std::size_t i = 0; i < f.points.size(); ++i) {
        if (!ref.points[i].converged) continue;
        if (!f.points[i].converged) {
            ++miss;
            continue;
        }
        const Vec3 d = f.points[i].twist, r = ref.points[i].twist;
        e = std::max(e, twist_error(sc, {d[0], d[1], d[2]}, {r[0], r[1], r[2]}));
    }
    if (missing) *missing = miss;
    return e;
}

void path_error(const Scene& sc, const std::vector<double>& a, const std::vector<double>& b, double& final_error,
                double& max_error) {
    final_error = max_error = std::numeric_limits<double>::infinity();
    if (a.size() != b.size() || a.empty()) return;
    const double rho = sc.part.rho();
    max_error = 0;
    for (std::size_t i = 0; i < a.size(); i += 3) {
        const double e =
            std::max({std::abs(a[i] - b[i]) / rho, std::abs(a[i + 1] - b[i + 1]) / rho, std::abs(a[i + 2] - b[i + 2])});
        max_error = std::max(max_error, e);
        final_error = e;
    }
}

RegularisedReference regularised_reference(const Scene& sc, const Vec3& q0, const RegularisedOptions& opt) {
    RegularisedReference out;
    const auto t0 = Clock::now();
    const double T = sc.plate.T, v = sc.v_ref();
    const Vec3 S(v, v, v / sc.part.rho());   // the twist's scale
    if (opt.eps.size() < 3) {
        out.failure = "the reference needs at least three eps";
        return out;
    }
    Vec3 start = Vec3::Zero();   // the cycle's start (physical), warm start for the next eps
    for (double eps : opt.eps) {
        const auto w = reduced_wrapped(sc, q0, FrictionLaw::Sqrt, eps * v);
        const OdeSystem sys = reduced_from(w, sc);
        MethodOptions mo;
        mo.tol = opt.tol;
        mo.h = 1e-3 * T;
        mo.h_min = 1e-15 * T;
        MethodRun run;
        std::vector<double> y(6, 0.0);
        for (int i = 0; i < 3; ++i) y[i] = start[i] / w->scale[i];
        Vec3 start_scaled;
        const int periods = periods_to_cycle(Method::GslBsimp, sys, T, mo, run, opt.cycle_tol, opt.max_periods, y, &start_scaled);
        const bool done = periods > 0;
        if (done) {
            out.twists.push_back(Vec3(y[3] * w->scale[3], y[4] * w->scale[4], y[5] * w->scale[5]) / T);
            for (int i = 0; i < 3; ++i) start[i] = start_scaled[i] * w->scale[i];
        }
        out.rhs_evals += w->model.ws.evals;
        out.periods.push_back(periods);
        if (!run.ok || !done || w->min_n < 0) {
            std::ostringstream m;
            m << "regularised cycle at eps = " << eps << " v_ref: "
              << (!run.ok        ? run.failure
                  : w->min_n < 0 ? std::string("contact lost")
                                 : std::string("not converged"));
            out.failure = m.str();
            out.seconds = seconds_since(t0);
            return out;
        }
    }
    // Richardson with the observed order on the last triples.
    const std::size_t n = out.twists.size();
    auto limit = [&](std::size_t i, double& p, double& corr) {
        const double r = opt.eps[i] / opt.eps[i + 1];
        const Vec3 d1 = (out.twists[i] - out.twists[i + 1]).cwiseQuotient(S);
        const Vec3 d2 = (out.twists[i + 1] - out.twists[i + 2]).cwiseQuotient(S);
        p = std::log(d1.norm() / d2.norm()) / std::log(r);
        if (!(p > 0.1) || !std::isfinite(p)) p = 0.1;   // no observed convergence: a weak order, a large error
        const Vec3 c = d2 / (std::pow(r, p) - 1);
        corr = c.cwiseAbs().maxCoeff();
        return Vec3(out.twists[i + 2] - c.cwiseProduct(S));
    };
    double p = 0, corr = 0;
    out.twist = limit(n - 3, p, corr);
    out.order = p;
    out.error = corr;
    if (n >= 4) {
        double p0, c0;
        const Vec3 before = limit(n - 4, p0, c0);
        out.error += (out.twist - before).cwiseQuotient(S).cwiseAbs().maxCoeff();
    }
    out.ok = true;
    out.seconds = seconds_since(t0);
    return out;
}

Scene sticking_random_scene(std::uint64_t seed, Vec3& q0, double* ratio) {
    RandomSceneOptions ro;
    ro.point = seed % 3 == 2;
    ro.thin = seed % 3 == 1;
    Scene sc = random_scene(seed, ro);
    Rng r(seed ^ 0x5715C0FFEEull);   // its own stream: the part and motion are random_scene's
    const double mu = sc.part.friction().largest_kinetic();
    const double k = r.uniform(0.05, 1.2);
    const double heave = r.uniform(0.5, 2.5);
    double horizontal = 0;
    for (const Harmonic& h : sc.plate.harmonics)
        if (h.axis == Axis::x || h.axis == Axis::y) horizontal = std::max(horizontal, std::abs(h.amp));
    for (Harmonic& h : sc.plate.harmonics) {
        if (h.axis == Axis::x || h.axis == Axis::y) h.amp *= k * mu * sc.g / horizontal;
        if (h.axis == Axis::z) h.amp *= heave;
    }
    const double rad = r.uniform(0, 0.03), a = r.uniform(0, 2 * kPi);
    q0 = Vec3(rad * std::cos(a), rad * std::sin(a), sc.part.point ? 0.0 : r.uniform(0, 2 * kPi));
    sc.name = "sticking-" + sc.name;
    if (ratio) *ratio = k;
    return sc;
}

RandomStickCase random_stick_case(std::uint64_t seed, const LimitCycleOptions& opt, const RegularisedOptions& ref) {
    RandomStickCase c;
    c.seed = seed;
    c.scene = sticking_random_scene(seed, c.q0, &c.ratio);
    c.cycle = limit_cycle(c.scene, c.q0, opt);
    const LimitCycleSummary& lc = c.cycle;
    if (!lc.converged) {
        c.failure = "engine: " + (lc.stop.reason != StopReason::None ? lc.stop.describe() : std::string("not converged"));
        return c;
    }
    c.held = *std::max_element(lc.stick_fraction.begin(), lc.stick_fraction.end());
    const RegularisedReference r = regularised_reference(c.scene, c.q0, ref);
    c.reference_ok = r.ok;
    if (!r.ok) {
        c.failure = "reference: " + r.failure;
        return c;
    }
    const double v = c.scene.v_ref();
    c.reference_twist = r.twist;
    c.error = (lc.twist - r.twist).cwiseQuotient(Vec3(v, v, v / c.scene.part.rho())).cwiseAbs().maxCoeff();
    c.reference_error = r.error;
    return c;
}

}   // namespace plate
