#include "plate/design.hpp"

#include "plate/random_scene.hpp"

#include <nlopt.hpp>

#include <Eigen/Eigenvalues>

#include <algorithm>
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

// min over the period (256 samples) and the region's corners of (g + vertical acceleration) / g, with
// the plate's acceleration at r = p'' + alpha x r (what the part feels; the U-dynamics' plate).
double vertical_margin(const PlateMotion& u, double g, double region) {
    double worst = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 256; ++k) {
        Vec3 pdd, wd;
        u.acceleration(u.T * k / 256, pdd, wd);
        for (double x : {-region, region})
            for (double y : {-region, region}) worst = std::min(worst, (g + pdd.z() + wd.x() * y - wd.y() * x) / g);
    }
    return worst;
}

// --- what the searches share -----------------------------------------------------------------------

// A plate motion from coefficients: per axis a and harmonic h, u = c cos(n w t) + s sin(n w t) with
// c = p[2 (a H + h)], s = p[2 (a H + h) + 1] (H harmonics), i.e. amp sin(n w t + phase).
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
    long evaluations = 0;
    // The best point evaluated that satisfies every constraint (COBYLA's own answer may violate one
    // by its tolerance: the limits and the flight margin are hard, so that is never taken).
    std::vector<double> best_p;
    double best_f = std::numeric_limits<double>::infinity();

    const Derived& self() const { return static_cast<const Derived&>(*this); }
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

