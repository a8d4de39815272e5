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

// --- the point-part sink ---------------------------------------------------------------------------
// Parameters: per axis of {x, y, rx, ry}, the first harmonic's cosine and sine coefficients,
// u_a = c cos(w t) + s sin(w t): odd harmonics without z or rz make the field odd about the centre,
// so the centre is a fixed point by construction and the search only makes it attract, fast, over
// the whole region (then shift_motion moves it onto the target).
constexpr Axis kSinkAxes[4] = {Axis::x, Axis::y, Axis::rx, Axis::ry};
constexpr int kSinkParams = 8;

PlateMotion sink_motion(const std::vector<double>& p, double T) {
    PlateMotion u;
    u.T = T;
    for (int a = 0; a < 4; ++a) {
        const double c = p[2 * a], s = p[2 * a + 1], amp = std::hypot(c, s);
        if (amp > 0) u.harmonics.push_back({kSinkAxes[a], 1, amp, std::atan2(c, s)});   // amp sin(wt + phase)
    }
    return u;
}

struct SinkProblem {
    SinkProblem(const Scene& part_, const Vec2& D_, const DesignOptions& opt_, double T_, std::atomic<long>* cycles_)
        : part(part_), D(D_), opt(opt_), T(T_), cycles(cycles_) {}
    const Scene& part;
    Vec2 D;
    const DesignOptions& opt;
    double T;
    std::atomic<long>* cycles;
    long evaluations = 0;
    // The best point evaluated that satisfies every constraint (COBYLA's own answer may violate one
    // by its tolerance: the limits and the flight margin are hard, so that is never taken).
    std::vector<double> best_p;
    double best_f = std::numeric_limits<double>::infinity();

    Scene centred(const std::vector<double>& p) const {
        Scene s = part;
        s.plate = sink_motion(p, T);
        return s;
    }
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
    static constexpr int kConstraints = 7;
    bool feasible(const std::vector<double>& p) const {
        double c[kConstraints];
        constraints(p, c);
        return std::all_of(c, c + kConstraints, [](double x) { return x <= 0; });
    }

    // The field at s of the centred motion (the final field at s + D).
    bool field(const Scene& sc, const Vec2& s, Vec2& v) const {
        const LimitCycleSummary lc = limit_cycle(sc, Vec3(s.x(), s.y(), 0), opt.cycle);
        ++*cycles;
        if (!lc.converged) return false;
        v = lc.twist.head<2>();
        return true;
    }
    // Convergence rate at the centre, and how much of the region's edge the field does not point
    // inwards; the best feasible point is kept.
    double objective(const std::vector<double>& p) {
        const double f = evaluate(p);
        if (f < best_f && feasible(p)) {
            best_f = f;
            best_p = p;
        }
        return f;
    }
    double evaluate(const std::vector<double>& p, double* rate_out = nullptr, Eigen::Vector2cd* eig_out = nullptr) {
        ++evaluations;
        const Scene sc = centred(p);
        const double h = 0.003;
        Vec2 vx, vy;
        if (!field(sc, Vec2(h, 0), vx) || !field(sc, Vec2(0, h), vy)) return 1e3;
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
            if (!field(sc, s, v)) return 1e3;
            outward += std::max(0.0, s.dot(v) / s.squaredNorm());   // [1/s]
        }
        return -rate + 10 * outward;
    }
};

}  // namespace

