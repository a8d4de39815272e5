#include "theorem1.hpp"

#include "plate/progress.hpp"

#include "plate/dynamics.hpp"
#include "plate/random_scene.hpp"

#include <boost/numeric/odeint.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <exception>
#include <chrono>
#include <limits>
#include <mutex>
#include <sstream>
#include <thread>
#include <cmath>

namespace plate::proofs {

namespace {

namespace odeint = boost::numeric::odeint;
using Pair = std::array<double, 6>;

}   // namespace

ContractionCase contraction_case(const Scene& sc, const Vec3& q0, const Vec3& xi_a, const Vec3& xi_b, int periods, double rtol) {
    ContractionCase out;
    const double v = sc.v_ref(), rho = sc.part.rho(), T = sc.plate.T;
    const Vec3 scale(v, v, v / rho);   // state scaling: errors relative to the slip-speed scale
    const Vec3 S(1, 1, rho);           // the Appendix's scaled twist: (v_x, v_y, rho omega)
    Workspace wa, wb;
    auto sys = [&](const Pair& y, Pair& dy, double t) {
        const PlateState ps = plate_state(sc.plate, t, Dynamics::ReducedU);
        const Vec3 a(y[0] * scale[0], y[1] * scale[1], y[2] * scale[2]);
        const Vec3 b(y[3] * scale[0], y[4] * scale[1], y[5] * scale[2]);
        accelerations(sc, Dynamics::ReducedU, q0, a, ps, wa);
        accelerations(sc, Dynamics::ReducedU, q0, b, ps, wb);
        for (int i = 0; i < 3; ++i) {
            dy[i] = wa.qdd[i] / scale[i];
            dy[3 + i] = wb.qdd[i] / scale[i];
        }
    };
    auto V = [&](const Pair& y) {
        double s = 0;
        for (int i = 0; i < 3; ++i) {
            const double d = (y[3 + i] - y[i]) * scale[i] * S[i];
            s += d * d;
        }
        return 0.5 * s;
    };
    auto ctrl = odeint::make_controlled<odeint::runge_kutta_dopri5<Pair>>(rtol, rtol);
    Pair y{xi_a[0] / scale[0], xi_a[1] / scale[1], xi_a[2] / scale[2],
           xi_b[0] / scale[0], xi_b[1] / scale[1], xi_b[2] / scale[2]};
    Pair dydt, y1, dydt1;
    double t = 0, dt = 1e-4 * T;
    sys(y, dydt, t);
    out.V0 = V(y);
    out.V_periods.push_back(out.V0);
    double worst = -HUGE_VAL;
    const double eps_slip = 1e-6 * v;
    // Until |xi_rel| has fallen by 1e6 (V by 1e12), at most `periods` periods.
    for (int k = 1; k <= periods && out.V_periods.back() > 1e-12 * out.V0; ++k) {
        const double t_end = k * T;
        long guard = 0;
        while (t < t_end) {
            if (++guard > 2'000'000 || dt < 1e-13 * T) {
                out.why_invalid = "step size collapsed";
                return out;
            }
            double h = std::min(dt, t_end - t);
            double tt = t;
            if (ctrl.try_step(sys, y, dydt, tt, y1, dydt1, h) == odeint::fail) {
                dt = h;
                continue;
            }
            if (t_end - tt < 1e-14 * T) tt = t_end;
            dt = std::max(h, 1e-12 * T);
            // The model's assumptions at the new point (the last evaluation was there).
            sys(y1, dydt1, tt);
            if (std::min(wa.n.minCoeff(), wb.n.minCoeff()) < 0) {
                out.why_invalid = "contact lost";
                return out;
            }
            for (int i = 0; i < 3; ++i)
                if (wa.slip[i].norm() < eps_slip || wb.slip[i].norm() < eps_slip) {
                    out.why_invalid = "a contact reached zero slip";
                    return out;
                }
            const double Vn = V(y1), Vo = V(y);
            double xmax = 0, rel = 0;
            for (int i = 0; i < 6; ++i) xmax = std::max(xmax, std::abs(y1[i]) * scale[i % 3] * S[i % 3]);
            for (int i = 0; i < 3; ++i) rel += std::pow((y1[3 + i] - y1[i]) * scale[i] * S[i], 2);
            const double delta = rtol * (v + xmax);
            const double bound = std::sqrt(rel) * 2 * std::sqrt(3.0) * delta + 6 * delta * delta;
            worst = std::max(worst, (Vn - Vo) / bound);
            y = y1;
            dydt = dydt1;
            t = tt;
        }
        out.V_periods.push_back(V(y));
    }
    out.valid = true;
    out.V_end = out.V_periods.back();
    out.worst_increase = worst;
    out.monotone = worst <= 1;
    out.converged = out.V_end <= 1e-12 * out.V0;
    // Contraction of |xi_rel| per period, up to the period where V reaches 1e-16 V0 (noise).
    int k = 1;
    while (k + 1 < static_cast<int>(out.V_periods.size()) && out.V_periods[k] > 1e-16 * out.V0) ++k;
    out.rate = std::pow(std::sqrt(out.V_periods[k] / out.V0), 1.0 / k);
    return out;
}

double floquet_radius(const Scene& sc, const Vec3& q0, const Vec3& x0, double rtol) {
    IntegrationOptions io;
    io.rtol = rtol;
    const double v = sc.v_ref();
    const Vec3 h(1e-5 * v, 1e-5 * v, 1e-5 * v / sc.part.rho());
    const int dim = sc.part.point ? 2 : 3;
    Mat3 J = Mat3::Identity();
    for (int c = 0; c < dim; ++c) {
        Vec3 p = x0, m = x0, Pp, Pm;
        p[c] += h[c];
        m[c] -= h[c];
        if (!period_map(sc, q0, p, Pp, io) || !period_map(sc, q0, m, Pm, io)) return std::nan("");
        J.col(c) = (Pp - Pm) / (2 * h[c]);
    }
    // In scaled coordinates (similar to J: same eigenvalues).
    return Eigen::EigenSolver<Mat3>(J.topLeftCorner(3, 3)).eigenvalues().head(dim).cwiseAbs().maxCoeff();
}

// A thin part's statics in the U-dynamics, from the paper: (33)-(34) f~ = m (p'' + w1' x s + g e_z),
// tau~ = J R2^T w1', and the rows sum c_iy N_i = tau~_x, -sum c_ix N_i = tau~_y, sum N_i = f~_z
// (Cramer's rule). Independent of the kernels.
static Vec3 statics_normal_forces(const Scene& sc, const Vec3& q, const PlateState& ps, Vec3& f, Vec3& tau) {
    const Part& P = sc.part;
    const Vec3 s(q[0], q[1], P.s_z());
    f = P.m * (ps.pdd + ps.wd.cross(s) + sc.g * Vec3::UnitZ());
    const Mat3 R2 = Eigen::AngleAxisd(q[2], Vec3::UnitZ()).toRotationMatrix();
    tau = P.J * (R2.transpose() * ps.wd);
    Mat3 M;
    for (int i = 0; i < 3; ++i) M.col(i) = Vec3(P.c[i].y(), -P.c[i].x(), 1);
    const Vec3 rhs(tau.x(), tau.y(), f.z());
    const double det = M.determinant();
    Vec3 Ns;
    for (int i = 0; i < 3; ++i) {
        Mat3 Mi = M;
        Mi.col(i) = rhs;
        Ns[i] = Mi.determinant() / det;
    }
    return Ns;
}

double FrictionSet::support_sampled(const Vec3& d, int angles) const {
    double h = 0;
    for (int i = 0; i < 3; ++i) {
        double best = 0;
        for (int k = 0; k < angles; ++k) {
            const double a = 2 * kPi * k / angles;
            const Vec2 f(cap[i] * std::cos(a), cap[i] * std::sin(a));
            const Vec3 w(f.x(), f.y(), (r[i].x() * f.y() - r[i].y() * f.x()) / rho);   // G_i f
            best = std::max(best, d.dot(w));
        }
        h += best;
    }
    return h;
}

FrictionSet thin_friction_set(const Scene& sc, const Vec3& q0, double t) {
    FrictionSet fs;
    Vec3 f, tau;
    const Vec3 N = statics_normal_forces(sc, q0, plate_state(sc.plate, t, Dynamics::U), f, tau);
    const Mat3 R2 = Eigen::AngleAxisd(q0[2], Vec3::UnitZ()).toRotationMatrix();
    for (int i = 0; i < 3; ++i) {
        fs.r[i] = (R2 * sc.part.c[i]).head<2>();
        fs.cap[i] = sc.part.friction().kinetic(i) * std::max(N[i], 0.0);
    }
    fs.rho = sc.part.rho();
    return fs;
}

DynamicsUnderTest production_dynamics() {
    return [](const Scene& sc, const Vec3& q, const Vec3& qd, const PlateState& ps, Vec3& qdd, Vec3& n) {
        Workspace ws;   // per call: a workspace caches its scene by address, and scenes come and go
        accelerations(sc, Dynamics::U, q, qd, ps, ws);
        qdd = ws.qdd;
        n = ws.n;
    };
}

void DynamicsTie::merge(const DynamicsTie& o) {
    samples += o.samples;
    worst_statics = std::max(worst_statics, o.worst_statics);
    worst_wrench = std::max(worst_wrench, o.worst_wrench);
    if (failure.empty()) failure = o.failure;
}

DynamicsTie check_dynamics_tie(const Scene& sc, const Vec3& q0, int samples, std::uint64_t seed,
                               const DynamicsUnderTest& dynamics) {
    DynamicsTie t;
    const Part& P = sc.part;
    const double mg = P.m * sc.g, rho = P.rho(), v = sc.v_ref();
    const DynamicsUnderTest dyn = dynamics ? dynamics : production_dynamics();
    Rng r(seed * 2654435761u + 3);
    for (int k = 0; k < samples; ++k) {
        const Vec3 q{q0[0] + r.uniform(-0.005, 0.005), q0[1] + r.uniform(-0.005, 0.005), q0[2] + r.uniform(-0.5, 0.5)};
        const Vec3 qd{r.uniform(-v, v), r.uniform(-v, v), r.uniform(-v, v) / rho};
        const PlateState ps = plate_state(sc.plate, r.uniform(0, sc.plate.T), Dynamics::U);
        Vec3 qdd, n;
        dyn(sc, q, qd, ps, qdd, n);
        Vec3 f, tau;
        const Vec3 Ns = statics_normal_forces(sc, q, ps, f, tau);
        const Mat3 R2 = Eigen::AngleAxisd(q[2], Vec3::UnitZ()).toRotationMatrix();
        // The limit surface (39): the generated thin_wrench with the statics' forces.
        std::array<Vec2, 3> r2;
        for (int i = 0; i < 3; ++i) r2[i] = (R2 * P.c[i]).head<2>();
        const Vec3 w = wrench_map(wrench_input(r2, Ns, P.friction(), rho))(Vec3(qd[0], qd[1], rho * qd[2]));
        const Vec3 W(P.m * qdd[0] + f.x(), P.m * qdd[1] + f.y(), (P.J(2, 2) * qdd[2] + tau.z()) / rho);
        const double es = (n - Ns).cwiseAbs().maxCoeff() / mg;
        const double ew = (W - w).cwiseAbs().maxCoeff() / mg;
        ++t.samples;
        t.worst_statics = std::max(t.worst_statics, es);
        t.worst_wrench = std::max(t.worst_wrench, ew);
        if (!t.failure.empty()) continue;
        std::ostringstream o;
        o.precision(3);
        if (!(es <= kTieTolerance))
            o << "statics: the normal forces differ from an independent solve of the part's statics by " << es << " m g (seed "
              << seed << ", sample " << k << ")";
        else if (!(ew <= kTieTolerance))
            o << "wrench: m q'' + b~ differs from the limit-surface wrench (39) of the relative twist by " << ew << " m g (seed "
              << seed << ", sample " << k << ")";
        t.failure = o.str();
    }
    return t;
}

bool unique_cycle(int reached, int starts, double spread) { return starts > 0 && reached == starts && spread < 1e-6; }

ContractionCase contraction_random_case(const ContractionOptions& opt, int k) {
    const std::uint64_t seed = opt.seed + static_cast<std::uint64_t>(k);
    RandomSceneOptions ro;
    ro.thin = opt.thin;
    Scene sc = random_scene(seed, ro);
    if (opt.modify) opt.modify(sc);
    Rng r(seed * 0x9E3779B97F4A7C15ull + 17);
    const double v = sc.v_ref(), w = v / sc.part.rho();
    const Vec3 q0{r.uniform(-0.02, 0.02), r.uniform(-0.02, 0.02), r.uniform(-kPi, kPi)};
    auto twist = [&] { return Vec3{r.uniform(-v, v), r.uniform(-v, v), r.uniform(-w, w)}; };
    const Vec3 a = twist(), b = twist();
    ContractionCase c = contraction_case(sc, q0, a, b, opt.periods, opt.rtol);
    c.seed = seed;
    if (sc.part.thin()) c.tie = check_dynamics_tie(sc, q0, opt.tie_samples, seed, opt.dynamics);
    if (!c.valid) return c;
    LimitCycleOptions lo;
    lo.integration.rtol = opt.rtol;
    lo.tol = 1e-9;
    lo.restarts = 0;
    const LimitCycleSummary lc = limit_cycle(sc, q0, lo, a);
    if (!lc.converged) {   // no attracting cycle: a counter-example to Observation 1, not a skip
        c.spectral_radius = std::numeric_limits<double>::quiet_NaN();
        c.why_invalid = "limit cycle: " + (lc.stop.reason != StopReason::None ? lc.stop.describe() : "not converged");
        return c;
    }
    c.spectral_radius = floquet_radius(sc, q0, lc.qd_start, opt.rtol);
    // Observation 1 from further initial twists: every cycle start within 1e-6 v_ref (each is
    // within its error estimate <= 1e-9 v_ref of the cycle, plus integration error).
    // A further start whose transient leaves the model (a contact sticks or lifts before the
    // cycle is reached) says nothing about the cycle: it is replaced by another, up to 3x.
    c.unique = true;
    const Vec3 scale(v, v, w);
    int& reached = c.starts_reached;
    for (int k = 0; k < 3 * opt.starts && reached < opt.starts; ++k) {
        const LimitCycleSummary o = limit_cycle(sc, q0, lo, twist());
        if (!o.converged) {
            if (o.stop.reason == StopReason::Sticking || o.stop.reason == StopReason::ContactLost) {
                ++c.starts_left_model;
                continue;
            }
            c.unique = false;   // ran to the period cap: no attracting cycle from there
            c.cycle_spread = std::numeric_limits<double>::infinity();
            break;
        }
        ++reached;
        c.cycle_spread = std::max(c.cycle_spread, ((o.qd_start - lc.qd_start).array() / scale.array()).abs().maxCoeff());
    }
    c.unique = c.unique && unique_cycle(reached, opt.starts, c.cycle_spread);
    return c;
}

ContractionSummary check_contraction(const ContractionOptions& opt) {
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<ContractionCase> cases(opt.cases);
    std::atomic<int> next{0}, done{0};
    std::mutex progress_mutex;
    // Every worker polls the caller's stop request (progress.hpp); the first exception (Interrupted)
    // stops the others taking cases and is rethrown once all have joined.
    const StopRequest* const stop = current_stop_request();
    std::exception_ptr failure;
    auto worker = [&] {
        const StopScope scope(stop);
        try {
            for (int k; (k = next.fetch_add(1)) < opt.cases;) {
                cases[k] = contraction_random_case(opt, k);
                const int d = ++done;
                if (opt.progress) {
                    std::lock_guard<std::mutex> lock(progress_mutex);
                    opt.progress(d, opt.cases);
                }
            }
        } catch (...) {
            std::lock_guard<std::mutex> lock(progress_mutex);
            if (!failure) failure = std::current_exception();
            next = opt.cases;
        }
    };
    int threads = opt.threads > 0 ? opt.threads : static_cast<int>(std::thread::hardware_concurrency());
    threads = std::max(1, std::min(threads, opt.cases));
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back(worker);
    worker();
    for (auto& t : pool) t.join();
    if (failure) std::rethrow_exception(failure);
    return summarize_contraction(opt, std::move(cases),
                                 std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

ContractionSummary summarize_contraction(const ContractionOptions& opt, std::vector<ContractionCase> cases, double seconds) {
    ContractionSummary s;
    std::vector<double> rates;
    for (auto& c : cases) {
        ++s.cases;
        if (c.valid) {
            ++s.valid;
            s.monotone += c.monotone;
            s.converged += c.converged;
            s.unique += c.unique;
            s.floquet_below_one += c.spectral_radius < 1;
            s.worst_V_end = std::max(s.worst_V_end, c.V0 > 0 ? c.V_end / c.V0 : 0.0);
            s.max_cycle_spread = std::max(s.max_cycle_spread, c.cycle_spread);
            s.starts_left_model += c.starts_left_model;
            if (s.valid == 1 || c.worst_increase > s.worst_increase) {
                s.worst_increase = c.worst_increase;
                s.worst_seed = c.seed;
            }
            rates.push_back(c.rate);
            s.max_rate = std::max(s.max_rate, c.rate);
            s.max_spectral_radius = std::max(s.max_spectral_radius, c.spectral_radius);
            if (!(c.monotone && c.converged && c.unique && c.spectral_radius < 1)) s.counterexamples.push_back(c.seed);
        }
        s.tie.merge(c.tie);   // every case, valid or not: the dynamics are checked where they are defined
    }
    s.tie_required = opt.thin;
    s.details = std::move(cases);
    if (!rates.empty()) {
        std::sort(rates.begin(), rates.end());
        s.median_rate = rates[rates.size() / 2];
    }
    s.seconds = seconds;
    return s;
}

LimitSurfaceResult check_limit_surface(const WrenchMap& wmap, double scale, int directions, double separation,
                                       const FrictionSet* set) {
    LimitSurfaceResult r;
    r.directions = directions;
    std::vector<Vec3> xi(directions), w(directions);
    const double golden = kPi * (3 - std::sqrt(5.0));
    for (int k = 0; k < directions; ++k) {
        const double z = 1 - (2 * k + 1.0) / directions, rad = std::sqrt(1 - z * z), a = golden * k;
        xi[k] = Vec3(rad * std::cos(a), rad * std::sin(a), z);
        w[k] = wmap(xi[k]);
    }
    r.min_separation = 1e300;
    r.min_strict_margin = 1e300;
    // Against the independent friction set: h_s(-xi_i), each disk's rim at 720 points.
    constexpr int kAngles = 720;
    std::vector<double> hs(directions, 0.0);
    if (set) {
        r.set_checked = true;
        for (int i = 0; i < directions; ++i) {
            hs[i] = set->support_sampled(-xi[i], kAngles);
            r.support_margin = std::min(r.support_margin, ((-xi[i]).dot(w[i]) - hs[i]) / scale);
        }
    }
    const double outer = 1 / std::cos(kPi / kAngles);
    for (int i = 0; i < directions; ++i)
        for (int j = 0; j < directions; ++j) {
            if (i == j) continue;
            ++r.pairs;
            r.max_work_margin = std::min(r.max_work_margin, (xi[i].dot(w[j]) - xi[i].dot(w[i])) / scale);
            if (set) r.outside_margin = std::min(r.outside_margin, (hs[i] * outer - (-xi[i]).dot(w[j])) / scale);
            if ((xi[i] - xi[j]).norm() > separation)
                r.min_strict_margin = std::min(r.min_strict_margin, (xi[i].dot(w[j]) - xi[i].dot(w[i])) / scale);
            if (j > i) {
                r.monotonicity_margin = std::min(r.monotonicity_margin, -(xi[i] - xi[j]).dot(w[i] - w[j]) / scale);
                if ((xi[i] - xi[j]).norm() > separation)
                    r.min_separation = std::min(r.min_separation, (w[i] - w[j]).norm() / scale);
            }
        }
    return r;
}

WrenchMap thin_wrench_map(const Scene& sc, const Vec3& q0, double t, double* friction_scale) {
    Workspace ws;
    accelerations(sc, Dynamics::ReducedU, q0, Vec3(0.1, 0.05, 1), plate_state(sc.plate, t, Dynamics::ReducedU), ws);
    if (friction_scale) *friction_scale = sc.part.friction().kinetic().dot(ws.n);
    return wrench_map(wrench_input(ws.r, ws.n, sc.part.friction(), sc.part.rho()));
}

WrenchMap wrench_map(gen::WrenchInput in) {
    return [in](const Vec3& xi) mutable {
        in.vx = xi[0];
        in.vy = xi[1];
        in.xith = xi[2];
        double w[3];
        gen::thin_wrench(in, w);
        return Vec3(w[0], w[1], w[2]);
    };
}

LimitSurfaceCampaign check_limit_surfaces(int parts, std::uint64_t seed, const DynamicsUnderTest& dynamics) {
    LimitSurfaceCampaign c;
    c.parts = parts;
    c.min_separation = c.min_strict_margin = parts > 0 ? 1e300 : 0;
    c.max_work_margin = c.monotonicity_margin = c.support_margin = c.outside_margin = parts > 0 ? 1e300 : 0;
    Rng r(seed + 7);
    for (int k = 0; k < parts; ++k) {
        const Scene sc = random_scene(seed + 90'000'000 + static_cast<std::uint64_t>(k), RandomSceneOptions{true});
        double scale = 0;
        const Vec3 q0{r.uniform(-0.02, 0.02), r.uniform(-0.02, 0.02), r.uniform(-kPi, kPi)};
        const double t = r.uniform(0, sc.plate.T);
        const WrenchMap w = thin_wrench_map(sc, q0, t, &scale);
        c.tie.merge(check_dynamics_tie(sc, q0, 10, seed + 90'000'000 + static_cast<std::uint64_t>(k), dynamics));
        const FrictionSet set = thin_friction_set(sc, q0, t);
        const LimitSurfaceResult lr = check_limit_surface(w, scale, 300, 0.2, &set);
        c.convex += lr.convex_and_normal();
        c.on_set += lr.on_friction_set();
        c.support_margin = std::min(c.support_margin, lr.support_margin);
        c.outside_margin = std::min(c.outside_margin, lr.outside_margin);
        c.strict += lr.strictly_convex();
        c.max_work_margin = std::min(c.max_work_margin, lr.max_work_margin);
        c.monotonicity_margin = std::min(c.monotonicity_margin, lr.monotonicity_margin);
        c.min_separation = std::min(c.min_separation, lr.min_separation);
        c.min_strict_margin = std::min(c.min_strict_margin, lr.min_strict_margin);
    }
    return c;
}

Conditioning condition_of_A(const Scene& sc, int samples, std::uint64_t seed) {
    Conditioning c;
    c.min_singular = 1e300;
    Rng r(seed);
    const double m = sc.part.m, g = sc.g, rho = sc.part.rho();
    // Dimensionless A: unknowns in units (g, g, g/rho, m g, m g, m g), rows in (m g, m g, m g, m g rho x3).
    Vec6 Dz, De;
    Dz << g, g, g / rho, m * g, m * g, m * g;
    De << m * g, m * g, m * g, m * g * rho, m * g * rho, m * g * rho;
    Workspace ws;
    for (int k = 0; k < samples; ++k) {
        const Vec3 q{r.uniform(-0.02, 0.02), r.uniform(-0.02, 0.02), r.uniform(-kPi, kPi)};
        const Vec3 qd{r.uniform(-1, 1), r.uniform(-1, 1), r.uniform(-30, 30)};
        accelerations_reference(sc, Dynamics::U, q, qd, PlateState{}, ws);
        const Mat6 As = De.cwiseInverse().asDiagonal() * ws.A * Dz.asDiagonal();
        const Vec6 sv = Eigen::JacobiSVD<Mat6>(As).singularValues();
        c.max_condition = std::max(c.max_condition, sv[0] / sv[5]);
        c.min_singular = std::min(c.min_singular, sv[5] / sv[0]);
    }
    return c;
}

std::vector<CollinearScene> collinear_scenes(const std::vector<double>& ratios) {
    std::vector<CollinearScene> out;
    for (double e : ratios) {
        CollinearScene c;
        c.e_over_L = e;
        c.scene = random_scene(3, RandomSceneOptions{true});
        const double L = 0.03;
        c.scene.part.c = {Vec3(-L, -e * L / 3, 0), Vec3(L, -e * L / 3, 0), Vec3(0, 2 * e * L / 3, 0)};
        out.push_back(c);
    }
    return out;
}

}   // namespace plate::proofs
