#include "plate/design.hpp"

#include "plate/random_scene.hpp"

#include <nlopt.hpp>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <complex>
#include <map>
#include <stdexcept>
#include <sstream>
#include <thread>

namespace plate {

// --- exact symmetries ------------------------------------------------------------------------------

PlateMotion rotate_motion(const PlateMotion& u, double a) {
    PlateMotion r;
    r.T = u.T;
    const double c = std::cos(a), s = std::sin(a);
    for (const Harmonic& h : u.harmonics) {
        // (x, y) and (rx, ry) are vectors in the plane: e_x -> (c, s), e_y -> (-s, c).
        auto pair = [&](Axis ax, Axis ay, bool is_x) {
            r.harmonics.push_back({ax, h.n, h.amp * (is_x ? c : -s), h.phase});
            r.harmonics.push_back({ay, h.n, h.amp * (is_x ? s : c), h.phase});
        };
        switch (h.axis) {
            case Axis::x: pair(Axis::x, Axis::y, true); break;
            case Axis::y: pair(Axis::x, Axis::y, false); break;
            case Axis::rx: pair(Axis::rx, Axis::ry, true); break;
            case Axis::ry: pair(Axis::rx, Axis::ry, false); break;
            default: r.harmonics.push_back(h);
        }
    }
    return r;
}

PlateMotion shift_motion(const PlateMotion& u, const Vec2& D) {
    PlateMotion r = u;
    const Vec3 d(D.x(), D.y(), 0);
    for (const Harmonic& h : u.harmonics) {
        if (h.axis != Axis::rx && h.axis != Axis::ry && h.axis != Axis::rz) continue;
        Vec3 alpha = Vec3::Zero();
        alpha[static_cast<int>(h.axis) - 3] = h.amp;
        const Vec3 add = -alpha.cross(d);   // the same harmonic, on the linear axes
        for (int k = 0; k < 3; ++k)
            if (add[k] != 0) r.harmonics.push_back({static_cast<Axis>(k), h.n, add[k], h.phase});
    }
    return r;
}

// --- orientation harmonics ------------------------------------------------------------------------

double OrientationHarmonics::rest() const {
    double r = amplitude.empty() ? 0.0 : amplitude[0];
    for (std::size_t k = 2; k < amplitude.size(); ++k) r += amplitude[k];
    return r;
}

double OrientationHarmonics::slope_bound() const {
    double r = 0;
    for (std::size_t k = 2; k < amplitude.size(); ++k) r += k * amplitude[k];
    return r;
}

bool OrientationHarmonics::one_stable() const {
    return defined && first() * first() > rest() * rest() + slope_bound() * slope_bound();
}

OrientationHarmonics harmonics_of(const std::vector<double>& w) {
    const int n = static_cast<int>(w.size());
    if (n < 4) throw std::invalid_argument("orientation harmonics: a ring of at least 4 orientations");
    OrientationHarmonics h;
    h.defined = true;
    h.amplitude.resize(n / 2 + 1);
    for (int m = 0; m <= n / 2; ++m) {   // c_m = (1/n) sum_k w_k e^{-i 2 pi m k / n}; B_m = 2 |c_m| (|c_m| at 0 and n/2)
        std::complex<double> c = 0;
        for (int k = 0; k < n; ++k) c += w[k] * std::polar(1.0, -2 * kPi * m * k / n);
        c /= n;
        if (m == 0) h.mean = c.real();
        h.amplitude[m] = (m == 0 || 2 * m == n ? 1.0 : 2.0) * std::abs(c);
    }
    return h;
}

OrientationHarmonics orientation_harmonics(const Scene& scene, const Vec2& s, const LimitCycleOptions& opt, int n) {
    if (n < 4) throw std::invalid_argument("orientation harmonics: a ring of at least 4 orientations");
    std::vector<double> w(n);
    Vec3 warm = Vec3::Zero();
    for (int k = 0; k < n; ++k) {
        const LimitCycleSummary lc = limit_cycle(scene, Vec3(s.x(), s.y(), 2 * kPi * k / n), opt, warm);
        if (!lc.converged) return {};
        w[k] = lc.twist[2];
        warm = lc.qd_start;
    }
    return harmonics_of(w);
}

// --- the flight check ----------------------------------------------------------------------------

// (design.hpp) 256 samples over the period.
double vertical_margin(const PlateMotion& u, double g, double half_width) {
    double worst = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 256; ++k) {
        Vec3 pdd, wd;
        u.acceleration(u.T * k / 256, pdd, wd);
        for (double x : {-half_width, half_width})
            for (double y : {-half_width, half_width}) worst = std::min(worst, (g + pdd.z() + wd.x() * y - wd.y() * x) / g);
    }
    return worst;
}

double flight_region(const Scene& part, const DesignOptions& opt) {
    double reach = 0;
    for (int i = 0; i < part.part.contacts(); ++i) reach = std::max(reach, part.part.c[i].head<2>().norm());
    return opt.region + (part.part.point ? 0.0 : reach);
}

PlateMotion motion_from(const std::vector<double>& p, const std::vector<Axis>& axes, const std::vector<int>& harmonics,
                        double T) {
    PlateMotion u;
    u.T = T;
    const int H = static_cast<int>(harmonics.size());
    for (int a = 0; a < static_cast<int>(axes.size()); ++a)
        for (int h = 0; h < H; ++h) {
            const double c = p[2 * (a * H + h)], s = p[2 * (a * H + h) + 1], amp = std::hypot(c, s);
            if (amp > 0) u.harmonics.push_back({axes[a], harmonics[h], amp, std::atan2(c, s)});
        }
    return u;
}

namespace {

using Clock = std::chrono::steady_clock;

// Harmonics combined per (axis, n) as phasors amp e^{i phase}: the amplitude a scene's reader sees.
std::map<std::pair<int, int>, std::complex<double>> phasors(const PlateMotion& u) {
    std::map<std::pair<int, int>, std::complex<double>> p;
    for (const Harmonic& h : u.harmonics) p[{static_cast<int>(h.axis), h.n}] += std::polar(h.amp, h.phase);
    return p;
}

// The motion with one harmonic per (axis, n) (amplitude >= 0), as a scene file states it.
PlateMotion combined(const PlateMotion& u) {
    PlateMotion r;
    r.T = u.T;
    for (const auto& [k, z] : phasors(u))
        if (std::abs(z) > 0) r.harmonics.push_back({static_cast<Axis>(k.first), k.second, std::abs(z), std::arg(z)});
    return r;
}

// --- what the searches share -----------------------------------------------------------------------

// The coefficients of u in motion_from's layout; empty if u has a harmonic outside it.
std::vector<double> params_from(const PlateMotion& u, const std::vector<Axis>& axes, const std::vector<int>& harmonics) {
    const int H = static_cast<int>(harmonics.size());
    std::vector<double> p(2 * axes.size() * H, 0.0);
    for (const auto& [k, z] : phasors(u)) {
        const auto a = std::find(axes.begin(), axes.end(), static_cast<Axis>(k.first)) - axes.begin();
        const auto h = std::find(harmonics.begin(), harmonics.end(), k.second) - harmonics.begin();
        if (a == static_cast<long>(axes.size()) || h == H) return {};
        p[2 * (a * H + h)] = z.imag();       // amp sin(phase): the cosine's coefficient
        p[2 * (a * H + h) + 1] = z.real();   // amp cos(phase): the sine's
    }
    return p;
}

// Eight points on the edge of the region |s_x|, |s_y| <= R: corners and midpoints.
std::array<Vec2, 8> region_edge(double R) {
    return {Vec2(-R, -R), Vec2(0, -R), Vec2(R, -R), Vec2(R, 0), Vec2(R, R), Vec2(0, R), Vec2(-R, R), Vec2(-R, 0)};
}

// A limit cycle's twist error relative to v_ref (and v_ref / rho): its tolerance plus the integrator's,
// ~60 rtol v_ref (field.hpp).
double cycle_noise(const LimitCycleOptions& o) { return o.tol + 60 * o.integration.rtol; }

// The option's task runner, else its threads.
TaskRunner runner(const DesignOptions& opt) { return opt.tasks ? opt.tasks : thread_tasks(opt.threads); }

// A search problem's bookkeeping. Derived (CRTP) supplies kParams, kConstraints, limit(i) (the
// bound of parameter i), constraints(p, c) (c_k <= 0 when feasible) and evaluate(p).
template <class Derived>
struct Problem {
    Problem(const Scene& part_, const DesignOptions& opt_, double T_, std::atomic<long>* cycles_)
        : part(part_), opt(opt_), T(T_), cycles(cycles_) {}
    const Scene& part;
    const DesignOptions& opt;
    double T;
    std::atomic<long>* cycles;
    std::vector<double> guess;   // a first start (the part scene's motion), if the problem can express it
    long evaluations = 0;
    // The best point evaluated that satisfies every constraint (COBYLA's own answer may violate one
    // by its tolerance: the limits and the flight margin are hard, so that is never taken).
    std::vector<double> best_p;
    double best_f = std::numeric_limits<double>::infinity();