namespace {

// --- the point-part transport --------------------------------------------------------------------
// Parameters: cosine and sine coefficients of harmonics n = 1, 2 on x, y and z (a plate that only
// translates). The field is uniform; its value at the centre is driven onto the target.
constexpr Axis kTransportAxes[3] = {Axis::x, Axis::y, Axis::z};
constexpr int kTransportParams = 12;

PlateMotion transport_motion(const std::vector<double>& p, double T) {
    PlateMotion u;
    u.T = T;
    for (int a = 0; a < 3; ++a)
        for (int n = 1; n <= 2; ++n) {
            const double c = p[4 * a + 2 * (n - 1)], s = p[4 * a + 2 * (n - 1) + 1], amp = std::hypot(c, s);
            if (amp > 0) u.harmonics.push_back({kTransportAxes[a], n, amp, std::atan2(c, s)});
        }
    return u;
}

struct TransportProblem {
    TransportProblem(const Scene& part_, const Vec2& v_, const DesignOptions& opt_, double T_, std::atomic<long>* cycles_)
        : part(part_), target(v_), opt(opt_), T(T_), cycles(cycles_) {}
    const Scene& part;
    Vec2 target;
    const DesignOptions& opt;
    double T;
    std::atomic<long>* cycles;
    long evaluations = 0;
    std::vector<double> best_p;
    double best_f = std::numeric_limits<double>::infinity();