// The multi-start search: from opt.starts seeded feasible random points (each parameter uniform in
// +-limit/sqrt 2, up to 1000 tries), NLopt COBYLA with the constraints, opt.local_evaluations each,
// starts in parallel; make(k) builds start k's problem. Returns the best feasible point over the
// starts (empty if none) and adds the evaluations to `evaluations`.
template <class P, class Make>
std::vector<double> multistart(const DesignOptions& opt, double stopval, Make&& make, long& evaluations) {
    constexpr int n = P::kParams;
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
        for (int tries = 0; tries < 1000 && !ok; ++tries) {
            for (int i = 0; i < n; ++i) p[i] = rng.uniform(-prob.limit(i), prob.limit(i)) / std::sqrt(2.0);
            ok = prob.feasible(p);
        }
        if (!ok) return "inf 0 0";
        for (int i = 0; i < n; ++i) {
            lo[i] = -prob.limit(i);
            hi[i] = prob.limit(i);
            step[i] = std::max(prob.limit(i), 1e-6) / 4;
        }
        nlopt::opt local(nlopt::LN_COBYLA, n);
        local.set_lower_bounds(lo);
        local.set_upper_bounds(hi);
        local.set_initial_step(step);
        local.set_maxeval(opt.local_evaluations);
        local.set_stopval(stopval);
        local.set_min_objective(
            [](const std::vector<double>& x, std::vector<double>&, void* d) { return static_cast<P*>(d)->objective(x); },
            &prob);
        local.add_inequality_mconstraint(
            [](unsigned, double* c, unsigned, const double* x, double*, void* d) {
                static_cast<P*>(d)->constraints(std::vector<double>(x, x + P::kParams), c);
            },
            &prob, std::vector<double>(P::kConstraints, 1e-9));
        prob.objective(p);   // the feasible start itself
        double f = 0;
        try {
            local.optimize(p, f);
        } catch (const std::exception&) {
            // (a roundoff-limited stop: the best feasible point found stands)
        }
        // The start's result as text (it may have run in another process): f, evaluations, cycles, p.
        std::string text = exact_text(prob.best_f) + ' ' + std::to_string(prob.evaluations) + ' ' +
                           std::to_string(own_cycles.load());
        for (double x : prob.best_p) text += ' ' + exact_text(x);
        return text;
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
// dynamics from verify_starts seeded random starts, each run for seconds(x, y) and measured by
// end_distance(start, end); the worst distance and the runs that left the model are tallied.
Field verification_field(const Scene& sc, const DesignOptions& opt) {
    GridSpec g;
    g.nx = g.ny = opt.verify_grid;
    g.nth = 1;
    g.x0 = g.y0 = -opt.region;
    g.x1 = g.y1 = opt.region;
    FieldOptions fo;
    fo.threads = opt.threads;
    fo.tasks = opt.tasks;
    return compute_field(sc, g, fo);
}

template <class Seconds, class EndDistance>
int verification_runs(DesignSummary& sum, const DesignOptions& opt, Seconds&& seconds, EndDistance&& end_distance) {
    Rng rng(opt.seed ^ 0x5DEECE66DULL);
    sum.runs.resize(opt.verify_starts);
    for (DesignStartRun& r : sum.runs) {
        r.x = rng.uniform(-opt.region, opt.region);
        r.y = rng.uniform(-opt.region, opt.region);
        r.seconds = seconds(Vec2(r.x, r.y));
    }
    runner(opt)(static_cast<int>(sum.runs.size()), [&](int k) {
        const DesignStartRun& r = sum.runs[k];
        IntegrationOptions io;
        io.rtol = 1e-7;
        const Trajectory tr = simulate(sum.scene, Dynamics::Full, Vec3(r.x, r.y, 0), Vec3::Zero(), r.seconds, r.seconds, io);
        const double d = tr.samples.empty() ? std::numeric_limits<double>::infinity()
                                            : end_distance(r, Vec2(tr.samples.back().q.head<2>()));
        // (text: the distance, then why the run stopped early, if it did)
        return exact_text(d) + (tr.stop.reason != StopReason::None ? ' ' + tr.stop.describe() : std::string());
    }, [&](int k, const std::string& text) {
        const std::size_t sp = text.find(' ');
        sum.runs[k].end_distance = exact_value(text.substr(0, sp));
        sum.runs[k].stop = sp == std::string::npos ? std::string() : text.substr(sp + 1);
    });
    int stopped = 0;
    sum.worst_end_distance = 0;
    for (const DesignStartRun& r : sum.runs) {
        sum.worst_end_distance = std::max(sum.worst_end_distance, r.end_distance);
        stopped += !r.stop.empty();
    }
    return stopped;
}

// The summary's scene before a design is found: the part on a plate at rest.
void start_summary(DesignSummary& sum, const Scene& part, const std::string& suffix, double T) {
    sum.scene = part;
    sum.scene.name = part.name + suffix;
    sum.scene.plate = PlateMotion{};
    sum.scene.plate.T = T;
}
constexpr const char* kNoFeasibleMotion = "no motion within the limits keeps the part on the plate over the region";

// --- the point-part sink ---------------------------------------------------------------------------
// Parameters: per axis of {x, y, rx, ry}, the first harmonic's cosine and sine coefficients,
// u_a = c cos(w t) + s sin(w t): odd harmonics without z or rz make the field odd about the centre,
// so the centre is a fixed point by construction and the search only makes it attract, fast, over
// the whole region (then shift_motion moves it onto the target).
PlateMotion sink_motion(const std::vector<double>& p, double T) {
    return motion_from(p, {Axis::x, Axis::y, Axis::rx, Axis::ry}, {1}, T);
}

struct SinkProblem : Problem<SinkProblem> {
    SinkProblem(const Scene& part_, const Vec2& D_, const DesignOptions& opt_, double T_, std::atomic<long>* cycles_)
        : Problem(part_, opt_, T_, cycles_), D(D_) {}
    Vec2 D;
    static constexpr int kParams = 8;
    static constexpr int kConstraints = 7;   // six amplitudes, the flight margin
    double limit(int i) const { return i < 4 ? opt.lin_limit : opt.ang_limit; }

    // Constraints c_k <= 0 on the final (shifted) motion: each harmonic's amplitude within its
    // limit, and no flight over the region.
    void constraints(const std::vector<double>& p, double* c) const {
        const PlateMotion fin = shift_motion(sink_motion(p, T), D);
        int k = 0;
        const auto ph = phasors(fin);
        for (int axis = 0; axis < 6; ++axis) {
            const auto it = ph.find({axis, 1});
            const double amp = it == ph.end() ? 0.0 : std::abs(it->second);
            c[k++] = (amp - (axis < 3 ? opt.lin_limit : opt.ang_limit)) / (axis < 3 ? opt.lin_limit : opt.ang_limit);
        }
        c[k++] = opt.flight_margin - vertical_margin(fin, part.g, opt.region);
    }
    // Convergence rate at the centre, and how much of the region's edge the field does not point
    // inwards (of the centred motion: the final field at s + D).
    double evaluate(const std::vector<double>& p, double* rate_out = nullptr, Eigen::Vector2cd* eig_out = nullptr) {
        ++evaluations;
        Scene sc = part;
        sc.plate = sink_motion(p, T);
        const double h = 0.003;
        Vec2 vx, vy;
        if (!twist_at(sc, Vec2(h, 0), vx) || !twist_at(sc, Vec2(0, h), vy)) return 1e3;
        Eigen::Matrix2d J;
        J.col(0) = vx / h;   // the field is odd about the centre: v(h e) / h is the central difference
        J.col(1) = vy / h;
        const Eigen::Vector2cd ev = J.eigenvalues();
        const double rate = -std::max(ev[0].real(), ev[1].real());
        if (rate_out) *rate_out = rate;
        if (eig_out) *eig_out = ev;
        // The region's edge, relative to the centre of the design: eight points on its boundary.
        double outward = 0;
        const double R = opt.region;
        const Vec2 edge[8] = {{-R, -R}, {0, -R}, {R, -R}, {R, 0}, {R, R}, {0, R}, {-R, R}, {-R, 0}};
        for (const Vec2& e : edge) {
            const Vec2 s = e - D;
            Vec2 v;
            if (!twist_at(sc, s, v)) return 1e3;
            outward += std::max(0.0, s.dot(v) / s.squaredNorm());   // [1/s]
        }
        return -rate + 10 * outward;
    }
};

DesignSummary design_sink(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt, double T) {
    const auto t0 = Clock::now();
    DesignSummary sum;
    sum.notes.push_back("odd harmonics on x, y, rx, ry only: the field is odd about the design's centre, so the "
                        "centre is a fixed point by construction and fixed points come in pairs s, -s");
    sum.notes.push_back("the design's centre moved onto the target by adding -alpha x D to the linear acceleration "
                        "(exact: the field shifts by D)");
    std::atomic<long> cycles{0};
    const auto make = [&] { return SinkProblem(part_scene, target.at, opt, T, &cycles); };
    const std::vector<double> best = multistart<SinkProblem>(opt, -HUGE_VAL, make, sum.evaluations);
    start_summary(sum, part_scene, "_sink", T);   // (no motion unless a design is found)
    if (best.empty()) {
        sum.failure = kNoFeasibleMotion;
        sum.cycles = cycles;
        sum.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
        return sum;
    }
    make().evaluate(best, &sum.rate, &sum.eigenvalues);
    sum.scene.plate = combined(shift_motion(sink_motion(best, T), target.at));
    sum.cycles = cycles;
    sum.min_vertical_margin = vertical_margin(sum.scene.plate, sum.scene.g, opt.region);

    // --- verification: the field's fixed points on the grid, then full dynamics from random starts.
    sum.fixed_points = find_fixed_points(sum.scene, verification_field(sum.scene, opt));
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
    sum.unique = stable == 1 && stable_at_target == 1;
    const double rate = std::max(sum.rate, 1e-3);
    const int stopped = verification_runs(
        sum, opt,
        [&](const Vec2& start) {
            // Long enough for the linearised convergence to bring it within a fifth of the distance asked.
            const double d0 = (start - target.at).norm();
            return std::clamp(std::log(std::max(d0, opt.verify_distance) / (0.2 * opt.verify_distance)) / rate, 2.0, 120.0);
        },
        [&](const DesignStartRun&, const Vec2& end) { return (end - target.at).norm(); });
    if (!sum.unique)
        sum.failure = "the designed field has " + std::to_string(stable) + " stable fixed point(s) or line(s) on the " +
                      std::to_string(opt.verify_grid) + "x" + std::to_string(opt.verify_grid) + " grid, " +
                      std::to_string(stable_at_target) + " within " + std::to_string(opt.fixed_point_tolerance) +
                      " m of the target";
    else if (stopped)
        sum.failure = std::to_string(stopped) + " full-dynamics run(s) left the model";
    else if (!(sum.worst_end_distance <= opt.verify_distance))
        sum.failure = "a full-dynamics run ended " + std::to_string(sum.worst_end_distance) + " m from the target";
    else if (!(sum.min_vertical_margin >= opt.flight_margin - 1e-9))
        sum.failure = "the vertical acceleration margin is below the one asked";
    sum.verified = sum.failure.empty();
    sum.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return sum;
}

// --- the point-part transport --------------------------------------------------------------------
// Parameters: cosine and sine coefficients of harmonics n = 1, 2 on x, y and z (a plate that only
// translates). The field is uniform; its value at the centre is driven onto the target.
PlateMotion transport_motion(const std::vector<double>& p, double T) {
    return motion_from(p, {Axis::x, Axis::y, Axis::z}, {1, 2}, T);
}

struct TransportProblem : Problem<TransportProblem> {
    TransportProblem(const Scene& part_, const Vec2& v_, const DesignOptions& opt_, double T_, std::atomic<long>* cycles_)
        : Problem(part_, opt_, T_, cycles_), target(v_) {}
    Vec2 target;
    static constexpr int kParams = 12;
    static constexpr int kConstraints = 7;   // six harmonic amplitudes, the flight margin
    double limit(int) const { return opt.lin_limit; }
    void constraints(const std::vector<double>& p, double* c) const {
        for (int k = 0; k < 6; ++k) c[k] = (std::hypot(p[2 * k], p[2 * k + 1]) - opt.lin_limit) / std::max(opt.lin_limit, 1e-12);
        c[6] = opt.flight_margin - vertical_margin(transport_motion(p, T), part.g, opt.region);
    }
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
    const auto make = [&] { return TransportProblem(part_scene, target.velocity, opt, T, &cycles); };
    // (stop within 0.01% of the target speed)
    const std::vector<double> best = multistart<TransportProblem>(opt, 1e-4, make, sum.evaluations);
    start_summary(sum, part_scene, "_transport", T);
    sum.cycles = cycles;
    if (best.empty()) {
        sum.failure = kNoFeasibleMotion;
        sum.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
        return sum;
    }
    sum.scene.plate = combined(transport_motion(best, T));
    sum.min_vertical_margin = vertical_margin(sum.scene.plate, sum.scene.g, opt.region);
    // Verification: the field on the grid (mean and spread), then full dynamics from random starts.
    const Field f = verification_field(sum.scene, opt);
    int undefined = 0;
    for (const FieldPoint& p : f.points) {
        if (!p.converged) ++undefined;
        else sum.transport_mean += p.twist.head<2>();
    }
    if (undefined < static_cast<int>(f.points.size())) sum.transport_mean /= static_cast<double>(f.points.size() - undefined);
    for (const FieldPoint& p : f.points)
        if (p.converged) sum.transport_spread = std::max(sum.transport_spread, (p.twist.head<2>() - sum.transport_mean).norm());
    sum.transport_tolerance = 0.02 * target.velocity.norm();
    const int stopped = verification_runs(
        sum, opt, [&](const Vec2&) { return std::clamp(0.05 / target.velocity.norm(), 1.0, 20.0); },   // a region's width
        // the distance from where the target velocity would have taken it
        [&](const DesignStartRun& r, const Vec2& end) { return (end - Vec2(r.x, r.y) - target.velocity * r.seconds).norm(); });
    sum.unique = true;   // (no fixed point is sought)
    if (undefined) sum.failure = std::to_string(undefined) + " configurations of the field are undefined";
    else if (!((sum.transport_mean - target.velocity).norm() <= sum.transport_tolerance))
        sum.failure = "the field's mean velocity (" + std::to_string(sum.transport_mean.x()) + ", " +
                      std::to_string(sum.transport_mean.y()) + ") m/s misses the target by more than 2%: out of reach within the limits";
    else if (!(sum.transport_spread <= sum.transport_tolerance))
        sum.failure = "the field is not uniform over the region";
    else if (stopped)
        sum.failure = std::to_string(stopped) + " full-dynamics run(s) left the model";
    else if (!(sum.worst_end_distance <= opt.verify_distance))
        sum.failure = "a full-dynamics run ended " + std::to_string(sum.worst_end_distance) +
                      " m from where the target velocity takes it";
    sum.verified = sum.failure.empty();
    sum.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return sum;
}

}  // namespace

DesignSummary design(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt) {
    const double T = opt.period > 0 ? opt.period : part_scene.plate.T;
    if (!(T > 0)) throw std::invalid_argument("no plate period (give one)");
    if (target.kind == DesignTargetKind::Transport) {
        if (!part_scene.part.point)
            throw std::invalid_argument("this version designs transport for point parts only");
        if (!(target.velocity.norm() > 0)) throw std::invalid_argument("a transport target needs a velocity");
        return design_transport(part_scene, target, opt, T);
    }
    if (!part_scene.part.point)
        throw std::invalid_argument("this version designs sinks for point parts; a rigid part's fixed point, "
                                    "transport and orientation targets are not built yet");
    if (!(std::abs(target.at.x()) <= opt.region && std::abs(target.at.y()) <= opt.region))
        throw std::invalid_argument("the target lies outside the plate region");
    return design_sink(part_scene, target, opt, T);
}

}  // namespace plate