    const Derived& self() const { return static_cast<const Derived&>(*this); }
    // Is parameter i of a layout over axes x harmonics (motion_from's) free under opt.axes and
    // opt.max_harmonic? (Derived's is_free(i); multistart holds the others at zero.)
    bool free(const std::vector<Axis>& axes, const std::vector<int>& harmonics, int i) const {
        const int H = static_cast<int>(harmonics.size());
        const Axis a = axes[static_cast<std::size_t>(i / (2 * H))];
        if (opt.max_harmonic > 0 && harmonics[static_cast<std::size_t>((i / 2) % H)] > opt.max_harmonic) return false;
        return opt.axes.empty() || std::find(opt.axes.begin(), opt.axes.end(), a) != opt.axes.end();
    }
    bool feasible(const std::vector<double>& p) const {
        double c[Derived::kConstraints];
        self().constraints(p, c);
        return std::all_of(c, c + Derived::kConstraints, [](double x) { return x <= 0; });
    }
    double objective(const std::vector<double>& p) {
        const double f = static_cast<Derived&>(*this).evaluate(p);
        if (f < best_f && feasible(p)) {
            best_f = f;
            best_p = p;
        }
        return f;
    }
    // The limit cycle at s; false if it did not converge.
    bool twist_at(const Scene& sc, const Vec2& s, Vec2& v) const {
        const LimitCycleSummary lc = limit_cycle(sc, Vec3(s.x(), s.y(), 0), opt.cycle);
        ++*cycles;
        if (!lc.converged) return false;
        v = lc.twist.head<2>();
        return true;
    }
};

// The multi-start search: from opt.starts seeded feasible random points (start 0: the problem's guess
// if it has a feasible one; else each parameter uniform in +-limit/sqrt 2, the box shrinking after
// every 100 infeasible tries, up to 1000), NLopt COBYLA with the constraints, opt.local_evaluations each,
// starts in parallel; make(k) builds start k's problem. Returns the best feasible point over the
// starts (empty if none) and adds the evaluations to `evaluations`.
template <class P, class Make>
std::vector<double> multistart(const DesignOptions& opt, double stopval, Make&& make, long& evaluations) {
    constexpr int n = P::kParams;
    // The free parameters (DesignOptions::axes and max_harmonic hold the others at zero, as does a
    // limit of zero): the local search runs on them alone.
    std::vector<int> free_idx;
    {
        const P probe = make();
        bool any = false;
        for (int i = 0; i < n; ++i) {
            any = any || probe.is_free(i);
            if (probe.is_free(i) && probe.limit(i) > 0) free_idx.push_back(i);
        }
        if (!any) throw std::invalid_argument("the axes and harmonics allowed leave this target's motion family nothing to move (" +
                                              std::string(P::kFamily) + ")");
    }
    const int m = static_cast<int>(free_idx.size());
    const int n_starts = std::max(1, opt.starts);
    std::vector<std::vector<double>> best_p(n_starts);
    std::vector<double> best_f(n_starts, std::numeric_limits<double>::infinity());
    std::vector<long> evals(n_starts, 0);
    std::atomic<long>* const cycles = make().cycles;   // (each start counts its own and sends it)
    runner(opt)(n_starts, [&](int k) -> std::string {
        P prob = make();
        std::atomic<long> own_cycles{0};
        prob.cycles = &own_cycles;
        Rng rng(opt.seed * 1000003 + static_cast<std::uint64_t>(k));
        std::vector<double> p(n), lo(n), hi(n), step(n);
        bool ok = false;
        // Start 0 from the part scene's own plate motion when the problem can express it and it is
        // feasible (the issue's "starting guess").
        if (k == 0 && !prob.guess.empty()) {
            p = prob.guess;
            for (int i = 0; i < n; ++i)
                if (!prob.is_free(i)) p[i] = 0;
            ok = prob.feasible(p);
        }
        // (every 100 infeasible draws the box shrinks by 0.7: with z and rx, ry motion most of the full
        // box lets the part fly)
        for (int tries = 0; tries < 1000 && !ok; ++tries) {
            const double box = std::pow(0.7, tries / 100) / std::sqrt(2.0);
            for (int i = 0; i < n; ++i) p[i] = rng.uniform(-prob.limit(i), prob.limit(i)) * box * prob.is_free(i);
            ok = prob.feasible(p);
        }
        if (!ok) return "inf 0 0";
        // The start's result as text (it may have run in another process): f, evaluations, cycles, p.
        const auto result = [&] {
            std::string text = exact_text(prob.best_f) + ' ' + std::to_string(prob.evaluations) + ' ' +
                               std::to_string(own_cycles.load());
            for (double x : prob.best_p) text += ' ' + exact_text(x);
            return text;
        };
        prob.objective(p);   // the feasible start itself
        if (m == 0) return result();   // (nothing free: the start is the answer)
        // The local search on the free parameters: x (m of them) placed into the full p.
        struct Reduced {
            P* prob;
            const std::vector<int>* idx;
            std::vector<double> full;
            const std::vector<double>& place(const double* x) {
                for (std::size_t j = 0; j < idx->size(); ++j) full[static_cast<std::size_t>((*idx)[j])] = x[j];
                return full;
            }
        } red{&prob, &free_idx, p};
        std::vector<double> x(m);
        lo.resize(m);
        hi.resize(m);
        step.resize(m);
        for (int j = 0; j < m; ++j) {
            const int i = free_idx[j];
            x[j] = p[i];
            lo[j] = -prob.limit(i);
            hi[j] = prob.limit(i);
            step[j] = prob.limit(i) / 4;
        }
        const bool gradients = opt.local == DesignOptions::Local::SlsqpFiniteDifferences;
        nlopt::opt local(gradients ? nlopt::LD_SLSQP : nlopt::LN_COBYLA, m);
        local.set_lower_bounds(lo);
        local.set_upper_bounds(hi);
        local.set_initial_step(step);
        // (SLSQP: forward differences of 1e-3 of each parameter's limit -- the objective's noise, the
        // cycles' tolerance, is ~1e-6 relative; the evaluations' budget includes the differences)
        local.set_maxeval(gradients ? std::max(1, opt.local_evaluations / (n + 1)) : opt.local_evaluations);
        local.set_stopval(stopval);
        local.set_min_objective(
            [](const std::vector<double>& xr, std::vector<double>& g, void* d) {
                Reduced& r = *static_cast<Reduced*>(d);
                const double f = r.prob->objective(r.place(xr.data()));
                for (std::size_t j = 0; j < g.size(); ++j) {
                    std::vector<double> xp = xr;
                    const double h = 1e-3 * r.prob->limit((*r.idx)[j]);
                    xp[j] += h;
                    g[j] = (r.prob->objective(r.place(xp.data())) - f) / h;
                }
                return f;
            },
            &red);
        local.add_inequality_mconstraint(
            [](unsigned, double* c, unsigned mr, const double* xr, double* grad, void* d) {
                Reduced& r = *static_cast<Reduced*>(d);
                r.prob->constraints(r.place(xr), c);
                if (!grad) return;
                double cp[P::kConstraints];
                std::vector<double> xp(xr, xr + mr);
                for (unsigned j = 0; j < mr; ++j) {   // grad[k m + j] = d c_k / d x_j
                    const double h = 1e-3 * r.prob->limit((*r.idx)[j]);
                    xp[j] += h;
                    r.prob->constraints(r.place(xp.data()), cp);
                    xp[j] = xr[j];
                    for (int k = 0; k < P::kConstraints; ++k) grad[k * mr + j] = (cp[k] - c[k]) / h;
                }
            },
            &red, std::vector<double>(P::kConstraints, 1e-9));
        double f = 0;
        try {
            local.optimize(x, f);
        } catch (const std::exception&) {
            // (a roundoff-limited stop: the best feasible point found stands)
        }
        return result();
    }, [&](int k, const std::string& text) {
        std::istringstream in(text);
        std::string f, x;
        long c = 0;
        in >> f >> evals[k] >> c;
        *cycles += c;
        best_f[k] = exact_value(f);
        best_p[k].clear();
        while (in >> x) best_p[k].push_back(exact_value(x));
    });
    for (long e : evals) evaluations += e;
    const auto best = std::min_element(best_f.begin(), best_f.end()) - best_f.begin();
    return std::isfinite(best_f[best]) ? best_p[best] : std::vector<double>{};
}

// Verification, shared: the designed field on the verify_grid^2 grid over the region, and full
// dynamics from verify_starts seeded random starts, each run for seconds(start) and measured by
// end_distance(start, end); the worst distance and the runs that left the model are tallied.
Field verification_field(const Scene& sc, const DesignOptions& opt) {
    GridSpec g;
    g.nx = g.ny = opt.verify_grid;
    g.nth = 1;
    g.x0 = g.y0 = -opt.region;
    g.x1 = g.y1 = opt.region;
    if (!sc.part.point) g.nth = opt.verify_grid;   // theta: a full turn
    FieldOptions fo;
    fo.threads = opt.threads;
    fo.tasks = opt.tasks;
    return compute_field(sc, g, fo);
}

// What the grid's fixed-point search could not look at (empty: it searched every cell): cells with an
// undefined corner, cells left when its budget ran out, cells where the part is stuck all period (a
// region of fixed configurations, not a point). A fixed point is called unique only without these.
std::string unsearched(const FixedPoints& f) {
    std::string gaps;
    const auto add = [&](int n, const char* what) {
        if (n > 0) gaps += (gaps.empty() ? "" : ", ") + std::to_string(n) + " cell(s) " + what;
    };
    add(f.undefined_cells, "with an undefined corner");
    add(f.unsearched_cells, "left unsearched (budget)");
    add(f.stuck_cells, "where the part is stuck all period");
    return gaps;
}

// With `hold` (sinks and fixed points, opt.hold > 0) one more run starts at rest at *hold, the target,
// for opt.hold seconds: sum.held (not among sum.runs, nor in the worst distance). With from > 0 each
// run also records where it was at about from * seconds, a whole number of periods before its end
// (DesignStartRun::at_from), for end_distance.
template <class Seconds, class EndDistance>
int verification_runs(DesignSummary& sum, const DesignOptions& opt, Seconds&& seconds, EndDistance&& end_distance,
                      const Vec3* hold = nullptr, double from = 0) {
    Rng rng(opt.seed ^ 0x5DEECE66DULL);
    const bool rigid = !sum.scene.part.point;
    sum.runs.resize(opt.verify_starts);
    for (DesignStartRun& r : sum.runs) {
        r.x = rng.uniform(-opt.region, opt.region);
        r.y = rng.uniform(-opt.region, opt.region);
        if (rigid) r.theta = rng.uniform(-kPi, kPi);   // (drawn after x, y: point parts' starts unchanged)
        r.seconds = seconds(r);
        // (a whole number of periods from the end: the part's position swings within each period)
        r.from = from > 0 ? r.seconds - std::round((1 - from) * r.seconds / sum.scene.plate.T) * sum.scene.plate.T : 0.0;
    }
    const bool holding = hold && opt.hold > 0;
    if (holding) {
        sum.held = DesignStartRun{};
        sum.held.x = (*hold)[0];
        sum.held.y = (*hold)[1];
        sum.held.theta = (*hold)[2];
        sum.held.seconds = opt.hold;
    }
    auto job = [&](int k) -> DesignStartRun& { return k < opt.verify_starts ? sum.runs[k] : sum.held; };
    runner(opt)(opt.verify_starts + holding, [&](int k) {
        DesignStartRun r = job(k);
        IntegrationOptions io;
        io.rtol = 1e-7;
        const Trajectory tr = simulate(sum.scene, Dynamics::Full, Vec3(r.x, r.y, r.theta), Vec3::Zero(), r.seconds,
                                       r.from > 0 ? r.from : r.seconds, io);
        r.end = tr.samples.empty() ? Vec3::Constant(std::numeric_limits<double>::quiet_NaN()) : tr.samples.back().q;
        if (r.from > 0)
            for (const Sample& smp : tr.samples)
                if (std::abs(smp.t - r.from) <= 1e-9 * r.seconds) r.at_from = smp.q;
        const double d = tr.samples.empty() ? std::numeric_limits<double>::infinity() : end_distance(r, r.end);
        // (text: the distance, the end, then why the run stopped early, if it did)
        return exact_text(d) + ' ' + exact_text(r.end[0]) + ' ' + exact_text(r.end[1]) + ' ' + exact_text(r.end[2]) + ' ' +
               exact_text(r.at_from[0]) + ' ' + exact_text(r.at_from[1]) + ' ' + exact_text(r.at_from[2]) +
               (tr.stop.reason != StopReason::None ? ' ' + tr.stop.describe() : std::string());
    }, [&](int k, const std::string& text) {
        std::istringstream in(text);
        std::string x[7];
        for (auto& w : x) in >> w;
        DesignStartRun& r = job(k);
        r.end_distance = exact_value(x[0]);
        r.end = Vec3(exact_value(x[1]), exact_value(x[2]), exact_value(x[3]));
        r.at_from = Vec3(exact_value(x[4]), exact_value(x[5]), exact_value(x[6]));
        std::getline(in >> std::ws, r.stop);
    });
    int stopped = 0;
    sum.worst_end_distance = 0;
    for (const DesignStartRun& r : sum.runs) {
        sum.worst_end_distance = std::max(sum.worst_end_distance, r.end_distance);
        stopped += !r.stop.empty();
    }
    return stopped;   // (the hold's own verdict: hold_failure)
}

// The hold's verdict (empty: held, or no hold asked): released at the target, the part ended beyond
// verify_distance (`unit` names the distance) or left the model.
std::string hold_failure(const DesignSummary& sum, const DesignOptions& opt, const std::string& unit) {
    if (!(opt.hold > 0) || (sum.held.stop.empty() && sum.held.end_distance <= opt.verify_distance)) return "";
    return "released at rest at the target, the part " +
           (sum.held.stop.empty() ? "ended " + std::to_string(sum.held.end_distance) + unit + " away after "
                                  : "stopped (" + sum.held.stop + ") within ") +
           std::to_string(opt.hold) + " s of full dynamics (coning " + std::to_string(sum.coning) + " rad/s)";
}

// The summary's last entries, whatever the outcome: the cycles computed and the wall time.
DesignSummary& finished(DesignSummary& sum, const std::atomic<long>& cycles, Clock::time_point t0) {
    sum.cycles = cycles;
    sum.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return sum;
}

// A verification run's duration: long enough for the slowest mode, at `rate` [1/s], to bring a start
// d0 away within a fifth of the distance asked (2 s to 120 s).
double settle_time(double d0, double rate, const DesignOptions& opt) {
    return std::clamp(std::log(std::max(d0, opt.verify_distance) / (0.2 * opt.verify_distance)) / std::max(rate, 1e-3), 2.0,
                      120.0);
}

// A point part's verification run from `start`: the time the designed field, interpolated bilinearly
// on the verification grid, takes to bring it within a fifth of verify_distance of `target` (RK4 in
// 0.05 s steps), plus half again and 2 s for the interpolation's error; at most 120 s (also if the
// interpolated curve never arrives). Far starts can take several times ln(d0 / d) / rate: the rate is
// the centre's, and the field weakens away from it.
double field_settle_time(const Field& f, const Vec2& start, const Vec2& target, const DesignOptions& opt) {
    const GridSpec& g = f.grid;
    constexpr double h = 0.05, cap = 120;
    if (g.nx < 2 || g.ny < 2) return cap;   // (no cell to interpolate in)
    auto v = [&](const Vec2& s) {
        const double u = std::clamp((s.x() - g.x0) / g.dx(), 0.0, g.nx - 1.0), w = std::clamp((s.y() - g.y0) / g.dy(), 0.0, g.ny - 1.0);
        const int i = std::min(static_cast<int>(u), g.nx - 2), j = std::min(static_cast<int>(w), g.ny - 2);
        const double a = u - i, b = w - j;
        auto at = [&](int di, int dj) -> Vec2 { return f.points[g.index(i + di, j + dj, 0)].twist.head<2>(); };
        return Vec2((1 - a) * (1 - b) * at(0, 0) + a * (1 - b) * at(1, 0) + (1 - a) * b * at(0, 1) + a * b * at(1, 1));
    };
    Vec2 s = start;
    for (double t = 0; t < cap; t += h) {
        if ((s - target).norm() <= 0.2 * opt.verify_distance) return std::min(1.5 * t + 2, cap);
        const Vec2 k1 = v(s), k2 = v(s + 0.5 * h * k1), k3 = v(s + 0.5 * h * k2), k4 = v(s + h * k3);
        s += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
        if (!s.allFinite()) break;
    }
    return cap;
}

// c_k <= 0 for each axis' harmonics n = 1..n_max of `fin` within `room` times the axis' limit (6 n_max
// entries, axis-major), then c <= 0 for no flight over the region; returns the entries written.
int amplitude_constraints(const PlateMotion& fin, const DesignOptions& opt, const Scene& part, int n_max, double room,
                          double* c) {
    const auto ph = phasors(fin);
    int k = 0;
    for (int axis = 0; axis < 6; ++axis)
        for (int n = 1; n <= n_max; ++n) {
            const auto it = ph.find({axis, n});
            const double amp = it == ph.end() ? 0.0 : std::abs(it->second);
            const double lim = axis < 3 ? opt.lin_limit : opt.ang_limit;
            c[k++] = (amp - room * lim) / std::max(lim, 1e-12);
        }
    c[k++] = opt.flight_margin - vertical_margin(fin, part.g, flight_region(part, opt));
    return k;
}

// The summary's scene before a design is found: the part on a plate at rest.
void start_summary(DesignSummary& sum, const Scene& part, const std::string& suffix, double T) {
    sum.scene = part;
    sum.scene.name = part.name + suffix;
    sum.scene.plate = PlateMotion{};
    sum.scene.plate.T = T;
}
constexpr const char* kNoFeasibleMotion = "no motion within the limits keeps the part on the plate over the region";

// The position's field v0 at (s, theta) and its Jacobian in s by central differences of h: five limit
// cycles (counted in `cycles`); false if one did not converge.
bool position_pull(const Scene& sc, const Vec2& s, double theta, const LimitCycleOptions& cyc, double h, Vec2& v0,
                   Eigen::Matrix2d& J, std::atomic<long>& cycles) {
    const Vec2 d[5] = {Vec2::Zero(), Vec2(h, 0), Vec2(-h, 0), Vec2(0, h), Vec2(0, -h)};
    Vec2 v[5];
    for (int j = 0; j < 5; ++j) {
        const LimitCycleSummary lc = limit_cycle(sc, Vec3(s.x() + d[j].x(), s.y() + d[j].y(), theta), cyc);
        ++cycles;
        if (!lc.converged) return false;
        v[j] = lc.twist.head<2>();
    }
    v0 = v[0];
    J.col(0) = (v[1] - v[2]) / (2 * h);
    J.col(1) = (v[3] - v[4]) / (2 * h);
    return true;
}

// --- the sink ---------------------------------------------------------------------------------------
// Parameters: per axis of {x, y, rx, ry} and harmonic n = 1, 3, the cosine and sine coefficients,
// u_a = c cos(n w t) + s sin(n w t): odd harmonics without z or rz make the field odd about the
// centre, so the centre is a point part's fixed point by construction and the search only makes it
// attract, fast, over the whole region (then shift_motion moves it onto the target). A rigid part's
// position is pulled the same way at every orientation (fig4's: -0.5 1/s at each, while it turns on
// at 0.08-0.44 rad/s); oddness only pairs (s, theta) with (-s, theta + pi), so its velocity at the
// centre need not vanish, and the search also keeps that offset small. The fastest sinks tilt the plate
// in circles (rx, ry a quarter period apart: 1.1 1/s at (0.02, -0.01) under 15 / 100), which cones
// (2e-3 rad/s: the sink walks 5.5 mm about the centre in two minutes); held to sink_coning_limit, the
// first harmonic can tilt in circles only a little, and the third, which cones 27 times less for the
// same amplitudes (coning pairs only equal n), adds the rest.
constexpr double kConingLimit = 1e-4;   // [rad/s] rigid fixed points' coning (coning_rate, design.hpp): 0.012 rad over a 120 s hold
// [rad/s] their tilt drift (tilt_drift_rate): a tilt pulls the part downhill, g times the tilt, all
// along, so it is held to 1e-3 rad (0.01 m/s^2, 0.3 % of mu g for mu 0.3) over the longest runs
// (break_pair's: up to about 500 s). A motion without rz has none; break_pair's has none by construction.
constexpr double kTiltDriftLimit = 2e-6;

PlateMotion sink_motion(const std::vector<double>& p, double T) {
    return motion_from(p, {Axis::x, Axis::y, Axis::rx, Axis::ry}, {1, 3}, T);
}

struct SinkProblem : Problem<SinkProblem> {
    // With `orient` (a rigid part's fixed point as a half-turn pair, design_rigid_pair): the part's
    // orientation THETA is to be a stable zero of theta' at the centre as well, and the coning is held to
    // kConingLimit (the plate's turn would turn the part's orientation with it).
    SinkProblem(const Scene& part_, const Vec2& D_, const DesignOptions& opt_, double T_, std::atomic<long>* cycles_,
                const double* orient_ = nullptr)
        : Problem(part_, opt_, T_, cycles_), D(D_), cone_limit(sink_coning_limit(D_, opt_)), orient(orient_ != nullptr),
          theta(orient_ ? *orient_ : 0.0) {
        if (orient) cone_limit = std::min(cone_limit, kConingLimit);
    }
    Vec2 D;
    double cone_limit;
    bool orient;
    double theta;   // [rad] (orient)
    // The orientations the pull is measured at: a point part's one (it has no orientation); at a rigid
    // part's centre the odd field repeats after a half turn, so theta = 0 (or THETA) and a quarter turn
    // sample it (the verification checks the grid's seven).
    std::vector<double> thetas() const {
        return part.part.point ? std::vector<double>{0.0} : std::vector<double>{theta, theta + kPi / 2};
    }
    static constexpr int kParams = 16;
    static constexpr const char* kFamily = "x, y, rx, ry at n = 1, 3";
    static constexpr int kConstraints = 21;   // eighteen amplitudes (n = 1..3), the flight margin, coning both ways
    double limit(int i) const { return i < 8 ? opt.lin_limit : opt.ang_limit; }
    bool is_free(int i) const { return free({Axis::x, Axis::y, Axis::rx, Axis::ry}, {1, 3}, i); }   // (sink_motion's layout)