    static constexpr int kConstraints = 7;   // six harmonic amplitudes, the flight margin
    void constraints(const std::vector<double>& p, double* c) const {
        for (int k = 0; k < 6; ++k) c[k] = (std::hypot(p[2 * k], p[2 * k + 1]) - opt.lin_limit) / std::max(opt.lin_limit, 1e-12);
        c[6] = opt.flight_margin - vertical_margin(transport_motion(p, T), part.g, opt.region);
    }
    bool feasible(const std::vector<double>& p) const {
        double c[kConstraints];
        constraints(p, c);
        return std::all_of(c, c + kConstraints, [](double x) { return x <= 0; });
    }
    double evaluate(const std::vector<double>& p, Vec2* v_out = nullptr) {
        ++evaluations;
        Scene sc = part;
        sc.plate = transport_motion(p, T);
        const LimitCycleSummary lc = limit_cycle(sc, Vec3::Zero(), opt.cycle);
        ++*cycles;
        if (!lc.converged) return 1e3;
        if (v_out) *v_out = lc.twist.head<2>();
        return (lc.twist.head<2>() - target).norm() / target.norm();
    }
    double objective(const std::vector<double>& p) {
        const double f = evaluate(p);
        if (f < best_f && feasible(p)) {
            best_f = f;
            best_p = p;
        }
        return f;
    }
};

// Runs `jobs` independent jobs on the option's threads.
template <class Job>
void run_parallel(int jobs, int threads, Job&& job) {
    std::atomic<int> next{0};
    auto worker = [&] {
        for (int k; (k = next++) < jobs;) job(k);
    };
    const int nt = std::max(1, std::min(jobs, threads > 0 ? threads : static_cast<int>(std::thread::hardware_concurrency())));
    std::vector<std::thread> pool;
    for (int i = 1; i < nt; ++i) pool.emplace_back(worker);
    worker();
    for (auto& th : pool) th.join();
}

DesignSummary design_transport(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt, double T) {
    const auto t0 = Clock::now();
    DesignSummary sum;
    sum.notes.push_back("a plate that only translates (x, y, z): a point part's velocity field is the same everywhere");
    std::atomic<long> cycles{0};
    const int n_starts = std::max(1, opt.starts);
    std::vector<std::vector<double>> best_p(n_starts);
    std::vector<double> best_f(n_starts, std::numeric_limits<double>::infinity());
    std::vector<long> evals(n_starts, 0);
    run_parallel(n_starts, opt.threads, [&](int k) {
        TransportProblem prob(part_scene, target.velocity, opt, T, &cycles);
        Rng rng(opt.seed * 1000003 + static_cast<std::uint64_t>(k));
        std::vector<double> p(kTransportParams);
        bool ok = false;
        for (int tries = 0; tries < 1000 && !ok; ++tries) {
            for (double& x : p) x = rng.uniform(-opt.lin_limit, opt.lin_limit) / std::sqrt(2.0);
            ok = prob.feasible(p);
        }
        if (!ok) return;
        nlopt::opt local(nlopt::LN_COBYLA, kTransportParams);
        local.set_lower_bounds(std::vector<double>(kTransportParams, -opt.lin_limit));
        local.set_upper_bounds(std::vector<double>(kTransportParams, opt.lin_limit));
        local.set_initial_step(std::vector<double>(kTransportParams, std::max(opt.lin_limit, 1e-6) / 4));
        local.set_maxeval(opt.local_evaluations);
        local.set_stopval(1e-4);   // within 0.01% of the target speed: done
        local.set_min_objective(
            [](const std::vector<double>& x, std::vector<double>&, void* d) { return static_cast<TransportProblem*>(d)->objective(x); },
            &prob);
        local.add_inequality_mconstraint(
            [](unsigned, double* c, unsigned, const double* x, double*, void* d) {
                static_cast<TransportProblem*>(d)->constraints(std::vector<double>(x, x + kTransportParams), c);
            },
            &prob, std::vector<double>(TransportProblem::kConstraints, 1e-9));
        prob.objective(p);
        double f = 0;
        try {
            local.optimize(p, f);
        } catch (const std::exception&) {
        }
        best_p[k] = prob.best_p;
        best_f[k] = prob.best_f;
        evals[k] = prob.evaluations;
    });
    for (long e : evals) sum.evaluations += e;
    const int best = static_cast<int>(std::min_element(best_f.begin(), best_f.end()) - best_f.begin());
    sum.scene = part_scene;
    sum.scene.name = part_scene.name + "_transport";
    sum.scene.plate = PlateMotion{};
    sum.scene.plate.T = T;
    sum.cycles = cycles;
    if (!std::isfinite(best_f[best])) {
        sum.failure = "no motion within the limits keeps the part on the plate over the region";
        sum.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
        return sum;
    }
    sum.scene.plate = combined(transport_motion(best_p[best], T));
    sum.min_vertical_margin = vertical_margin(sum.scene.plate, sum.scene.g, opt.region);
    // Verification: the field on the grid (mean and spread), then full dynamics from random starts.
    GridSpec g;
    g.nx = g.ny = opt.verify_grid;
    g.nth = 1;
    g.x0 = g.y0 = -opt.region;
    g.x1 = g.y1 = opt.region;
    FieldOptions fo;
    fo.threads = opt.threads;
    const Field f = compute_field(sum.scene, g, fo);
    int undefined = 0;
    for (const FieldPoint& p : f.points) {
        if (!p.converged) ++undefined;
        else sum.transport_mean += p.twist.head<2>();
    }
    if (undefined < static_cast<int>(f.points.size())) sum.transport_mean /= static_cast<double>(f.points.size() - undefined);
    for (const FieldPoint& p : f.points)
        if (p.converged) sum.transport_spread = std::max(sum.transport_spread, (p.twist.head<2>() - sum.transport_mean).norm());
    sum.transport_tolerance = 0.02 * target.velocity.norm();
    Rng rng(opt.seed ^ 0x5DEECE66DULL);
    sum.runs.resize(opt.verify_starts);
    for (DesignStartRun& r : sum.runs) {
        r.x = rng.uniform(-opt.region, opt.region);
        r.y = rng.uniform(-opt.region, opt.region);
        r.seconds = std::clamp(0.05 / target.velocity.norm(), 1.0, 20.0);   // about a region's width of travel
    }
    run_parallel(static_cast<int>(sum.runs.size()), opt.threads, [&](int k) {
        DesignStartRun& r = sum.runs[k];
        IntegrationOptions io;
        io.rtol = 1e-7;
        const Trajectory tr = simulate(sum.scene, Dynamics::Full, Vec3(r.x, r.y, 0), Vec3::Zero(), r.seconds, r.seconds, io);
        // The distance from where the target velocity would have taken it.
        r.end_distance = tr.samples.empty() ? std::numeric_limits<double>::infinity()
                                            : (tr.samples.back().q.head<2>() - Vec2(r.x, r.y) - target.velocity * r.seconds).norm();
        if (tr.stop.reason != StopReason::None) r.stop = tr.stop.describe();
    });
    int stopped = 0;
    for (const DesignStartRun& r : sum.runs) {
        sum.worst_end_distance = std::max(sum.worst_end_distance, r.end_distance);
        stopped += !r.stop.empty();
    }
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

static DesignSummary design_sink(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt);

DesignSummary design(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt) {
    const double T = opt.period > 0 ? opt.period : part_scene.plate.T;
    if (!(T > 0)) throw std::invalid_argument("no plate period (give one)");
    if (target.kind == DesignTargetKind::Transport) {
        if (!part_scene.part.point)
            throw std::invalid_argument("this version designs transport for point parts only");
        if (!(target.velocity.norm() > 0)) throw std::invalid_argument("a transport target needs a velocity");
        return design_transport(part_scene, target, opt, T);
    }
    return design_sink(part_scene, target, opt);
}

static DesignSummary design_sink(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt) {
    const auto t0 = Clock::now();
    if (!part_scene.part.point)
        throw std::invalid_argument("this version designs sinks for point parts; a rigid part's fixed point, "
                                    "transport and orientation targets are not built yet");
    if (!(std::abs(target.at.x()) <= opt.region && std::abs(target.at.y()) <= opt.region))
        throw std::invalid_argument("the target lies outside the plate region");
    const double T = opt.period > 0 ? opt.period : part_scene.plate.T;
    if (!(T > 0)) throw std::invalid_argument("no plate period (give one)");

    DesignSummary sum;
    sum.notes.push_back("odd harmonics on x, y, rx, ry only: the field is odd about the design's centre, so the "
                        "centre is a fixed point by construction and fixed points come in pairs s, -s");
    sum.notes.push_back("the design's centre moved onto the target by adding -alpha x D to the linear acceleration "
                        "(exact: the field shifts by D)");
    std::atomic<long> cycles{0};
    const int n_starts = std::max(1, opt.starts);
    std::vector<std::vector<double>> best_p(n_starts);
    std::vector<double> best_f(n_starts, std::numeric_limits<double>::infinity());
    std::vector<long> evals(n_starts, 0);
    std::atomic<int> next{0};
    auto worker = [&] {
        for (int k; (k = next++) < n_starts;) {
            SinkProblem prob(part_scene, target.at, opt, T, &cycles);
            Rng rng(opt.seed * 1000003 + static_cast<std::uint64_t>(k));
            std::vector<double> p(kSinkParams);
            bool ok = false;
            for (int tries = 0; tries < 1000 && !ok; ++tries) {
                for (int i = 0; i < kSinkParams; ++i) {
                    const double L = i < 4 ? opt.lin_limit : opt.ang_limit;
                    p[i] = rng.uniform(-L, L) / std::sqrt(2.0);
                }
                ok = prob.feasible(p);
            }
            if (!ok) continue;
            nlopt::opt local(nlopt::LN_COBYLA, kSinkParams);
            std::vector<double> lo(kSinkParams), hi(kSinkParams), step(kSinkParams);
            for (int i = 0; i < kSinkParams; ++i) {
                const double L = i < 4 ? opt.lin_limit : opt.ang_limit;
                lo[i] = -L;
                hi[i] = L;
                step[i] = L / 4;
            }
            local.set_lower_bounds(lo);
            local.set_upper_bounds(hi);
            local.set_initial_step(step);
            local.set_maxeval(opt.local_evaluations);
            local.set_min_objective(
                [](const std::vector<double>& x, std::vector<double>&, void* d) {
                    return static_cast<SinkProblem*>(d)->objective(x);
                },
                &prob);
            local.add_inequality_mconstraint(
                [](unsigned, double* c, unsigned, const double* x, double*, void* d) {
                    static_cast<SinkProblem*>(d)->constraints(std::vector<double>(x, x + kSinkParams), c);
                },
                &prob, std::vector<double>(SinkProblem::kConstraints, 1e-9));
            prob.objective(p);   // the feasible start itself
            double f = 0;
            try {
                local.optimize(p, f);
            } catch (const std::exception&) {
                // (a roundoff-limited stop: the best feasible point found stands)
            }
            best_p[k] = prob.best_p;
            best_f[k] = prob.best_f;
            evals[k] = prob.evaluations;
        }
    };
    const int nt = std::max(1, std::min(n_starts, opt.threads > 0 ? opt.threads : static_cast<int>(std::thread::hardware_concurrency())));
    std::vector<std::thread> pool;
    for (int i = 1; i < nt; ++i) pool.emplace_back(worker);
    worker();
    for (auto& th : pool) th.join();
    for (long e : evals) sum.evaluations += e;
    const int best = static_cast<int>(std::min_element(best_f.begin(), best_f.end()) - best_f.begin());
    sum.scene = part_scene;
    sum.scene.name = part_scene.name + "_sink";
    sum.scene.plate = PlateMotion{};
    sum.scene.plate.T = T;   // (no motion unless a design is found)
    if (!std::isfinite(best_f[best])) {
        sum.failure = "no motion within the limits keeps the part on the plate over the region";
        sum.cycles = cycles;
        sum.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
        return sum;
    }
    {
        SinkProblem prob(part_scene, target.at, opt, T, &cycles);
        prob.evaluate(best_p[best], &sum.rate, &sum.eigenvalues);
        sum.scene.plate = combined(shift_motion(sink_motion(best_p[best], T), target.at));
    }
    sum.cycles = cycles;
    sum.min_vertical_margin = vertical_margin(sum.scene.plate, sum.scene.g, opt.region);

    // --- verification: the field's fixed points on the grid, then full dynamics from random starts.
    GridSpec g;
    g.nx = g.ny = opt.verify_grid;
    g.nth = 1;
    g.x0 = g.y0 = -opt.region;
    g.x1 = g.y1 = opt.region;
    FieldOptions fo;
    fo.threads = opt.threads;
    const Field f = compute_field(sum.scene, g, fo);
    sum.fixed_points = find_fixed_points(sum.scene, f);
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
    Rng rng(opt.seed ^ 0x5DEECE66DULL);
    sum.runs.resize(opt.verify_starts);
    for (DesignStartRun& r : sum.runs) {
        r.x = rng.uniform(-opt.region, opt.region);
        r.y = rng.uniform(-opt.region, opt.region);
        const double d0 = (Vec2(r.x, r.y) - target.at).norm();
        // Long enough for the linearised convergence to bring it within a fifth of the distance asked.
        r.seconds = std::clamp(std::log(std::max(d0, opt.verify_distance) / (0.2 * opt.verify_distance)) / rate, 2.0, 120.0);
    }
    std::atomic<int> next_run{0};
    auto run_worker = [&] {
        for (int k; (k = next_run++) < static_cast<int>(sum.runs.size());) {
            DesignStartRun& r = sum.runs[k];
            IntegrationOptions io;
            io.rtol = 1e-7;
            const Trajectory tr = simulate(sum.scene, Dynamics::Full, Vec3(r.x, r.y, 0), Vec3::Zero(), r.seconds, r.seconds, io);
            r.end_distance = tr.samples.empty() ? std::numeric_limits<double>::infinity()
                                                : (tr.samples.back().q.head<2>() - target.at).norm();
            if (tr.stop.reason != StopReason::None) r.stop = tr.stop.describe();
        }
    };
    pool.clear();
    for (int i = 1; i < nt; ++i) pool.emplace_back(run_worker);
    run_worker();
    for (auto& th : pool) th.join();
    sum.worst_end_distance = 0;
    int stopped = 0;
    for (const DesignStartRun& r : sum.runs) {
        sum.worst_end_distance = std::max(sum.worst_end_distance, r.end_distance);
        stopped += !r.stop.empty();
    }
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

}  // namespace plate