    // Constraints c_k <= 0 on the final (shifted) motion: each harmonic's amplitude within its
    // limit, no flight under the part over the region, and no more coning than the hold allows.
    void constraints(const std::vector<double>& p, double* c) const {
        const PlateMotion fin = shift_motion(sink_motion(p, T), D);
        // (orient: 3 % of each limit and 0.02 g of the flight margin kept in hand for the placement's
        // small turn and shift onto the fixed point found)
        const int k = amplitude_constraints(fin, opt, part, 3, orient ? 0.97 : 1.0, c);
        if (orient) c[k - 1] += 0.02;
        const double psi = coning_rate(fin);
        const double cone = !std::isfinite(cone_limit) ? 0.0
                            : cone_limit > 0       ? psi / cone_limit
                                                   : (psi == 0 ? 0.0 : std::copysign(1e9, psi));   // (max_coning 0)
        c[k] = cone - 1;
        c[k + 1] = -cone - 1;
    }
    // Convergence rate at the centre (the slowest orientation's), and how much of the region's edge
    // the field does not point inwards (of the centred motion: the final field at s + D); a rigid
    // part's offset, where its position's field vanishes near the centre, beyond 1 mm.
    double evaluate(const std::vector<double>& p, double* rate_out = nullptr, Eigen::Vector2cd* eig_out = nullptr) {
        ++evaluations;
        Scene sc = part;
        sc.plate = sink_motion(p, T);
        const double h = 0.003;
        double rate = std::numeric_limits<double>::infinity(), offset = 0;
        for (double th : thetas()) {
            Eigen::Matrix2d J;
            if (part.part.point) {
                Vec2 vx = Vec2::Zero(), vy = Vec2::Zero();
                if (!twist_at(sc, Vec2(h, 0), vx) || !twist_at(sc, Vec2(0, h), vy)) return 1e3;
                J.col(0) = vx / h;   // the field is odd about the centre: v(h e) / h is the central difference
                J.col(1) = vy / h;
            } else {
                Vec2 v0 = Vec2::Zero();
                if (!position_pull(sc, Vec2::Zero(), th, opt.cycle, h, v0, J, *cycles)) return 1e3;
                const Vec2 step = J.fullPivLu().solve(v0);
                offset = std::max(offset, step.allFinite() ? step.norm() : 1.0);
            }
            const Eigen::Vector2cd ev = J.eigenvalues();
            const double r = -std::max(ev[0].real(), ev[1].real());
            if (r < rate) {
                rate = r;
                if (eig_out) *eig_out = ev;
            }
        }
        if (rate_out) *rate_out = rate;
        // The region's edge, relative to the centre of the design: eight points on its boundary.
        double outward = 0;
        for (const Vec2& e : region_edge(opt.region)) {
            const Vec2 s = e - D;
            Vec2 v;
            if (!twist_at(sc, s, v)) return 1e3;
            outward += std::max(0.0, s.dot(v) / s.squaredNorm());   // [1/s]
        }
        double turn = 0;   // orient: the orientation's own pull and how far its zero is from THETA
        if (orient) {
            const double d = 0.15;
            double w[3];
            for (int k = 0; k < 3; ++k) {
                const LimitCycleSummary lc = limit_cycle(sc, Vec3(0, 0, theta + (k - 1) * d), opt.cycle);
                ++*cycles;
                if (!lc.converged) return 1e3;
                w[k] = lc.twist[2];
            }
            const double slope = (w[0] - w[2]) / (2 * d);   // -d theta' / d theta [1/s]
            rate = std::min(rate, slope);
            if (rate_out) *rate_out = rate;
            // the zero's distance from THETA, in 0.01 rad (capped: a motion whose cycles fail scores 1e3, worse)
            turn = std::min(50.0, std::abs(w[1]) / std::max(slope, 1e-3) / 0.01);
        }
        return -rate + 10 * outward + 10 * std::max(0.0, offset / 0.001 - 1) + 10 * std::max(0.0, turn - 1);
    }
};

// The checks every sink and fixed point ends with, where nothing before failed: the hold (`unheld`:
// hold_failure's verdict) and the flight margin; then the summary's end.
DesignSummary& last_checks(DesignSummary& sum, const DesignOptions& opt, const std::string& unheld,
                           const std::atomic<long>& cycles, Clock::time_point t0) {
    if (sum.failure.empty()) sum.failure = unheld;
    if (sum.failure.empty() && !(sum.min_vertical_margin >= opt.flight_margin - 1e-9))
        sum.failure = "the vertical acceleration margin is below the one asked";
    sum.verified = sum.failure.empty();
    return finished(sum, cycles, t0);
}

// A sink's verdict, shared: full-dynamics runs from random starts (each as long as the position
// field `settle` takes to bring it in) and from the target (the hold), then the first check that
// fails: uniqueness (`not_unique` says why not), runs that left the model, a run ending too far, the
// hold, the flight margin.
DesignSummary& sink_verdict(DesignSummary& sum, const Field& settle, const DesignTarget& target, const DesignOptions& opt,
                            const std::string& not_unique, std::atomic<long>& cycles, Clock::time_point t0) {
    const Vec3 hold_at(target.at.x(), target.at.y(), 0);
    const int stopped = verification_runs(
        sum, opt, [&](const DesignStartRun& r) { return field_settle_time(settle, Vec2(r.x, r.y), target.at, opt); },
        [&](const DesignStartRun&, const Vec3& end) { return (end.head<2>() - target.at).norm(); }, &hold_at);
    const std::string unheld = hold_failure(sum, opt, " m");
    if (!sum.unique) sum.failure = not_unique;
    else if (stopped)
        sum.failure = std::to_string(stopped) + " full-dynamics run(s) left the model";
    else if (!(sum.worst_end_distance <= opt.verify_distance))
        sum.failure = "a full-dynamics run ended " + std::to_string(sum.worst_end_distance) + " m from the target";
    return last_checks(sum, opt, unheld, cycles, t0);
}

// A rigid part's sink, verified: at the target, for each orientation of the verification grid, the
// position's field vanishes within fixed_point_tolerance (Newton from the target, 3 mm central
// differences) with both eigenvalues' real parts negative; full-dynamics runs from random (x, y, theta)
// end within verify_distance of the target's position, whatever their orientation; the hold.
DesignSummary& verify_rigid_sink(DesignSummary& sum, const Field& field, const DesignTarget& target, const DesignOptions& opt,
                                 std::atomic<long>& cycles, Clock::time_point t0) {
    sum.fixed_points = FixedPoints{};
    const double h = 0.003;
    int held = 0;
    std::string why;
    for (int k = 0; k < field.grid.nth; ++k) {
        DesignSummary::OrientationPull pull;
        pull.theta = field.grid.th0 + k * field.grid.dth();
        Vec2 s = target.at;
        bool ok = false;
        for (int it = 0; it < 6 && !ok; ++it) {
            Vec2 v0 = Vec2::Zero();
            Eigen::Matrix2d J;
            if (!position_pull(sum.scene, s, pull.theta, opt.cycle, h, v0, J, cycles)) break;
            pull.eigenvalues = J.eigenvalues();
            const Vec2 step = J.fullPivLu().solve(v0);
            if (!step.allFinite()) break;
            s -= step;
            ok = step.norm() < 1e-6;
        }
        pull.zero = s;
        sum.pulls.push_back(pull);
        const bool here = ok && (s - target.at).norm() <= opt.fixed_point_tolerance &&
                          std::max(pull.eigenvalues[0].real(), pull.eigenvalues[1].real()) < 0;
        held += here;
        if (!here && why.empty())
            why = "at orientation " + std::to_string(pull.theta) + " rad the position's field " +
                  (ok ? "vanishes " + std::to_string((s - target.at).norm()) + " m from the target" +
                            (std::max(pull.eigenvalues[0].real(), pull.eigenvalues[1].real()) < 0 ? "" : ", not attracting")
                      : std::string("has no zero found near the target"));
    }
    sum.unique = held == field.grid.nth;   // (one position for every orientation)
    sum.fixed_point = Vec3(sum.pulls.front().zero.x(), sum.pulls.front().zero.y(), sum.pulls.front().theta);
    // The runs' durations: the position's field averaged over the grid's orientations (the part turns
    // as it travels), interpolated as for a point part.
    Field avg = field;
    avg.grid.nth = 1;
    avg.points.assign(field.grid.nx * field.grid.ny, FieldPoint{});
    for (int i = 0; i < field.grid.nx; ++i)
        for (int j = 0; j < field.grid.ny; ++j) {
            // (over the orientations whose cycle converged; none: NaN, and the runs take the cap)
            Vec3 m = Vec3::Zero();
            int n = 0;
            for (int k = 0; k < field.grid.nth; ++k) {
                const Vec3& w = field.points[field.grid.index(i, j, k)].twist;
                if (!w.allFinite()) continue;
                m += w;
                ++n;
            }
            avg.points[avg.grid.index(i, j, 0)].twist = m / n;
        }
    return sink_verdict(sum, avg, target, opt, why, cycles, t0);
}

DesignSummary design_sink(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt, double T) {
    const auto t0 = Clock::now();
    DesignSummary sum;
    sum.notes.push_back("odd harmonics on x, y, rx, ry only: the field is odd about the design's centre, so the "
                        "centre is a fixed point by construction and fixed points come in pairs s, -s");
    sum.notes.push_back("the design's centre moved onto the target by adding -alpha x D to the linear acceleration "
                        "(exact: the field shifts by D)");
    if (std::isfinite(sink_coning_limit(target.at, opt)))
        sum.notes.push_back("coning held to " + std::to_string(sink_coning_limit(target.at, opt)) +
                            " rad/s: the plate's second-order turn about z, which the field does not see, turns the "
                            "sink about the plate's centre; at most half the verification distance over the hold");
    else if (target.at.norm() > 0)   // (an outside audit: --hold 0 lifted the coning limit without a word)
        sum.notes.push_back("coning not limited (no hold, no --max-coning): the plate's second-order turn about z turns "
                            "the sink about the plate's centre, so a part held at the target walks off it in time "
                            "(not checked)");
    std::atomic<long> cycles{0};
    const auto make = [&] { return SinkProblem(part_scene, target.at, opt, T, &cycles); };
    const std::vector<double> best = multistart<SinkProblem>(opt, -HUGE_VAL, make, sum.evaluations);
    start_summary(sum, part_scene, "_sink", T);   // (no motion unless a design is found)
    if (best.empty()) {
        sum.failure = kNoFeasibleMotion;
        return finished(sum, cycles, t0);
    }
    make().evaluate(best, &sum.rate, &sum.eigenvalues);
    sum.scene.plate = combined(shift_motion(sink_motion(best, T), target.at));
    sum.min_vertical_margin = vertical_margin(sum.scene.plate, sum.scene.g, flight_region(sum.scene, opt));
    sum.coning = coning_rate(sum.scene.plate);

    // --- verification: the field's fixed points on the grid (a rigid part: where its position's
    // field vanishes near the target, at each of the grid's orientations), then full dynamics from
    // random starts (each for as long as the field takes to bring it in) and from the target itself
    // (the hold).
    const Field field = verification_field(sum.scene, opt);
    if (!part_scene.part.point) return verify_rigid_sink(sum, field, target, opt, cycles, t0);
    sum.fixed_points = find_fixed_points(sum.scene, field);
    int stable = 0, stable_at_target = 0;
    double nearest = std::numeric_limits<double>::infinity();
    for (const FixedPoint& p : sum.fixed_points.points) {
        if (p.stability != Stability::Stable) continue;
        ++stable;
        const double d = (p.q.head<2>() - target.at).norm();
        if (d < nearest) {
            nearest = d;
            sum.fixed_point = p.q;
            sum.fixed_point_eigenvalues = p.eigenvalues;
        }
        stable_at_target += d <= opt.fixed_point_tolerance;
    }
    for (const FixedLine& l : sum.fixed_points.lines) stable += l.stability == Stability::Stable;
    const std::string gaps = unsearched(sum.fixed_points);
    sum.unique = stable == 1 && stable_at_target == 1 && gaps.empty();
    return sink_verdict(sum, field, target, opt,
                        "the designed field has " + std::to_string(stable) + " stable fixed point(s) or line(s) on the " +
                            std::to_string(opt.verify_grid) + "x" + std::to_string(opt.verify_grid) + " grid, " +
                            std::to_string(stable_at_target) + " within " + std::to_string(opt.fixed_point_tolerance) +
                            " m of the target" + (gaps.empty() ? "" : "; not searched: " + gaps),
                        cycles, t0);
}

// --- the point-part line sink ------------------------------------------------------------------
// Parameters: cosine and sine coefficients of y and rx, first harmonic. rx couples the plate's
// vertical acceleration to y (alpha x s = (0, 0, alpha_x y)), so the normal force swings with y in
// step with the y shaking and a part drifts along y at a rate that changes sign with y. The line y = 0
// is exact by construction: the motion is mirror symmetric about x = 0 (y and the pseudovector's x
// component keep their signs) and nothing depends on x, so v_x = 0 everywhere; odd harmonics make
// v_y odd in y. The search makes it attract (fast, and over the whole region); rotate_motion turns
// the line onto the direction asked, shift_motion moves it through the point asked.
PlateMotion line_motion(const std::vector<double>& p, double T) { return motion_from(p, {Axis::y, Axis::rx}, {1}, T); }

struct LineSinkProblem : Problem<LineSinkProblem> {
    LineSinkProblem(const Scene& part_, const DesignTarget& t_, const DesignOptions& opt_, double T_, std::atomic<long>* cycles_)
        : Problem(part_, opt_, T_, cycles_), target(t_) {
        // the farthest the region reaches from the line, across it
        const Vec2 nrm(-std::sin(target.theta), std::cos(target.theta));
        for (const Vec2& e : region_edge(opt.region)) reach = std::max(reach, std::abs((e - target.at).dot(nrm)));
    }
    DesignTarget target;
    double reach = 0;
    static constexpr int kParams = 4;
    static constexpr const char* kFamily = "y, rx at n = 1";
    static constexpr int kConstraints = 7;   // six amplitudes, the flight margin
    double limit(int i) const { return i < 2 ? opt.lin_limit : opt.ang_limit; }
    bool is_free(int i) const { return free({Axis::y, Axis::rx}, {1}, i); }
    PlateMotion placed(const std::vector<double>& p) const {
        return shift_motion(rotate_motion(line_motion(p, T), target.theta), target.at);
    }
    void constraints(const std::vector<double>& p, double* c) const {
        amplitude_constraints(placed(p), opt, part, 1, 1.0, c);
    }
    // The convergence rate onto the line, -dv_y/dy at y = 0 (v_y is odd: v_y(h) / h), and how much of
    // the region the field does not pull towards the line (four distances out to its reach).
    double evaluate(const std::vector<double>& p, double* rate_out = nullptr) {
        ++evaluations;
        Scene sc = part;
        sc.plate = line_motion(p, T);
        const double h = 0.003;
        Vec2 v;
        if (!twist_at(sc, Vec2(0, h), v)) return 1e3;
        const double rate = -v.y() / h;
        if (rate_out) *rate_out = rate;
        double outward = 0;
        for (int k = 1; k <= 4; ++k) {
            const double y = reach * k / 4;
            if (!twist_at(sc, Vec2(0, y), v)) return 1e3;
            outward += std::max(0.0, v.y() / y);
        }
        return -rate + 10 * outward;
    }
};

DesignSummary design_line_sink(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt, double T) {
    const auto t0 = Clock::now();
    DesignSummary sum;
    sum.notes.push_back("y and rx, first harmonic: mirror symmetric about the line's normal and odd, so the field has a "
                        "line of fixed points by construction (no drift along it)");
    sum.notes.push_back("the line turned onto the direction asked (the field turns with the motion) and moved through "
                        "the point asked by adding -alpha x D to the linear acceleration (the field shifts by D)");
    std::atomic<long> cycles{0};
    const auto make = [&] { return LineSinkProblem(part_scene, target, opt, T, &cycles); };
    const std::vector<double> best = multistart<LineSinkProblem>(opt, -HUGE_VAL, make, sum.evaluations);
    start_summary(sum, part_scene, "_line_sink", T);
    if (best.empty()) {
        sum.failure = kNoFeasibleMotion;
        return finished(sum, cycles, t0);
    }
    make().evaluate(best, &sum.rate);
    sum.eigenvalues = Eigen::Vector2cd(0, -sum.rate);   // along the line neutral, across it the rate
    sum.scene.plate = combined(make().placed(best));
    sum.min_vertical_margin = vertical_margin(sum.scene.plate, sum.scene.g, flight_region(sum.scene, opt));

    // --- verification: on the grid, no velocity along the line and every point off it (by more than
    // the fixed-point tolerance) moving towards it; full dynamics from random starts ending on it.
    const Vec2 dir(std::cos(target.theta), std::sin(target.theta)), nrm(-dir.y(), dir.x());
    const Field f = verification_field(sum.scene, opt);
    int undefined = 0, away = 0;
    double along = 0;
    for (const FieldPoint& p : f.points) {
        if (!p.converged) { ++undefined; continue; }
        const Vec2 v = p.twist.head<2>();
        const double d = (p.q.head<2>() - target.at).dot(nrm);
        along = std::max(along, std::abs(v.dot(dir)));
        away += std::abs(d) > opt.fixed_point_tolerance && !(v.dot(nrm) * d < 0);
    }
    sum.transport_spread = along;   // (the largest speed along the line on the grid)
    sum.transport_tolerance = cycle_noise(opt.cycle) * part_scene.v_ref();   // (zero by the symmetry)
    sum.fixed_point = Vec3(target.at.x(), target.at.y(), 0);
    sum.fixed_point_eigenvalues = Eigen::Vector3cd(sum.eigenvalues[0], sum.eigenvalues[1], 0);
    const int stopped = verification_runs(
        sum, opt,
        [&](const DesignStartRun& r) { return settle_time(std::abs((Vec2(r.x, r.y) - target.at).dot(nrm)), sum.rate, opt); },
        [&](const DesignStartRun&, const Vec3& end) { return std::abs((end.head<2>() - target.at).dot(nrm)); });
    // The pull onto the line at 1 mm (the search's rate is a secant at 3 mm, and the grid and the runs
    // do not look closer than 2 and 5 mm: a line that repels between two attracting ones nearby would
    // pass them).
    double pull = 0;
    {
        const Vec2 s1 = target.at + 1e-3 * nrm;
        const LimitCycleSummary c = limit_cycle(sum.scene, Vec3(s1.x(), s1.y(), 0), opt.cycle);
        ++cycles;
        pull = c.converged ? -c.twist.head<2>().dot(nrm) / 1e-3 : std::numeric_limits<double>::quiet_NaN();
    }
    sum.unique = undefined == 0 && away == 0 && along <= sum.transport_tolerance && sum.rate > 0 && pull > 0;
    if (!(sum.rate > 0 && pull > 0))
        sum.failure = "the line does not attract (rate " + std::to_string(sum.rate) + " 1/s at 3 mm, " + std::to_string(pull) +
                      " 1/s at 1 mm)";
    else if (undefined)
        sum.failure = std::to_string(undefined) + " configurations of the field are undefined";
    else if (away)
        sum.failure = std::to_string(away) + " of the grid's points off the line do not move towards it";
    else if (!(along <= sum.transport_tolerance))
        sum.failure = "the field moves parts along the line (" + std::to_string(along) + " m/s)";
    else if (stopped)
        sum.failure = std::to_string(stopped) + " full-dynamics run(s) left the model";
    else if (!(sum.worst_end_distance <= opt.verify_distance))
        sum.failure = "a full-dynamics run ended " + std::to_string(sum.worst_end_distance) + " m from the line";
    else if (!(sum.min_vertical_margin >= opt.flight_margin - 1e-9))
        sum.failure = "the vertical acceleration margin is below the one asked";
    sum.verified = sum.failure.empty();
    return finished(sum, cycles, t0);
}

// --- the point-part transport --------------------------------------------------------------------
// Parameters: cosine and sine coefficients of harmonics n = 1, 2 on x, y and z (a plate that only
// translates). The field is uniform; its value at the centre is driven onto the target.
const std::vector<Axis> kTranslationAxes = {Axis::x, Axis::y, Axis::z};
PlateMotion transport_motion(const std::vector<double>& p, double T) {
    return motion_from(p, kTranslationAxes, {1, 2}, T);
}

// c_k <= 0: each of transport_motion's six harmonics within the linear limit, and no flight.
void translation_constraints(const std::vector<double>& p, const DesignOptions& opt, double g, double T, double* c) {
    for (int k = 0; k < 6; ++k) c[k] = (std::hypot(p[2 * k], p[2 * k + 1]) - opt.lin_limit) / std::max(opt.lin_limit, 1e-12);
    c[6] = opt.flight_margin - vertical_margin(transport_motion(p, T), g, opt.region);
}

struct TransportProblem : Problem<TransportProblem> {
    TransportProblem(const Scene& part_, const Vec2& v_, const DesignOptions& opt_, double T_, std::atomic<long>* cycles_)
        : Problem(part_, opt_, T_, cycles_), target(v_) {}
    Vec2 target;
    static constexpr int kParams = 12;
    static constexpr const char* kFamily = "x, y, z at n = 1, 2";
    static constexpr int kConstraints = 7;   // six harmonic amplitudes, the flight margin
    double limit(int) const { return opt.lin_limit; }
    bool is_free(int i) const { return free(kTranslationAxes, {1, 2}, i); }
    void constraints(const std::vector<double>& p, double* c) const { translation_constraints(p, opt, part.g, T, c); }
    double evaluate(const std::vector<double>& p) {
        ++evaluations;
        Scene sc = part;
        sc.plate = transport_motion(p, T);
        Vec2 v;
        if (!twist_at(sc, Vec2::Zero(), v)) return 1e3;
        return (v - target).norm() / target.norm();
    }
};

DesignSummary design_transport(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt, double T) {
    const auto t0 = Clock::now();
    DesignSummary sum;
    sum.notes.push_back("a plate that only translates (x, y, z): a point part's velocity field is the same everywhere");
    std::atomic<long> cycles{0};
    // A rigid part with one friction coefficient moves on a translating plate as a point part with
    // that coefficient (DesignTarget): the search runs on that point part, the verification on the part.
    Scene point = part_scene;
    if (!point.part.point) {
        sum.notes.push_back("a rigid part with one friction coefficient on a plate that only translates: it moves as a point "
                            "part with that coefficient (no turn; the same velocity at every orientation); designed as that "
                            "point part, verified as the part itself");
        point.part.point = true;
        point.part.mu.setConstant(part_scene.part.mu[0]);
    }
    const auto make = [&] { return TransportProblem(point, target.velocity, opt, T, &cycles); };
    // (stop within 0.01% of the target speed)
    const std::vector<double> best = multistart<TransportProblem>(opt, 1e-4, make, sum.evaluations);
    start_summary(sum, part_scene, "_transport", T);
    if (best.empty()) {
        sum.failure = kNoFeasibleMotion;
        return finished(sum, cycles, t0);
    }
    sum.scene.plate = combined(transport_motion(best, T));
    sum.min_vertical_margin = vertical_margin(sum.scene.plate, sum.scene.g, flight_region(sum.scene, opt));
    // Verification: the field on the grid (mean and spread), then full dynamics from random starts.
    const Field f = verification_field(sum.scene, opt);
    int undefined = 0;
    for (const FieldPoint& p : f.points) {
        if (!p.converged) ++undefined;
        else sum.transport_mean += p.twist.head<2>();
    }
    if (undefined < static_cast<int>(f.points.size())) sum.transport_mean /= static_cast<double>(f.points.size() - undefined);
    for (const FieldPoint& p : f.points)
        if (p.converged) {
            sum.transport_spread = std::max(sum.transport_spread, (p.twist.head<2>() - sum.transport_mean).norm());
            if (!sum.scene.part.point) sum.transport_turn = std::max(sum.transport_turn, std::abs(p.twist[2]));
        }
    sum.transport_tolerance = 0.02 * target.velocity.norm();
    // (a rigid part: theta' within the same 2 %, turned into an angular rate by the part's radius rho)
    const double turn_tolerance = sum.transport_tolerance / sum.scene.part.rho();
    // Each run for a region's width of travel (1-20 s), judged over its second half: released at rest
    // the part lags the plate's drive while its cycle builds up (about 0.1 s on fig1_point: 9.6 mm at
    // 0.08 m/s, which a check from the start counted against the design; an outside audit found it),
    // so the distance is from where the target velocity takes it from the run's midpoint, within the
    // field's 2 % over that half (and 5 mm).
    const int stopped = verification_runs(
        sum, opt, [&](const DesignStartRun&) { return std::clamp(0.05 / target.velocity.norm(), 1.0, 20.0); },
        [&](const DesignStartRun& r, const Vec3& end) {   // (a rigid part's turn over the half: 0.05 rad counts as 5 mm)
            return std::max((end.head<2>() - r.at_from.head<2>() - target.velocity * (r.seconds - r.from)).norm(),
                            sum.scene.part.point ? 0.0 : std::abs(end[2] - r.at_from[2]) * opt.verify_distance / 0.05);
        },
        nullptr, 0.5);
    double allowed = opt.verify_distance;
    for (const DesignStartRun& r : sum.runs) allowed = std::min(allowed, sum.transport_tolerance * (r.seconds - r.from));
    sum.unique = true;   // (no fixed point is sought)
    if (undefined) sum.failure = std::to_string(undefined) + " configurations of the field are undefined";
    else if (!((sum.transport_mean - target.velocity).norm() <= sum.transport_tolerance))
        sum.failure = "the field's mean velocity (" + std::to_string(sum.transport_mean.x()) + ", " +
                      std::to_string(sum.transport_mean.y()) + ") m/s misses the target by more than 2%: out of reach within the limits";
    else if (!(sum.transport_spread <= sum.transport_tolerance))
        sum.failure = "the field is not uniform over the region";
    else if (!(sum.transport_turn <= turn_tolerance))
        sum.failure = "the part turns (theta' up to " + std::to_string(sum.transport_turn) + " rad/s on the grid)";
    else if (stopped)
        sum.failure = std::to_string(stopped) + " full-dynamics run(s) left the model";
    else if (!(sum.worst_end_distance <= allowed))
        sum.failure = "a full-dynamics run ended " + std::to_string(sum.worst_end_distance) +
                      " m from where the target velocity takes it over the run's second half (allowed " +
                      std::to_string(allowed) + " m: 2 % of the travel)";
    sum.verified = sum.failure.empty();
    return finished(sum, cycles, t0);
}

// --- the rigid part's orientation: a weathervane ------------------------------------------------
// A plate that only translates (transport_motion) gives the part nothing that depends on where it is
// (no alpha x r, no tilt, no coning: its full dynamics are its U-dynamics), so the twist is a function
// of theta alone, the same at every position. With every contact sliding along one direction u (the
// part not turning), friction's torque about the centre of mass is -(sum_i mu_i N_i r_i) x u, and the
// normal forces balance friction's moment about the horizontal axes, which makes sum_i N_i r_i
// parallel to u: with one friction coefficient the torque vanishes, and such a plate never turns the
// part (tests/test_design.cpp). With unequal ones it is a weathervane: the torque vanishes where
// sum_i (mu_i - mu) N_i r_i lies along u; on a plate shaken along one line with a heave in phase
// (the transport driven by the normal force: the part slips backwards while pressed hardest, and
// friction pushes it on) the part turns until its high-friction contact leads -- one stable
// orientation in the turn (where the transport is driven otherwise, e.g. by a sawtooth, the foot
// may trail; other motions put it elsewhere, still one). The search
// shapes theta'(theta) on a ring of kRing orientations to one stable zero, as steep as it can be,
// and rotate_motion turns that zero onto THETA.
constexpr int kRing = 12, kFineRing = 72;

// theta' at the centre on a ring of n equally spaced orientations from 0 (false if a cycle did not
// converge); twist receives the whole twists if given.
bool orientation_ring(const Scene& sc, int n, const LimitCycleOptions& cyc, std::atomic<long>& cycles, std::vector<double>& th,
                      std::vector<double>& w, std::vector<Vec3>* twist = nullptr) {
    th.resize(n);
    w.resize(n);
    if (twist) twist->resize(n);
    for (int k = 0; k < n; ++k) {
        th[k] = 2 * kPi * k / n;
        const LimitCycleSummary lc = limit_cycle(sc, Vec3(0, 0, th[k]), cyc);
        ++cycles;
        if (!lc.converged) return false;
        w[k] = lc.twist[2];
        if (twist) (*twist)[k] = lc.twist;
    }
    return true;
}

// The stable zeros of theta' on a ring (theta' falls through zero going round): their number, and
// the steepest one's angle (linear between the ring's points) and rate -d theta'/d theta.
struct RingZeros {
    int stable = 0;
    double theta = 0, rate = 0;
};
RingZeros ring_zeros(const std::vector<double>& th, const std::vector<double>& w) {
    RingZeros z;
    const int n = static_cast<int>(w.size());
    const double h = 2 * kPi / n;
    for (int k = 0; k < n; ++k) {
        const double a = w[k], b = w[(k + 1) % n];
        if (!(a > 0 && b <= 0)) continue;
        ++z.stable;
        if ((a - b) / h > z.rate) {
            z.rate = (a - b) / h;
            z.theta = wrap_angle(th[k] + h * a / (a - b));
        }
    }
    return z;
}

// The largest amplitude a turned pair of x, y phasors (X, Y) reaches over every turn: the square root
// of the largest eigenvalue of their Gram matrix. The design is turned onto THETA afterwards, so the
// limits must hold at every turn.
double turned_amplitude(double xc, double xs, double yc, double ys) {
    const double xx = xc * xc + xs * xs, yy = yc * yc + ys * ys, xy = xc * yc + xs * ys;
    return std::sqrt(0.5 * (xx + yy) + std::hypot(0.5 * (xx - yy), xy));
}

struct OrientProblem : Problem<OrientProblem> {
    using Problem::Problem;
    static constexpr int kParams = 12;   // transport_motion's layout: x, y, z; n = 1, 2; cos, sin
    static constexpr const char* kFamily = "x, y, z at n = 1, 2";
    static constexpr int kConstraints = 5;   // x-y at any turn (n = 1, 2), z (n = 1, 2), the flight margin
    double limit(int) const { return opt.lin_limit; }
    bool is_free(int i) const { return free(kTranslationAxes, {1, 2}, i); }
    void constraints(const std::vector<double>& p, double* c) const {
        const double L = std::max(opt.lin_limit, 1e-12);
        for (int h = 0; h < 2; ++h) {
            c[h] = (turned_amplitude(p[2 * h], p[2 * h + 1], p[4 + 2 * h], p[4 + 2 * h + 1]) - opt.lin_limit) / L;
            c[2 + h] = (std::hypot(p[8 + 2 * h], p[8 + 2 * h + 1]) - opt.lin_limit) / L;
        }
        c[4] = opt.flight_margin - vertical_margin(transport_motion(p, T), part.g, opt.region);
    }
    // One stable orientation on the ring: minus its rate [1/s]; else the number of stable ones less
    // one, or 1 for none (a part that does not turn).
    double evaluate(const std::vector<double>& p) {
        ++evaluations;
        Scene sc = part;
        sc.plate = transport_motion(p, T);
        std::vector<double> th, w;
        if (!orientation_ring(sc, kRing, opt.cycle, *cycles, th, w)) return 1e3;
        const RingZeros z = ring_zeros(th, w);
        return z.stable == 1 ? -z.rate : z.stable == 0 ? 1.0 : z.stable - 1.0;
    }
};

// The time the averaged turning, theta' = w(theta) linear between the ring's points, takes from
// theta0 to within `within` of the stable orientation theta_s (steps of 5 mrad; at most `cap`).
double turn_time(const std::vector<double>& w, double theta0, double theta_s, double within, double cap) {
    const int n = static_cast<int>(w.size());
    const double h = 2 * kPi / n;
    auto at = [&](double x) {
        const double u = (x - 2 * kPi * std::floor(x / (2 * kPi))) / h;
        const int k = static_cast<int>(u) % n;
        return w[k] + (u - std::floor(u)) * (w[(k + 1) % n] - w[k]);
    };
    double t = 0, x = theta0;
    while (std::abs(wrap_angle(x - theta_s)) > within && t < cap) {
        const double v = at(x);
        if (v == 0) return cap;
        t += 5e-3 / std::abs(v);
        x += v > 0 ? 5e-3 : -5e-3;
    }
    return std::min(t, cap);
}

DesignSummary design_orient(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt, double T) {
    const auto t0 = Clock::now();
    DesignSummary sum;
    sum.notes.push_back("orient by transport, a weathervane: a plate that only translates (x, y, z; n = 1, 2) gives the "
                        "part the same twist at every position and full dynamics equal to its U-dynamics (no tilt, no "
                        "coning); with unequal friction coefficients on its contacts the part turns to where friction's "
                        "torque vanishes (on a plate shaken along one line with a heave in phase: its high-friction contact "
                        "leads)");
    sum.notes.push_back("position free: the part travels while it turns and after (velocity_at_orientation)");
    sum.notes.push_back("designed on a ring of " + std::to_string(kRing) + " orientations and turned onto THETA "
                        "(the field turns with the motion); the limits hold at every turn");
    std::atomic<long> cycles{0};
    const auto make = [&] {
        OrientProblem p(part_scene, opt, T, &cycles);
        p.guess = params_from(part_scene.plate, kTranslationAxes, {1, 2});
        return p;
    };
    const std::vector<double> best = multistart<OrientProblem>(opt, -HUGE_VAL, make, sum.evaluations);
    start_summary(sum, part_scene, "_orient", T);
    if (best.empty()) {
        sum.failure = kNoFeasibleMotion;
        return finished(sum, cycles, t0);
    }
    Scene centred = part_scene;
    centred.plate = transport_motion(best, T);
    std::vector<double> th, w;
    RingZeros z;
    if (orientation_ring(centred, kRing, opt.cycle, cycles, th, w)) z = ring_zeros(th, w);
    if (z.stable != 1) {
        sum.failure = "no plate motion that only translates found turns the part to one orientation" +
                      std::string(z.stable == 0 ? " (it does not turn it at all: with one friction coefficient on "
                                                  "every contact none can)" : "");
        return finished(sum, cycles, t0);
    }
    // The stable orientation by bisection on theta' (at the refinement's tolerances), its rate by
    // central differences.
    LimitCycleOptions fine = opt.cycle;
    fine.integration.rtol = 1e-9;
    fine.tol = 1e-8;
    auto w_at = [&](double a) {
        const LimitCycleSummary lc = limit_cycle(centred, Vec3(0, 0, a), fine);
        ++cycles;
        return lc.converged ? lc.twist[2] : std::numeric_limits<double>::quiet_NaN();
    };
    const double h = 2 * kPi / kRing;
    double lo = z.theta - 0.5 * h, hi = z.theta + 0.5 * h;
    if (!(w_at(lo) > 0 && w_at(hi) <= 0)) {
        sum.failure = "the ring's stable orientation did not survive the refinement's tolerances";
        return finished(sum, cycles, t0);
    }
    bool defined = true;
    while (defined && hi - lo > 1e-7) {
        const double m = 0.5 * (lo + hi), wm = w_at(m);
        defined = std::isfinite(wm);
        (wm > 0 ? lo : hi) = m;
    }
    const double theta_s = 0.5 * (lo + hi);
    sum.rate = -(w_at(theta_s + 0.01) - w_at(theta_s - 0.01)) / 0.02;
    if (!defined || !std::isfinite(sum.rate)) {
        sum.failure = "a cycle did not converge while the stable orientation was refined";
        return finished(sum, cycles, t0);
    }
    sum.eigenvalues3 = Eigen::Vector3cd(0, 0, -sum.rate);   // positions are neutral: the field is theta's alone
    sum.scene.plate = combined(rotate_motion(centred.plate, target.theta - theta_s));
    sum.min_vertical_margin = vertical_margin(sum.scene.plate, sum.scene.g, flight_region(sum.scene, opt));
    double c[OrientProblem::kConstraints];
    OrientProblem(part_scene, opt, T, &cycles).constraints(params_from(sum.scene.plate, kTranslationAxes, {1, 2}), c);
    if (*std::max_element(c, c + OrientProblem::kConstraints) > 1e-9) {
        sum.failure = "the turned motion exceeds the amplitude limits or the flight margin";
        return finished(sum, cycles, t0);
    }

    // --- verification: a fine ring at the centre (one stable orientation, at THETA), the 7^3 field
    // (the same twist at every position), full dynamics from random starts.
    std::vector<Vec3> ring;
    if (!orientation_ring(sum.scene, kFineRing, opt.cycle, cycles, th, w, &ring)) {
        sum.failure = "a cycle on the verification ring did not converge";
        return finished(sum, cycles, t0);
    }
    sum.ring_theta = th;
    sum.ring_twist = ring;
    const RingZeros zf = ring_zeros(th, w);
    sum.fixed_point = Vec3(0, 0, zf.theta);
    sum.fixed_point_eigenvalues = sum.eigenvalues3;
    {   // the twist at the orientation: the travel (linear between the ring's points)
        const double u = (zf.theta - 2 * kPi * std::floor(zf.theta / (2 * kPi))) / (2 * kPi / kFineRing);
        const int k = static_cast<int>(u) % kFineRing;
        sum.transport_mean = ring[k].head<2>() + (u - std::floor(u)) * (ring[(k + 1) % kFineRing] - ring[k]).head<2>();
    }
    const bool at_theta = zf.stable == 1 && std::abs(wrap_angle(zf.theta - target.theta)) <= 0.02;
    sum.unique = at_theta;
    const Field f = verification_field(sum.scene, opt);
    // (each of the field's cycles is within cycle_noise of its limit, from its own warm start)
    const Vec3 S(part_scene.v_ref(), part_scene.v_ref(), part_scene.v_ref() / part_scene.part.rho());
    int undefined = 0;
    double spread = 0;
    for (const FieldPoint& p : f.points) {
        if (!p.converged) { ++undefined; continue; }
        for (const FieldPoint& o : f.points)
            if (o.converged && o.q[2] == p.q[2]) spread = std::max(spread, (p.twist - o.twist).cwiseQuotient(S).cwiseAbs().maxCoeff());
    }
    sum.transport_spread = spread;   // (relative to v_ref and v_ref / rho)
    sum.transport_tolerance = 2 * cycle_noise(opt.cycle);
    const int stopped = verification_runs(
        sum, opt,
        [&](const DesignStartRun& r) { return 1.5 * turn_time(w, r.theta, zf.theta, 0.01, 200) + 2; },
        [&](const DesignStartRun&, const Vec3& end) {
            return std::abs(wrap_angle(end[2] - target.theta)) * opt.verify_distance / 0.05;
        });
    int reached = 0;
    for (const DesignStartRun& r : sum.runs) reached += r.stop.empty() && r.end_distance <= opt.verify_distance;
    sum.basin_share = sum.runs.empty() ? 0.0 : static_cast<double>(reached) / sum.runs.size();
    if (!at_theta)
        sum.failure = "the verification ring has " + std::to_string(zf.stable) + " stable orientation(s), the nearest " +
                      std::to_string(zf.theta) + " rad";
    else if (undefined)
        sum.failure = std::to_string(undefined) + " configurations of the field are undefined";
    else if (!(spread <= sum.transport_tolerance))
        sum.failure = "the field is not the same at every position (the motion is not a translation?)";
    else if (stopped)
        sum.failure = std::to_string(stopped) + " full-dynamics run(s) left the model";
    else if (!(sum.worst_end_distance <= opt.verify_distance))
        sum.failure = "a full-dynamics run ended " + std::to_string(sum.worst_end_distance / opt.verify_distance * 0.05) +
                      " rad from THETA";
    else if (!(sum.min_vertical_margin >= opt.flight_margin - 1e-9))
        sum.failure = "the vertical acceleration margin is below the one asked";
    sum.verified = sum.failure.empty();
    return finished(sum, cycles, t0);
}

// --- the rigid part's fixed point (and orientation) ----------------------------------------------
// Parameters: cosine and sine coefficients of harmonics n = 1, 2 on all six axes (24). z, rz and the
// second harmonics break the pairing of fixed points (s, theta), (-s, theta + pi) that odd x, y, rx,
// ry motions force (design.hpp), so the centre is no longer a fixed point by construction: the search
// makes (0, 0, 0) one -- fast, and pulling the region's edge and every orientation towards it -- and
// the fixed point found near the centre, q*, is then placed exactly on the target by the two
// symmetries: turned by THETA - theta*, shifted by the target minus the turned s*.
const std::vector<Axis> kRigidAxes = {Axis::x, Axis::y, Axis::z, Axis::rx, Axis::ry, Axis::rz};
PlateMotion rigid_motion(const std::vector<double>& p, double T) { return motion_from(p, kRigidAxes, {1, 2}, T); }

// Constraints c_k <= 0 on a motion as placed: each (axis, n <= n_max) amplitude within its limit times
// `room`, no flight under the part's contacts over the region, no coning beyond kConingLimit either
// way and no tilt drift beyond kTiltDriftLimit (6 n_max + 4 entries).
void placed_constraints(const PlateMotion& fin, const DesignOptions& opt, const Scene& part, int n_max, double room,
                        double* c) {
    const int k = amplitude_constraints(fin, opt, part, n_max, room, c);
    const double cone = coning_rate(fin) / kConingLimit;
    c[k] = cone - 1;
    c[k + 1] = -cone - 1;
    c[k + 2] = tilt_drift_rate(fin).norm() / kTiltDriftLimit - 1;
}

// The field xi_a at q and its Jacobian by central differences (steps 3 mm and 0.1 rad), warm-started
// from the cycle at q. False if a cycle did not converge.
bool twist_and_jacobian(const Scene& sc, const Vec3& q, const LimitCycleOptions& cyc, Vec3& xi, Mat3& J,
                        std::atomic<long>& cycles) {
    const LimitCycleSummary c0 = limit_cycle(sc, q, cyc);
    ++cycles;
    if (!c0.converged) return false;
    xi = c0.twist;
    const double h[3] = {0.003, 0.003, 0.1};
    for (int d = 0; d < 3; ++d) {
        Vec3 e = Vec3::Zero();
        e[d] = h[d];
        const LimitCycleSummary p = limit_cycle(sc, q + e, cyc, c0.qd_start), m = limit_cycle(sc, q - e, cyc, c0.qd_start);
        cycles += 2;
        if (!p.converged || !m.converged) return false;
        J.col(d) = (p.twist - m.twist) / (2 * h[d]);
    }
    return true;
}

struct RigidProblem : Problem<RigidProblem> {
    RigidProblem(const Scene& part_, const DesignTarget& t_, const DesignOptions& opt_, double T_, std::atomic<long>* cycles_)
        : Problem(part_, opt_, T_, cycles_), target(t_) {
        if (std::abs(part_.plate.T - T_) <= 1e-12 * T_)
            guess = params_from(part_.plate, kRigidAxes, {1, 2});
    }
    DesignTarget target;
    static constexpr int kParams = 24;
    static constexpr const char* kFamily = "x, y, z, rx, ry, rz at n = 1, 2";
    static constexpr int kConstraints = 16;   // twelve amplitudes, the flight margin, coning both ways, tilt drift
    // The search keeps 3% of each limit in hand for the final placement's correction (shifting by the
    // found fixed point's offset, a few mm, adds alpha x offset to the linear amplitudes).
    static constexpr double kRoom = 0.97;
    double limit(int i) const { return i < 12 ? opt.lin_limit : opt.ang_limit; }
    bool is_free(int i) const { return free(kRigidAxes, {1, 2}, i); }
    void constraints(const std::vector<double>& p, double* c) const {
        placed_constraints(combined(shift_motion(rotate_motion(rigid_motion(p, T), target.theta), target.at)), opt,
                           part, 2, kRoom, c);
    }
    // -rate at the centre, plus how far the centre is from being the fixed point (the Newton step
    // J^-1 xi there, over 1 cm / 0.1 rad), plus how much the region's edge (8 points, theta = 0) and
    // the orientations at the centre (8, all round) are not drawn towards the centre.
    double evaluate(const std::vector<double>& p, double* rate_out = nullptr, Eigen::Vector3cd* eig_out = nullptr) {
        ++evaluations;
        Scene sc = part;
        sc.plate = rigid_motion(p, T);
        Vec3 xi;
        Mat3 J;
        if (!twist_and_jacobian(sc, Vec3::Zero(), opt.cycle, xi, J, *cycles)) return 1e3;
        const Eigen::Vector3cd ev = J.eigenvalues();
        const double rate = -std::max({ev[0].real(), ev[1].real(), ev[2].real()});
        if (rate_out) *rate_out = rate;
        if (eig_out) *eig_out = ev;
        const Vec3 step = J.fullPivLu().solve(xi);
        const double off = step.allFinite() ? std::hypot(step.head<2>().norm() / 0.01, step[2] / 0.1) : 10.0;
        double outward = 0;
        for (const Vec2& s : region_edge(opt.region)) {
            const LimitCycleSummary c = limit_cycle(sc, Vec3(s.x(), s.y(), 0), opt.cycle);
            ++*cycles;
            if (!c.converged) return 1e3;
            outward += std::max(0.0, s.dot(c.twist.head<2>()) / s.squaredNorm());   // [1/s]
        }
        Vec3 warm = Vec3::Zero();
        for (int k = 0; k < 8; ++k) {
            const double th = -kPi + (k + 0.5) * kPi / 4;
            const LimitCycleSummary c = limit_cycle(sc, Vec3(0, 0, th), opt.cycle, warm);
            ++*cycles;
            if (!c.converged) return 1e3;
            warm = c.qd_start;
            outward += std::max(0.0, c.twist[2] * th / (th * th));   // [1/s]
        }
        return -rate + 10 * outward + 5 * off * off;
    }
};

DesignSummary& place_and_verify_rigid(DesignSummary& sum, const Scene& part_scene, const PlateMotion& centred_motion,
                                      const Vec3& q0, const DesignTarget& target, const DesignOptions& opt,
                                      std::atomic<long>& cycles, Clock::time_point t0, bool pair = false,
                                      double run_seconds = 0, double theta_offset = 0);

// A centred motion whose fixed point is q, placed so that it lands on (at, THETA - theta_offset): turned
// by THETA - theta_offset - q_theta about the origin (the field turns), then shifted by `at` less the
// turned s (the field shifts).
PlateMotion placed_motion(const PlateMotion& centred, const Vec3& q, const Vec2& at, double theta, double theta_offset = 0) {
    const double turn = theta - theta_offset - q[2];
    return combined(shift_motion(rotate_motion(centred, turn), at - Eigen::Rotation2Dd(turn) * Vec2(q.head<2>())));
}

// --- the half-turn pair broken: rz about its centre ---------------------------------------------------
// (Measured on fig4's pair, 2026-11-28: docs/inverse-design.md.) At the pair's fixed point theta' has a
// mean M and a second harmonic B_2 (0.007 and 0.088 rad/s) and no first. rz at n = 2 about the design's
// centre keeps the pairing (a half turn leaves rz, half a period leaves n = 2) but moves M and B_2 (with
// 50 rad/s^2: 0.030 and 0.035), so the pair's two stable orientations, at theta''s two minima, come
// near a saddle-node; rz at n = 1 breaks the pairing (half a period reverses it) and adds a first
// harmonic of 0.005-0.015 rad/s -- ten times what x, y, rx and ry gave there -- which lifts one minimum
// above zero and leaves one stable orientation. First rx and ry at n = 1 are made parallel (the pair's
// are a few degrees apart) and rz at n = 1 takes their direction: rotations about two axes a quarter
// period apart turn the plate steadily (tilt_drift_rate; a trial with rz out of line drifted 1e-3 rad/s
// and every full-dynamics run left the plate after 36 s). A grid over rz's amplitudes, its phase at n =
// 2 and its sense at n = 1 is screened by theta' on a ring of orientations at the pair's fixed point
// (exactly one stable zero), the survivors refined to their fixed point (stable, near the centre) and
// verified like every rigid design, the shortest passage round the ring first (it sets the runs'
// length), each first with theta''s other wells along s*(theta), where the field's fixed points lie,
// lifted clear of zero (lift_wells: the screen's ring at the centre misses a shallow one); the first
// that verifies as unique is returned, else the verified one with the largest share of the runs
// (design_rigid_pair keeps it where that beats the pair's).
constexpr int kBreakRing = 24;      // orientations of the screening ring
constexpr int kBreakVerified = 3;   // candidates verified at most
constexpr int kWellRing = 48;       // orientations of the ring along s* (lift_wells)
constexpr int kLiftSteps = 16;      // lift_wells's pattern-search steps at most
// [rad/s] the shallowest other well's clearance above zero (fig4 with 0.006 or 0.01: lifted to 0.012, where
// the candidate's fixed point was not found again, and the pair's remnant stayed)
constexpr double kWellMargin = 0.003;

// The pair's motion with rx and ry at n = 1 turned onto one line (each keeps its amplitude; the line is
// their amplitude-weighted direction, b + a or b - a), and that line's phase psi.
PlateMotion aligned_tilts(const PlateMotion& u, double& psi) {
    auto ph = phasors(u);
    const std::pair<int, int> kx{static_cast<int>(Axis::rx), 1}, ky{static_cast<int>(Axis::ry), 1};
    const std::complex<double> a = ph.count(kx) ? ph[kx] : 0.0, b = ph.count(ky) ? ph[ky] : 0.0;
    const double sense = std::real(a * std::conj(b)) < 0 ? -1.0 : 1.0;
    const std::complex<double> line = b + sense * a;
    psi = std::abs(line) > 0 ? std::arg(line) : 0.0;
    PlateMotion r;
    r.T = u.T;
    for (const auto& [k, z] : ph) {
        double amp = std::abs(z), phase = std::arg(z);
        if (k == kx) phase = psi + (sense < 0 ? kPi : 0.0);
        if (k == ky) phase = psi;
        if (amp > 0) r.harmonics.push_back({static_cast<Axis>(k.first), k.second, amp, phase});
    }
    return r;
}

// theta' along the position's fixed points: on n orientations theta_k, s*(theta_k), where the position's
// twist vanishes, linearised about `base` (one-sided differences, 2 mm), and w*(theta_k), theta' there.
// The field's fixed points are exactly the zeros of w*; where the position converges faster than the
// orientation, a stable one is a zero w* falls through. (theta' at one position alone misses them:
// on fig4's broken pair s* strays 6 mm from the centre, where theta' differs by 0.02 rad/s, and a
// shallow well that stays above zero at the centre dips below it along s*.) False where a cycle did
// not converge.
bool reduced_ring(const Scene& sc, const Vec2& base, int n, const LimitCycleOptions& cyc, long& own, double* w) {
    Vec3 warm = Vec3::Zero();
    const double hs = 0.002;
    for (int k = 0; k < n; ++k) {
        const Vec3 q0(base.x(), base.y(), -kPi + 2 * kPi * k / n);
        const LimitCycleSummary c = limit_cycle(sc, q0, cyc, warm);
        ++own;
        if (!c.converged) return false;
        warm = c.qd_start;
        const LimitCycleSummary cx = limit_cycle(sc, q0 + Vec3(hs, 0, 0), cyc, warm),
                                cy = limit_cycle(sc, q0 + Vec3(0, hs, 0), cyc, warm);
        own += 2;
        if (!cx.converged || !cy.converged) return false;
        Eigen::Matrix2d Jss;
        Jss.col(0) = (cx.twist - c.twist).head<2>() / hs;
        Jss.col(1) = (cy.twist - c.twist).head<2>() / hs;
        const Vec2 ds = -Jss.fullPivLu().solve(Vec2(c.twist.head<2>()));
        if (!ds.allFinite()) return false;
        w[k] = c.twist[2] + (cx.twist[2] - c.twist[2]) / hs * ds.x() + (cy.twist[2] - c.twist[2]) / hs * ds.y();
    }
    return true;
}

// The shallowest well of theta' round a ring of n other than the target's: the target's well is the arc
// where theta' < 0 from the stable zero nearest theta_target (theta' falls through it) to the unstable
// one; every local minimum outside that arc (a parabola through it and its neighbours) is another well,
// and the lowest of them is returned -- negative where it holds a second stable orientation, the
// ring's largest value where there is none, -infinity without a stable zero.
double other_well(const double* w, int n, double theta_target) {
    const double h = 2 * kPi / n;
    int at = -1;
    for (int k = 0; k < n; ++k)
        if (w[k] > 0 && w[(k + 1) % n] <= 0 &&
            (at < 0 || std::abs(wrap_angle(-kPi + h * (k + 0.5) - theta_target)) <
                           std::abs(wrap_angle(-kPi + h * (at + 0.5) - theta_target))))
            at = k;
    if (at < 0) return -HUGE_VAL;
    std::vector<bool> own(n, false);
    for (int k = (at + 1) % n; w[k] <= 0 && !own[k]; k = (k + 1) % n) own[k] = true;
    double lowest = *std::max_element(w, w + n);
    for (int k = 0; k < n; ++k) {
        const double a = w[(k + n - 1) % n], b = w[k], c = w[(k + 1) % n];
        if (own[k] || !(b <= a && b < c)) continue;
        const double curv = a - 2 * b + c;
        lowest = std::min(lowest, curv > 0 ? b - (c - a) * (c - a) / (8 * curv) : b);
    }
    return lowest;
}

// theta' = w(theta) round a ring of n (linear between its points), with exactly one stable zero: the
// time to within 0.05 rad of it, both ways from 0.01 rad past the unstable zero (of 20 uniform starts,
// one lies that close with probability 0.06) -- the slowest start's time, which the narrowest passage
// sets (the linear rate alone says nothing of it); infinity without exactly one stable zero.
double ring_passage(const double* w, int n) {
    int stable = 0, at = -1, unstable = -1;
    for (int k = 0; k < n; ++k) {
        if (w[k] > 0 && w[(k + 1) % n] <= 0) ++stable, at = k;
        if (w[k] < 0 && w[(k + 1) % n] >= 0) unstable = k;
    }
    if (stable != 1 || unstable < 0) return HUGE_VAL;
    const double h = 2 * kPi / n;
    const double th_s = -kPi + h * (at + w[at] / (w[at] - w[(at + 1) % n]));
    const double th_u = -kPi + h * (unstable + w[unstable] / (w[unstable] - w[(unstable + 1) % n]));
    auto w_at = [&](double th) {
        const double x = (wrap_angle(th) + kPi) / h;
        const int k = static_cast<int>(std::floor(x)) % n;
        const double f = x - std::floor(x);
        return (1 - f) * w[k] + f * w[(k + 1) % n];
    };
    double passage = 0;
    for (double dir : {1.0, -1.0}) {
        double th = th_u + dir * 0.01, t = 0;
        while (std::abs(wrap_angle(th - th_s)) > 0.05 && t < 1000) {
            const double v = w_at(th);
            const double dt = std::min(1.0, 0.01 / std::max(std::abs(v), 1e-6));
            th += v * dt;
            t += dt;
        }
        passage = std::max(passage, t);
    }
    return passage;
}

DesignSummary break_pair(const Scene& part_scene, const PlateMotion& pair_motion, const DesignTarget& target,
                         const DesignOptions& opt, double T, std::atomic<long>& cycles, Clock::time_point t0) {
    std::string failure = "no rz about the pair's centre left one stable orientation there";
    double psi = 0;
    const PlateMotion aligned0 = aligned_tilts(pair_motion, psi);
    struct Candidate {
        PlateMotion u;
        Vec3 q;
        double rate;
        double passage;   // [s] the slowest start's way round the ring to the stable orientation
        int index;        // in the grid (ties)
        PlateMotion base;             // the motion before rz: the pair's, tilts aligned, scaled
        std::array<double, 4> g;      // rz's setting
        double scale;
    };
    std::vector<Candidate> found;
    std::vector<std::array<double, 4>> grid;   // (rz amplitude at n = 1, its sense, at n = 2, its phase)
    const double room = 0.97 * opt.ang_limit;
    for (double a1 : {2.0 / 3, 1.0})
        for (double s1 : {1.0, -1.0})
            for (double a2 : {0.4, 0.5, 0.6, 0.7, 0.8, 1.0})
                for (int k = 0; k < 24; ++k) grid.push_back({a1 * room, s1, a2 * room, -kPi + k * kPi / 12});
    auto with_rz = [&](const PlateMotion& base, const std::array<double, 4>& g) {
        PlateMotion u = base;
        u.harmonics.push_back({Axis::rz, 1, g[0], psi + (g[1] < 0 ? kPi : 0.0)});
        u.harmonics.push_back({Axis::rz, 2, g[2], g[3]});
        return u;
    };
    // The motion with fixed point q, placed as place_and_verify_rigid will place it: within the limits,
    // the flight margin, and the coning and tilt-drift limits.
    auto fits = [&](const PlateMotion& u, const Vec3& q) {
        double con[6 * 3 + 4];
        placed_constraints(placed_motion(u, q, target.at, target.theta), opt, part_scene, 3, 1.0, con);
        return *std::max_element(con, con + 6 * 3 + 4) <= 0;
    };
    // A ring of n values of theta' with exactly one stable zero: its fixed point by Newton from q (not
    // finite: the middle of the zero's cell at the centre), stable and within `reach` of the centre
    // (the screen's 5 mm; 10 mm once lifted, its fixed point found again along s*), the placed motion
    // within the limits and the flight margin; "" where it fails, else "q0 q1 q2 rate passage" (exact
    // text: a task may run in another process).
    auto fixed_point_on = [&](const Scene& sc, const double* w, int n, Vec3 q, double reach, long& own) -> std::string {
        int stable = 0, at = -1;
        for (int k = 0; k < n; ++k)
            if (w[k] > 0 && w[(k + 1) % n] <= 0) ++stable, at = k;
        if (stable != 1) return "";
        if (!q.allFinite()) q = Vec3(0, 0, -kPi + 2 * kPi * (at + 0.5) / n);
        Vec3 xi;
        Mat3 J;
        bool conv = false;
        std::atomic<long> newton{0};
        for (int it = 0; it < 8 && !conv; ++it) {
            if (!twist_and_jacobian(sc, q, opt.cycle, xi, J, newton)) break;
            const Vec3 step = J.fullPivLu().solve(xi);
            if (!step.allFinite()) break;
            q -= step;
            conv = step.head<2>().norm() < 1e-6 && std::abs(step[2]) < 1e-4;
        }
        own += newton.load();
        if (!conv || q.head<2>().norm() > reach) return "";
        const Eigen::Vector3cd ev = J.eigenvalues();
        const double rate = -std::max({ev[0].real(), ev[1].real(), ev[2].real()});
        if (!(rate > 0) || !fits(sc.plate, q)) return "";
        const double passage = ring_passage(w, n);
        return exact_text(q[0]) + ' ' + exact_text(q[1]) + ' ' + exact_text(q[2]) + ' ' + exact_text(rate) + ' ' +
               exact_text(passage);
    };
    // One setting's screen: theta' on the ring at the centre, then its fixed point.
    auto screen = [&](const PlateMotion& base, const std::array<double, 4>& g, long& own) -> std::string {
        Scene sc = part_scene;
        sc.plate = with_rz(base, g);
        double w[kBreakRing];
        Vec3 warm = Vec3::Zero();
        for (int k = 0; k < kBreakRing; ++k) {
            const LimitCycleSummary c = limit_cycle(sc, Vec3(0, 0, -kPi + 2 * kPi * k / kBreakRing), opt.cycle, warm);
            ++own;
            if (!c.converged) return "";
            warm = c.qd_start;
            w[k] = c.twist[2];
        }
        return fixed_point_on(sc, w, kBreakRing, Vec3::Constant(NAN), 0.005, own);
    };
    // The placement turns the motion by THETA less the orientation found, and a pair searched at the
    // flight margin turned that far tilts its corners beyond it (fig4: 0.04-0.09 g over): the sink's
    // harmonics scaled down until some settings fit.
    int tried = 0;
    for (double scale : {1.0, 0.95, 0.9, 0.85, 0.8}) {
        PlateMotion base = aligned0;
        for (Harmonic& hm : base.harmonics) hm.amp *= scale;
        const int n = static_cast<int>(grid.size());
        runner(opt)(
            n,
            [&](int k) -> std::string {
                long own = 0;
                const std::string r = screen(base, grid[k], own);
                return std::to_string(own) + (r.empty() ? "" : " " + r);
            },
            [&](int k, const std::string& text) {
                std::istringstream in(text);
                long own = 0;
                std::string x[5];
                in >> own;
                cycles += own;
                if (!(in >> x[0] >> x[1] >> x[2] >> x[3] >> x[4])) return;
                found.push_back({with_rz(base, grid[k]), Vec3(exact_value(x[0]), exact_value(x[1]), exact_value(x[2])),
                                 exact_value(x[3]), exact_value(x[4]), k, base, grid[k], scale});
            });
        tried += n;
        if (!found.empty()) break;
    }
    // (tasks finish in any order: ranked by the slowest start's passage -- the runs' length and the
    // design's real speed -- ties by the grid's order)
    std::sort(found.begin(), found.end(), [](const Candidate& a, const Candidate& b) {
        return a.passage != b.passage ? a.passage < b.passage : a.index < b.index;
    });
    auto describe = [](const Candidate& c) {
        std::ostringstream what;
        what.precision(3);
        what << "rz " << c.g[0] << " rad/s^2 at n = 1 along the tilts (" << (c.g[1] > 0 ? "+" : "-") << "), " << c.g[2]
             << " rad/s^2 at n = 2, phase " << c.g[3] << ", the sink's harmonics scaled by " << c.scale;
        return what.str();
    };
    // The screen's ring lies at the centre; the field's fixed points lie on the curve s*(theta) where the
    // position's twist vanishes, up to 6 mm away, where a shallow well of theta' can dip below zero
    // (fig4: -0.0016 rad/s, a second stable fixed point the runs never reach). Lifting: rz's three
    // settings (amplitudes, phase at n = 2) moved by a pattern search, each step to the neighbour that
    // lifts the shallowest other well of w* (reduced_ring) the most, steps halved where none does, until
    // it clears kWellMargin; the candidate is replaced where its fixed point is found again within the
    // limits. `lift` says from what to what.
    auto lift_wells = [&](Candidate& c, std::string& lift) -> bool {
        // (the well's clearance, and the passage round the ring for the note; a search for the shortest
        // passage instead, 2026-11-28, went to rz 144 rad/s^2 at n = 1, where the full dynamics settled
        // 0.12-0.13 rad past the field's fixed point, more than the two tolerances' 0.07 together: the
        // smallest change that clears the margin keeps the pair's offset, 0.06 rad)
        struct Score {
            double well = -HUGE_VAL, passage = HUGE_VAL;
        };
        auto score = [&](const std::array<double, 4>& g, long& own) -> Score {
            Score sc0;
            if (g[0] < 0 || g[0] > room || g[2] < 0 || g[2] > room) return sc0;
            Scene sc = part_scene;
            sc.plate = with_rz(c.base, g);
            if (!fits(sc.plate, c.q)) return sc0;
            double w[kWellRing];
            if (!reduced_ring(sc, c.q.head<2>(), kWellRing, opt.cycle, own, w)) return sc0;
            return Score{other_well(w, kWellRing, c.q[2]), ring_passage(w, kWellRing)};
        };
        std::array<double, 4> g = c.g;
        long own0 = 0;
        const Score start = score(g, own0);
        cycles += own0;
        Score now = start;
        double step[3] = {0.05 * room, 0.05 * room, kPi / 48};
        for (int it = 0; it < kLiftSteps && start.well > -HUGE_VAL && now.well < kWellMargin; ++it) {
            std::vector<std::array<double, 4>> next;
            for (int d = 0; d < 3; ++d)
                for (double sgn : {1.0, -1.0}) {
                    std::array<double, 4> t = g;
                    t[d == 0 ? 0 : d == 1 ? 2 : 3] += sgn * step[d];
                    next.push_back(t);
                }
            std::vector<Score> got(next.size());
            runner(opt)(
                static_cast<int>(next.size()),
                [&](int k) -> std::string {
                    long own = 0;
                    const Score v = score(next[k], own);
                    return std::to_string(own) + ' ' + exact_text(v.well) + ' ' + exact_text(v.passage);
                },
                [&](int k, const std::string& text) {
                    std::istringstream in(text);
                    long own = 0;
                    std::string a, b;
                    in >> own >> a >> b;
                    cycles += own;
                    got[k] = Score{exact_value(a), exact_value(b)};
                });
            std::size_t best = 0;
            for (std::size_t k = 1; k < got.size(); ++k)
                if (got[k].well > got[best].well) best = k;
            if (got[best].well > now.well) {
                now = got[best];
                g = next[best];
            } else {
                for (double& st : step) st /= 2;
            }
        }
        std::ostringstream note;
        note.precision(2);
        note << "theta' along the position's fixed points (" << kWellRing << " orientations, linearised): its shallowest "
             << "other well " << start.well << " rad/s";
        if (now.well != start.well) note << ", lifted to " << now.well << " rad/s";
        note << " (" << kWellMargin << " needed), the slowest passage round it " << std::min(now.passage, 1e9) << " s";
        lift = note.str();
        if (now.well < kWellMargin) {
            lift += " -- not applied: the margin not reached";
            return false;
        }
        if (g == c.g) return true;
        Scene sc = part_scene;
        sc.plate = with_rz(c.base, g);
        double w[kWellRing];
        long own = 0;
        const bool ring_ok = reduced_ring(sc, c.q.head<2>(), kWellRing, opt.cycle, own, w);
        const std::string r = ring_ok ? fixed_point_on(sc, w, kWellRing, c.q, 0.01, own) : "";
        cycles += own;
        std::istringstream in(r);
        std::string x[5];
        if (!(in >> x[0] >> x[1] >> x[2] >> x[3] >> x[4])) {
            lift += " -- not applied: the lifted motion's fixed point not found again within the limits";
            return false;
        }
        c.u = sc.plate;
        c.g = g;
        c.q = Vec3(exact_value(x[0]), exact_value(x[1]), exact_value(x[2]));
        c.rate = exact_value(x[3]);
        c.passage = exact_value(x[4]);
        return true;
    };
    DesignSummary kept;   // the best verified so far: unique, else the largest share of the runs
    for (std::size_t i = 0; i < found.size() && static_cast<int>(i) < kBreakVerified; ++i) {
        Candidate c = found[i];
        std::string lift;
        if (opt.lift_wells && !lift_wells(c, lift)) c = found[i];
        DesignSummary sum;
        start_summary(sum, part_scene, "_fixed_point", T);
        sum.evaluations = tried;
        // Where the full dynamics settles: from the field's fixed point, as placed, over whole periods
        // until the slow mode has decayed, theta averaged over the last period (it swings within each);
        // the offset is then split in proportion to the two tolerances (the field's fixed point within
        // 0.02 rad of THETA, the runs within 0.05): the field's placed 2/7 of it short of THETA, the full
        // dynamics' 5/7 past it.
        const double settle = std::ceil(settle_time(2 * opt.region, c.rate, opt) / T) * T;
        double offset = 0;
        {
            Scene placed = part_scene;
            placed.plate = placed_motion(c.u, c.q, target.at, target.theta);
            IntegrationOptions io;
            io.rtol = 1e-7;
            const Trajectory tr = simulate(placed, Dynamics::Full, Vec3(target.at.x(), target.at.y(), target.theta), Vec3::Zero(),
                                           settle, T / 20, io);
            double sum_off = 0;
            int count = 0;
            for (const Sample& smp : tr.samples)
                if (smp.t > settle - T + 1e-9 * T) sum_off += wrap_angle(smp.q[2] - target.theta), ++count;
            if (tr.stop.reason == StopReason::None && count > 0) offset = sum_off / count;
        }
        const double short_of = offset * 0.02 / (0.02 + 0.05);
        place_and_verify_rigid(sum, part_scene, c.u, c.q, target, opt, cycles, t0, false, 1.5 * c.passage + settle, short_of);
        if (!lift.empty()) sum.notes.push_back(lift);
        sum.notes.push_back("the half-turn pair broken by " + describe(c) +
                            " about its centre (rx and ry at n = 1 made parallel first: no tilt drift)");
        if (offset != 0) {
            std::ostringstream note;
            note.precision(2);
            note << "the full dynamics settles " << offset << " rad past the field's fixed point (averaged over a period): "
                 << "the field's is placed " << short_of << " rad short of THETA, the full dynamics' " << offset - short_of
                 << " past it (the tolerances' 0.02 : 0.05)";
            sum.notes.push_back(note.str());
        }
        if (sum.verified && sum.unique) return sum;
        if (sum.verified && (!kept.verified || sum.basin_share > kept.basin_share)) kept = sum;
        failure = "the first " + std::to_string(i + 1) + " of " + std::to_string(found.size()) +
                  " candidates with one stable orientation at the centre did not verify as unique (the last: " +
                  (sum.failure.empty() ? "verified with another stable fixed point, or unsearched cells, on the grid"
                                       : sum.failure) + ")";
        if (kept.verified && kept.basin_share >= 0.9) break;
    }
    if (kept.verified) {
        kept.notes.push_back("not unique: " + failure);
        return kept;
    }
    DesignSummary none;
    none.evaluations = tried;
    none.failure = found.empty() ? failure + " within the flight margin (" + std::to_string(tried) + " tried)" : failure;
    return none;
}

// --- the rigid part's fixed point as a half-turn pair ----------------------------------------------
// Where no unique fixed point is found (fig4's part: its first harmonic in theta stays below the rest
// within the limits -- bench_orientation_drive -- and the one orientation reachable by tuning the mean
// loses the position's pull, README), the sink's motion (odd harmonics on x, y, rx, ry; n = 1, 3) with
// theta' at THETA made a stable zero as well, coning held to kConingLimit. Turning such a motion by pi is shifting it by half a period, so (s*, THETA) and
// (-s*, THETA + pi) are both stable fixed points, at the centre (s* ~ 0) the same position: the part
// is brought to the target's position from everywhere and to its orientation up to a half turn.
// Then broken (break_pair, where DesignOptions::break_pair): the pair's field checked first (no runs),
// and where the broken motion verifies as unique it is returned without the pair's own runs; else the
// pair is verified in full and reported as not unique, with the twin and each one's share of the
// random starts, unless a verified broken motion has the larger share.
DesignSummary design_rigid_pair(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt, double T) {
    const auto t0 = Clock::now();
    DesignSummary sum;
    sum.notes.push_back("a half-turn pair: odd harmonics on x, y, rx, ry (n = 1, 3) pull the position to the target at "
                        "every orientation, and THETA is made a stable zero of theta' there; such a motion turned by pi "
                        "is the same motion half a period later, so THETA + pi is one as well (not unique)");
    sum.notes.push_back("coning held to 1e-4 rad/s (the plate's turn about z turns the part's orientation with it)");
    std::atomic<long> cycles{0};
    const double theta = wrap_angle(target.theta);
    const auto make = [&] { return SinkProblem(part_scene, target.at, opt, T, &cycles, &theta); };
    DesignOptions o = opt;
    o.starts = std::min(opt.starts, default_starts(part_scene, DesignTarget{}));   // (a sink's starts)
    const std::vector<double> best = multistart<SinkProblem>(o, -HUGE_VAL, make, sum.evaluations);
    start_summary(sum, part_scene, "_fixed_point", T);
    sum.starts = o.starts;
    if (best.empty()) {
        sum.failure = kNoFeasibleMotion;
        return finished(sum, cycles, t0);
    }
    // (the search's motion is centred: the placement shifts it by the target less the small offset of
    // the fixed point found.) Broken first: where that verifies as unique the pair's own runs are not needed (its field is checked,
    // a pair that does not hold the target is not broken); else the pair verified in full and the better kept.
    DesignSummary broken;
    broken.failure = "not tried";
    // (the broken pair returned, saying what the pair was)
    auto adopt = [&](const std::string& pair_was) -> DesignSummary {
        broken.notes.insert(broken.notes.begin(), "from a half-turn pair (odd harmonics n = 1, 3 on x, y, rx, ry with THETA "
                                                  "a stable zero of theta'; " + pair_was + ")");
        broken.evaluations += sum.evaluations;
        broken.starts = sum.starts;
        return finished(broken, cycles, t0);
    };
    if (opt.break_pair) {
        DesignOptions quick = opt;
        quick.verify_starts = 0;
        quick.hold = 0;
        DesignSummary probe = sum;
        place_and_verify_rigid(probe, part_scene, sink_motion(best, T), Vec3(0, 0, theta), target, quick, cycles, t0, true);
        if (probe.verified) broken = break_pair(part_scene, sink_motion(best, T), target, opt, T, cycles, t0);
        else broken.failure = "not tried: the pair's field does not hold the target (" + probe.failure + ")";
        if (broken.verified && broken.unique)
            return adopt("its field checked, its own full-dynamics runs not needed once the broken pair verified as unique");
    }
    place_and_verify_rigid(sum, part_scene, sink_motion(best, T), Vec3(0, 0, theta), target, opt, cycles, t0, true);
    if (!opt.break_pair) return sum;
    if (sum.verified && broken.verified && broken.basin_share > sum.basin_share) {
        std::ostringstream note;
        note.precision(2);
        note << "verified, the target's share of the runs " << sum.basin_share << ", which its pairing caps at "
             << sum.basin_share_bound;
        return adopt(note.str());
    }
    sum.notes.push_back("breaking the pairing with rz about its centre: " + broken.failure);
    sum.evaluations += broken.evaluations;
    return finished(sum, cycles, t0);
}

DesignSummary design_rigid(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt, double T) {
    const auto t0 = Clock::now();
    DesignSummary sum;
    const bool orient = target.kind == DesignTargetKind::Orient;
    sum.notes.push_back("harmonics n = 1, 2 on x, y, z, rx, ry, rz: z, rz and n = 2 break the pairing of fixed points "
                        "(s, theta), (-s, theta + pi) that odd x, y, rx, ry motions force");
    sum.notes.push_back("designed for a fixed point at the centre, theta = 0; the one found, q*, placed on the target by "
                        "turning the motion by THETA - theta* (the field turns) and adding -alpha x D (the field shifts by D)");
    sum.notes.push_back("no coning (|rx, ry out of phase| turns the plate about z, which the field does not see and the "
                        "full dynamics does): the plate's yaw drift held within 1e-4 rad/s");
    if (orient) sum.notes.push_back("orient: designed as a fixed point at the region's centre with orientation THETA "
                                    "(a stronger target); verified on the orientation only");
    std::atomic<long> cycles{0};
    const auto make = [&] { return RigidProblem(part_scene, target, opt, T, &cycles); };
    const std::vector<double> best = multistart<RigidProblem>(opt, -HUGE_VAL, make, sum.evaluations);
    start_summary(sum, part_scene, orient ? "_orient" : "_fixed_point", T);
    if (best.empty()) {
        sum.failure = kNoFeasibleMotion;
        return finished(sum, cycles, t0);
    }
    make().evaluate(best, &sum.rate, &sum.eigenvalues3);
    return place_and_verify_rigid(sum, part_scene, rigid_motion(best, T), Vec3::Zero(), target, opt, cycles, t0);
}

// A rigid design's last stages, shared: the fixed point of `centred` near q0 (Newton with the
// central-difference Jacobian, at the refinement's tolerances: field noise well below the step),
// placed exactly on the target by the two symmetries (turned by THETA - theta*, shifted by the target
// minus the turned s*), checked against the limits, and verified: the 7^3 field's fixed points, full
// dynamics from random starts (the target's basin share and each competing stable point's), the hold.
DesignSummary& place_and_verify_rigid(DesignSummary& sum, const Scene& part_scene, const PlateMotion& centred_motion,
                                      const Vec3& q0, const DesignTarget& target, const DesignOptions& opt,
                                      std::atomic<long>& cycles, Clock::time_point t0, bool pair,
                                      double run_seconds, double theta_offset) {
    // (run_seconds: the verification runs last at least this long; theta_offset: the field's fixed point
    // is placed this far short of THETA -- break_pair's, where the full dynamics settles past it)
    const bool orient = target.kind == DesignTargetKind::Orient;
    Scene centred = part_scene;
    centred.plate = centred_motion;
    LimitCycleOptions fine = opt.cycle;
    fine.integration.rtol = 1e-9;
    fine.tol = 1e-8;
    Vec3 q = q0;
    bool found = false;
    for (int it = 0; it < 12; ++it) {
        Vec3 xi;
        Mat3 J;
        if (!twist_and_jacobian(centred, q, fine, xi, J, cycles)) break;
        const Vec3 step = J.fullPivLu().solve(xi);
        if (!step.allFinite()) break;
        q -= step;
        if (step.head<2>().norm() < 1e-7 && std::abs(step[2]) < 1e-6) {
            found = true;
            sum.eigenvalues3 = J.eigenvalues();   // (at the fixed point, a step away)
            sum.rate = -std::max({sum.eigenvalues3[0].real(), sum.eigenvalues3[1].real(), sum.eigenvalues3[2].real()});
            break;
        }
    }
    {   // What the orientation has to work with there (orientation_harmonics, design.hpp).
        const bool near = found && q.head<2>().norm() <= opt.region;
        const int ring = 12;
        const OrientationHarmonics oh = orientation_harmonics(centred, near ? Vec2(q.head<2>()) : Vec2::Zero(), opt.cycle, ring);
        cycles += ring;
        if (oh.defined) {
            std::ostringstream note;
            note.precision(2);
            note << "theta' at the " << (near ? "fixed point's position" : "centre") << " (12 orientations): first harmonic "
                 << oh.first() << " rad/s against " << oh.rest() << " for the mean and the others ("
                 << (oh.one_stable()            ? "enough for exactly one stable orientation"
                     : oh.first() > oh.rest() ? "the zeros lie in two arcs, but more than one may be stable"
                                              : "below the rest: not enough by itself for one orientation, whose stable ones pair "
                                                "about a half turn apart unless the mean is tuned near a saddle-node")
                 << "; orientation_harmonics, design.hpp)";
            sum.notes.push_back(note.str());
        }
    }
    if (!found || q.head<2>().norm() > opt.region || std::abs(wrap_angle(q[2] - q0[2])) > kPi / 2) {
        sum.failure = "the search's best motion has no fixed point near the design's centre";
        return finished(sum, cycles, t0);
    }
    const Vec2 at = orient ? Vec2::Zero() : target.at;
    const Vec2 s_turned = Eigen::Rotation2Dd(target.theta - theta_offset - q[2]) * Vec2(q.head<2>());
    sum.scene.plate = placed_motion(centred.plate, q, at, target.theta, theta_offset);
    sum.min_vertical_margin = vertical_margin(sum.scene.plate, sum.scene.g, flight_region(sum.scene, opt));
    int n_max = 1;
    for (const Harmonic& h : sum.scene.plate.harmonics) n_max = std::max(n_max, h.n);
    std::vector<double> c(6 * n_max + 4);
    placed_constraints(sum.scene.plate, opt, sum.scene, n_max, 1.0, c.data());
    if (*std::max_element(c.begin(), c.end()) > 1e-9) {
        sum.failure = "the placed motion exceeds the amplitude limits, the flight margin or the coning (or tilt drift) limit";
        return finished(sum, cycles, t0);
    }
    const Vec3 goal(at.x(), at.y(), wrap_angle(target.theta));
    auto reached = [&](const Vec3& a, const Vec3& b, double dist, double ang) {
        return (orient || (a.head<2>() - b.head<2>()).norm() <= dist) && std::abs(wrap_angle(a[2] - b[2])) <= ang;
    };

    // --- verification: the field's fixed points on the 7^3 grid, then full dynamics from random starts.
    sum.fixed_points = find_fixed_points(sum.scene, verification_field(sum.scene, opt));
    int stable = 0, stable_at_target = 0;
    double nearest = std::numeric_limits<double>::infinity();
    std::vector<FixedPoint> others;
    for (const FixedPoint& p : sum.fixed_points.points) {
        if (p.stability != Stability::Stable) continue;
        ++stable;
        const double d = std::hypot(orient ? 0.0 : (p.q.head<2>() - at).norm() / 0.002, wrap_angle(p.q[2] - goal[2]) / 0.02);
        if (d < nearest) {
            nearest = d;
            sum.fixed_point = p.q;
            sum.fixed_point_eigenvalues = p.eigenvalues;
        }
        if (reached(p.q, goal, opt.fixed_point_tolerance, 0.02)) ++stable_at_target;
        else others.push_back(p);
    }
    int stable_lines = 0;
    for (const FixedLine& l : sum.fixed_points.lines) stable_lines += l.stability == Stability::Stable;
    // A half-turn pair is never unique: its twin exists by the pairing whether or not the grid
    // resolves it (an outside audit: nothing else kept a missed twin from reading unique).
    const std::string gaps = unsearched(sum.fixed_points);
    sum.unique = !pair && stable == 1 && stable_at_target == 1 && stable_lines == 0 && gaps.empty();
    if (!gaps.empty()) sum.notes.push_back("the grid's fixed-point search did not cover " + gaps + ": not called unique");
    sum.coning = coning_rate(sum.scene.plate);
    const int stopped = verification_runs(
        sum, opt,
        [&](const DesignStartRun&) { return std::max(settle_time(2 * opt.region, sum.rate, opt), run_seconds); },   // (from across the region)
        [&](const DesignStartRun&, const Vec3& end) {
            return std::max(orient ? 0.0 : (end.head<2>() - at).norm(),
                            std::abs(wrap_angle(end[2] - goal[2])) * opt.verify_distance / 0.05);
        },
        stable_at_target == 1 ? &goal : nullptr);   // (the hold only where the target is a stable fixed point)
    const std::string unheld = hold_failure(sum, opt, " m (0.05 rad counted as " + std::to_string(opt.verify_distance) + " m)");
    // The basin shares: of the runs, those that end at the target and at each competing stable point
    // (each run counted once: at the target, else at the first competitor it reached).
    std::vector<int> ended(others.size() + 1, 0);   // ended[0]: at the target
    int accounted = 0;
    for (const DesignStartRun& r : sum.runs) {
        if (!r.stop.empty()) continue;
        std::size_t where = r.end_distance <= opt.verify_distance ? 0 : ended.size();
        for (std::size_t k = 0; where == ended.size() && k < others.size(); ++k)
            if (reached(r.end, others[k].q, opt.verify_distance, 0.05)) where = k + 1;
        if (where < ended.size()) ++ended[where], ++accounted;
    }
    const double runs = static_cast<double>(std::max<std::size_t>(sum.runs.size(), 1));
    sum.basin_share = ended[0] / runs;
    for (std::size_t k = 0; k < others.size(); ++k) sum.competitors.push_back({others[k], ended[k + 1] / runs});
    // A half-turn pair: exactly one competitor, the target's image under the pairing about the design's
    // centre D = target - s_turned, i.e. at (2 D - target, THETA + pi).
    const Vec2 twin_at = at - 2 * s_turned;
    if (pair) {
        sum.basin_share_bound = pair_basin_bound(at - s_turned, opt.region);
        std::ostringstream note;
        note.precision(2);
        note << "the pairing caps the target's basin share in the field's flow at " << sum.basin_share_bound
             << " of starts uniform over the region: the twin's basin is the image of the target's under the half turn about "
                "the design's centre, so where the region is its own image at most half of it can go to the target (the "
                "full-dynamics runs' share is a sample of " << sum.runs.size() << " from phase 0 and can exceed it by chance)";
        sum.notes.push_back(note.str());
    }
    const bool twin_ok = others.size() == 1 && (others[0].q.head<2>() - twin_at).norm() <= opt.fixed_point_tolerance &&
                         std::abs(wrap_angle(others[0].q[2] - goal[2] - kPi)) <= 0.02;
    if (stable_at_target != 1)
        sum.failure = "the designed field has " + std::to_string(stable_at_target) + " stable fixed point(s) at the target on the " +
                      std::to_string(opt.verify_grid) + "^3 grid (" + std::to_string(stable) + " stable in all)";
    else if (stopped)
        sum.failure = std::to_string(stopped) + " full-dynamics run(s) left the model";
    else if (sum.unique && !(sum.worst_end_distance <= opt.verify_distance))
        sum.failure = "a full-dynamics run ended " + std::to_string(sum.worst_end_distance) + " m (0.05 rad counted as " +
                      std::to_string(opt.verify_distance) + " m) from the target";
    else if (!sum.unique && accounted < static_cast<int>(sum.runs.size()))
        sum.failure = "of " + std::to_string(sum.runs.size()) + " full-dynamics runs, " +
                      std::to_string(static_cast<int>(sum.runs.size()) - accounted) +
                      " ended at neither the target nor a competing stable fixed point";
    else if (!sum.unique && ended[0] == 0 && opt.verify_starts > 0)   // (0, design_rigid_pair's probe: the field only)
        sum.failure = "no full-dynamics run ended at the target";
    else if (pair && !twin_ok)
        sum.failure = "the half-turn pair's stable fixed points are not the target and its twin alone (" +
                      std::to_string(others.size()) + " other stable fixed point(s))";
    return last_checks(sum, opt, unheld, cycles, t0);
}

}  // namespace

double pair_basin_bound(const Vec2& D, double region) {
    // R = [-a, a]^2 and its image 2 D - R = [2 D - a, 2 D + a]^2 overlap over (2 a - 2 |D_i|) per axis.
    double overlap = 1;
    for (int i = 0; i < 2; ++i) overlap *= std::max(0.0, 2 * region - 2 * std::abs(D[i]));
    return 1 - overlap / (2 * 4 * region * region);
}

namespace {
// sum_n Im(A_a,n conj(A_b,n)) / (2 (n w)^3) over the phasors amp e^{i phase} of each (axis, n): the
// second-order drift about the third axis of (a, b) in the cross product's cyclic order.
double drift_sum(const PlateMotion& u, Axis a, Axis b) {
    const auto ph = phasors(u);
    double r = 0;
    for (const auto& [k, za] : ph) {
        if (k.first != static_cast<int>(a)) continue;
        const auto zb = ph.find({static_cast<int>(b), k.second});
        if (zb == ph.end()) continue;
        const double nw = k.second * 2 * kPi / u.T;
        r += std::imag(za * std::conj(zb->second)) / (2 * nw * nw * nw);
    }
    return r;
}
}  // namespace

double coning_rate(const PlateMotion& u) { return drift_sum(u, Axis::rx, Axis::ry); }

Vec2 tilt_drift_rate(const PlateMotion& u) { return Vec2(drift_sum(u, Axis::ry, Axis::rz), drift_sum(u, Axis::rz, Axis::rx)); }

double sink_coning_limit(const Vec2& at, const DesignOptions& opt) {
    if (opt.max_coning >= 0) return opt.max_coning;
    const double walk = at.norm() * opt.hold;   // [m s]: the sink's walk per unit coning rate
    return walk > 0 ? 0.5 * opt.verify_distance / walk : std::numeric_limits<double>::infinity();
}

int default_starts(const Scene& part_scene, const DesignTarget& target) {
    const bool sink = target.kind == DesignTargetKind::Sink || target.kind == DesignTargetKind::LineSink ||
                      (target.kind == DesignTargetKind::FixedPoint && part_scene.part.point);
    return sink ? 4 : 16;
}

namespace {
DesignSummary dispatch(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt) {
    const double T = opt.period > 0 ? opt.period : part_scene.plate.T;
    if (!(T > 0)) throw std::invalid_argument("no plate period (give one)");
    if (target.kind == DesignTargetKind::Transport) {
        if (!(target.velocity.norm() > 0)) throw std::invalid_argument("a transport target needs a velocity");
        if (target.omega != 0)
            throw std::invalid_argument("transport with a turn: a plate that only translates cannot turn a part with one "
                                        "friction coefficient, and a turning plate's alpha x s makes the twist depend on "
                                        "position (a whirl), so no uniform twist with OMEGA != 0 is designed (DesignTarget)");
        if (!part_scene.part.point) {
            const auto mu = part_scene.part.mu.head(part_scene.part.contacts());
            if (mu.maxCoeff() > mu.minCoeff() * (1 + 1e-9))
                throw std::invalid_argument("transport of a part whose contacts' friction differs: a translating plate turns it "
                                            "(the weathervane) and its velocity with it, so it has no uniform twist (try orient)");
        }
        return design_transport(part_scene, target, opt, T);
    }
    if (!(std::abs(target.at.x()) <= opt.region && std::abs(target.at.y()) <= opt.region))
        throw std::invalid_argument("the target lies outside the plate region");
    if (!part_scene.part.point) {
        // (with one friction coefficient on every contact a translating plate cannot turn the part:
        // the rotating plate's search, design_rigid, is left)
        const auto mu = part_scene.part.mu.head(part_scene.part.contacts());
        if (target.kind == DesignTargetKind::Orient && mu.maxCoeff() > mu.minCoeff() * (1 + 1e-9))
            return design_orient(part_scene, target, opt, T);
        if (target.kind == DesignTargetKind::LineSink)
            throw std::invalid_argument("a line sink is built for point parts only");
        if (target.kind == DesignTargetKind::Sink) return design_sink(part_scene, target, opt, T);
        if (target.kind != DesignTargetKind::FixedPoint) return design_rigid(part_scene, target, opt, T);
        // The half-turn pair first, broken where rz about its centre leaves one stable fixed point
        // (design_rigid_pair, break_pair); where the pair itself fails (no sink for this part), the
        // general search over all six axes at n = 1, 2 (design_rigid).
        DesignSummary pair = design_rigid_pair(part_scene, target, opt, T);
        if (pair.verified) return pair;
        DesignSummary general = design_rigid(part_scene, target, opt, T);
        std::ostringstream note;
        note.precision(3);
        note << "the half-turn pair failed (" << pair.failure << "; " << pair.evaluations << " evaluations, " << pair.seconds
             << " s, counted below)";
        general.notes.insert(general.notes.begin(), note.str());
        general.evaluations += pair.evaluations;
        general.cycles += pair.cycles;
        general.starts += pair.starts;   // (both searches')
        general.seconds += pair.seconds;
        return general;
    }
    if (target.kind == DesignTargetKind::Orient) throw std::invalid_argument("a point part has no orientation to set");
    if (target.kind == DesignTargetKind::LineSink) return design_line_sink(part_scene, target, opt, T);
    return design_sink(part_scene, target, opt, T);
}
}  // namespace

DesignSummary design(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt) {
    // Every design is verified in full dynamics before it is reported: no runs, no verification (the
    // sinks, lines, transports and orienters would otherwise pass on the field alone).
    if (opt.verify_starts < 1) throw std::invalid_argument("verify_starts must be at least 1 (designs are verified in full dynamics)");
    DesignOptions o = opt;
    if (o.starts <= 0) o.starts = default_starts(part_scene, target);
    DesignSummary sum = dispatch(part_scene, target, o);
    if (sum.starts == 0) sum.starts = o.starts;   // (set where a search ran its own number of starts)
    return sum;
}

}  // namespace plate
