// design/'s internal header: what the target files share (the search's Problem and multi-start driver,
// the verification's runs and verdicts, the coefficient layout) and the targets' entry points, which
// design.cpp's dispatch calls. Not installed: the public API is design.hpp.
#pragma once

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
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace plate::design_detail {

using Clock = std::chrono::steady_clock;

// --- the coefficient layout and what the searches share (search.cpp) ------------------------------

// Harmonics combined per (axis, n) as phasors amp e^{i phase}: the amplitude a scene's reader sees.
std::map<std::pair<int, int>, std::complex<double>> phasors(const PlateMotion& u);
// The motion with one harmonic per (axis, n) (amplitude >= 0), as a scene file states it.
PlateMotion combined(const PlateMotion& u);
// The coefficients of u in motion_from's layout; empty if u has a harmonic outside it.
std::vector<double> params_from(const PlateMotion& u, const std::vector<Axis>& axes, const std::vector<int>& harmonics);
// Eight points on the edge of the region |s_x|, |s_y| <= R: corners and midpoints.
std::array<Vec2, 8> region_edge(double R);
// A limit cycle's twist error relative to v_ref (and v_ref / rho): its tolerance plus the integrator's,
// ~60 rtol v_ref (field.hpp).
double cycle_noise(const LimitCycleOptions& o);
// The option's task runner, else its threads.
TaskRunner runner(const DesignOptions& opt);
// c_a <= 0 for each axis' peak of `fin` (axis_peaks) within `room` times the axis' limit (6 entries),
// then c <= 0 for no flight over the region, then corner_constraints' entries; returns the entries
// written (kPeakConstraints + corner_count(opt)).
constexpr int kPeakConstraints = 7;
int peak_constraints(const PlateMotion& fin, const DesignOptions& opt, const Scene& part, double room, double* c);
// The corner limits' constraints: none where neither limit is set (a search without them is unchanged),
// else c <= 0 for the corners' peak displacement and velocity within `room` times their limits (an
// unset one: -1). Arrays of constraints leave room for kCornerConstraints more than their own.
constexpr int kCornerConstraints = 2;
int corner_count(const DesignOptions& opt);
int corner_constraints(const PlateMotion& fin, const DesignOptions& opt, const Scene& part, double room, double* c);
// The plate's corners the limits apply at: plate_half_size, or the flight check's square.
Vec2 corner_half_size(const Scene& part, const DesignOptions& opt);

// --- peaks (plate/peaks.hpp, numeric) ------------------------------------------------------------------
using plate::horizontal_peak;
using plate::trig_peak;

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
    // Derived's constraints and the corner limits' (corner_count).
    int constraint_count() const { return Derived::kConstraints + corner_count(opt); }
    bool feasible(const std::vector<double>& p) const {
        double c[Derived::kConstraints + kCornerConstraints];
        self().constraints(p, c);
        return std::all_of(c, c + constraint_count(), [](double x) { return x <= 0; });
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
// every 100 infeasible tries, up to 1000), NLopt COBYLA with the constraints within the box +-limit
// (a search range: a coefficient within the peak limits may reach 4 / pi of them, and a box that wide
// made fig4's half-turn pair search fail; docs/decisions/design-and-tools.md, "Peak limits"),
// opt.local_evaluations each,
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
        if (!any)
            throw std::invalid_argument("the axes and harmonics allowed leave this target's motion family nothing to move (" +
                                        std::string(P::kFamily) + ")");
    }
    const int m = static_cast<int>(free_idx.size());
    const int n_starts = std::max(1, opt.starts);
    std::vector<std::vector<double>> best_p(n_starts);
    std::vector<double> best_f(n_starts, std::numeric_limits<double>::infinity());
    std::vector<long> evals(n_starts, 0);
    std::atomic<long>* const cycles = make().cycles;   // (each start counts its own and sends it)
    runner(opt)(
        n_starts,
        [&](int k) -> std::string {
            P prob = make();
            std::atomic<long> own_cycles{0};
            prob.cycles = &own_cycles;
            Rng rng(opt.seed * 1000003 + static_cast<std::uint64_t>(k));
            std::vector<double> p(n), lo(n), hi(n), step(n);
            bool ok = false;
            // Start 0 from the part scene's own plate motion when the problem can express it and it is
            // feasible (the "starting guess").
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
                std::string text =
                    exact_text(prob.best_f) + ' ' + std::to_string(prob.evaluations) + ' ' + std::to_string(own_cycles.load());
                for (double x : prob.best_p) text += ' ' + exact_text(x);
                return text;
            };
            prob.objective(p);             // the feasible start itself
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
                    double cp[P::kConstraints + kCornerConstraints];
                    std::vector<double> xp(xr, xr + mr);
                    for (unsigned j = 0; j < mr; ++j) {   // grad[k m + j] = d c_k / d x_j
                        const double h = 1e-3 * r.prob->limit((*r.idx)[j]);
                        xp[j] += h;
                        r.prob->constraints(r.place(xp.data()), cp);
                        xp[j] = xr[j];
                        for (int k = 0; k < r.prob->constraint_count(); ++k) grad[k * mr + j] = (cp[k] - c[k]) / h;
                    }
                },
                &red, std::vector<double>(static_cast<std::size_t>(prob.constraint_count()), 1e-9));
            double f = 0;
            try {
                local.optimize(x, f);
            } catch (const std::exception&) {
                // (a roundoff-limited stop: the best feasible point found stands)
            }
            return result();
        },
        [&](int k, const std::string& text) {
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

// --- robust designs (robust.cpp) ------------------------------------------------------------------

// The search holds the first-order radius to this fraction of robust_radius: the verification's 95 %
// radius is an order statistic of its draws, 5 % uncertain at 200 (docs/decisions/uncertainty.md).
constexpr double kRobustRadiusMargin = 0.85;

// The first-order 95 % radius under `spec` of the fixed point at `at` of final_scene (its plate the
// final, shifted motion, as the draws perturb it); infinite where a cycle failed. Counts its cycles.
double first_order_radius95(const Scene& final_scene, const UncertaintySpec& spec, const Vec2& at, const LimitCycleOptions& lo,
                            std::atomic<long>& cycles);
// The verification on the spec's draws (DesignOptions::robust): sum.robustness, a note, and on failure
// verified false with the reason.
void verify_robust(DesignSummary& sum, const DesignTarget& target, const DesignOptions& opt);

// --- verification (verify.cpp) -------------------------------------------------------------------

constexpr const char* kNoFeasibleMotion =
    "no motion within the limits (and the corner limits, if set) keeps the part on the plate over the region";
// The verify_grid^2 grid over the region (a rigid part: verify_grid orientations too), and the designed
// field on it.
GridSpec verification_grid(const Scene& sc, const DesignOptions& opt);
Field verification_field(const Scene& sc, const DesignOptions& opt);
// What the grid's fixed-point search could not look at (empty: it searched every cell); a fixed point is
// called unique only where this is empty.
std::string unsearched(const FixedPoints& f);
// The designed motion's peaks (sum.peaks) judged against the limits: a verified design beyond one fails.
void judge_peaks(DesignSummary& sum, const DesignOptions& opt);
// The hold's verdict (empty: held, or no hold asked): released at the target, the part ended beyond
// verify_distance (`unit` names the distance) or left the model.
std::string hold_failure(const DesignSummary& sum, const DesignOptions& opt, const std::string& unit);
// The summary's last entries, whatever the outcome: the cycles computed and the wall time.
DesignSummary& finished(DesignSummary& sum, const std::atomic<long>& cycles, Clock::time_point t0);
// A verification run's duration: long enough for the slowest mode, at `rate` [1/s], to bring a start
// d0 away within a fifth of the distance asked (2 s to 120 s).
double settle_time(double d0, double rate, const DesignOptions& opt);
// A point part's verification run from `start`: the time the designed field takes to bring it within a
// fifth of verify_distance of `target` (verify.cpp says how).
double field_settle_time(const Field& f, const Vec2& start, const Vec2& target, const DesignOptions& opt);
// The summary's scene before a design is found: the part on a plate at rest.
void start_summary(DesignSummary& sum, const Scene& part, const std::string& suffix, double T);
// The position's field v0 at (s, theta) and its Jacobian in s by central differences of h: five limit
// cycles (counted in `cycles`); false if one did not converge.
bool position_pull(const Scene& sc, const Vec2& s, double theta, const LimitCycleOptions& cyc, double h, Vec2& v0,
                   Eigen::Matrix2d& J, std::atomic<long>& cycles);
// The checks every sink and fixed point ends with, where nothing before failed: the hold (`unheld`:
// hold_failure's verdict) and the flight margin; then the summary's end.
DesignSummary& last_checks(DesignSummary& sum, const DesignOptions& opt, const std::string& unheld,
                           const std::atomic<long>& cycles, Clock::time_point t0);
// An orient run's end judged against `theta` (orient.cpp): its orientation's distance from theta on
// the scale of verify_distance, which stands for 0.05 rad.
double orient_end_distance(const Vec3& end, double theta, const DesignOptions& opt);
// A rigid part's sink verified (sink.cpp): at the target, for each of `field`'s orientations, the
// position's field vanishes there and attracts (both eigenvalues' real parts negative); then sink_verdict.
DesignSummary& verify_rigid_sink(DesignSummary& sum, const Field& field, const DesignTarget& target, const DesignOptions& opt,
                                 std::atomic<long>& cycles, Clock::time_point t0);
// A sink's verdict, shared: full-dynamics runs from random starts and from the target (the hold), then
// the first check that fails (verify.cpp).
DesignSummary& sink_verdict(DesignSummary& sum, const Field& settle, const DesignTarget& target, const DesignOptions& opt,
                            const std::string& not_unique, std::atomic<long>& cycles, Clock::time_point t0);

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
    runner(opt)(
        opt.verify_starts + holding,
        [&](int k) {
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
        },
        [&](int k, const std::string& text) {
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
constexpr double kConingLimit =
    1e-4;   // [rad/s] rigid fixed points' coning (coning_rate, design.hpp): 0.012 rad over a 120 s hold
// [rad/s] their tilt drift (tilt_drift_rate): a tilt pulls the part downhill, g times the tilt, all
// along, so it is held to 1e-3 rad (0.01 m/s^2, 0.3 % of mu g for mu 0.3) over the longest runs
// (break_pair's: up to about 500 s). A motion without rz has none; break_pair's has none by construction.
constexpr double kTiltDriftLimit = 2e-6;

inline PlateMotion sink_motion(const std::vector<double>& p, double T) {
    return motion_from(p, {Axis::x, Axis::y, Axis::rx, Axis::ry}, {1, 3}, T);
}

struct SinkProblem : Problem<SinkProblem> {
    // With `orient` (a rigid part's fixed point as a half-turn pair, design_rigid_pair): the part's
    // orientation THETA is to be a stable zero of theta' at the centre as well, and the coning is held to
    // kConingLimit (the plate's turn would turn the part's orientation with it).
    SinkProblem(const Scene& part_, const Vec2& D_, const DesignOptions& opt_, double T_, std::atomic<long>* cycles_,
                const double* orient_ = nullptr)
        : Problem(part_, opt_, T_, cycles_),
          D(D_),
          cone_limit(sink_coning_limit(D_, opt_)),
          orient(orient_ != nullptr),
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
    static constexpr int kConstraints = kPeakConstraints + 2;   // six peaks, the flight margin, coning both ways
    double limit(int i) const { return i < 8 ? opt.lin_limit : opt.ang_limit; }
    bool is_free(int i) const { return free({Axis::x, Axis::y, Axis::rx, Axis::ry}, {1, 3}, i); }   // (sink_motion's layout)

    // Constraints c_k <= 0 on the final (shifted) motion: each axis' peak within its limit (the shift
    // adds -alpha x D to x and y), no flight under the part over the region, and no more coning than
    // the hold allows.
    void constraints(const std::vector<double>& p, double* c) const {
        const PlateMotion fin = shift_motion(sink_motion(p, T), D);
        // (orient: 3 % of each limit and 0.02 g of the flight margin kept in hand for the placement's
        // small turn and shift onto the fixed point found)
        const int k = peak_constraints(fin, opt, part, orient ? 0.97 : 1.0, c);
        if (orient) c[kPeakConstraints - 1] += 0.02;   // (the flight margin's entry)
        const double psi = coning_rate(fin);
        const double cone = !std::isfinite(cone_limit) ? 0.0
                            : cone_limit > 0           ? psi / cone_limit
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
        // Robust (a point part's sink): the first-order spread of the final motion's fixed point; a point
        // that does not attract has no spread to speak of and takes the cap (else a repeller, whose
        // "spread" -J^-1 dxi/dp can be small, would beat every sink).
        double spread = 0;
        if (opt.robust && part.part.point && !orient && !(rate > 0)) spread = 50;
        if (opt.robust && part.part.point && !orient && rate > 0) {
            Scene fin = part;
            fin.plate = combined(shift_motion(sink_motion(p, T), D));
            spread = std::min(50.0, std::max(0.0, first_order_radius95(fin, *opt.robust, D, opt.cycle, *cycles) /
                                                          (kRobustRadiusMargin * opt.robust_radius) -
                                                      1));
        }
        return -rate + 10 * outward + 10 * std::max(0.0, offset / 0.001 - 1) + 10 * std::max(0.0, turn - 1) + 10 * spread;
    }
};

// --- the targets (one file each; design.cpp's dispatch picks one) ---------------------------------

// Whether the part's contacts' kinetic friction differs (beyond 1e-9 relative): a translating plate
// turns such a part like a weathervane, and cannot turn one whose contacts share one coefficient.
inline bool friction_differs(const Part& part) {
    const ContactFriction mu = part.friction();
    double lo = mu.kinetic(0), hi = lo;
    for (int i = 1; i < part.contacts(); ++i) lo = std::min(lo, mu.kinetic(i)), hi = std::max(hi, mu.kinetic(i));
    return hi > lo * (1 + 1e-9);
}

// A registered kind of target by name (nullptr if none; design_target.cpp).
const DesignTargetType* registered(const std::string& name);

DesignSummary design_sink(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt, double T);
DesignSummary design_line_sink(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt, double T);
DesignSummary design_transport(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt, double T);
DesignSummary design_orient(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt, double T);
DesignSummary design_rigid_pair(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt, double T);
DesignSummary design_rigid(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt, double T);

// The translating plate's motion (x, y, z at n = 1, 2; transport.cpp), which the weathervane shares.
inline const std::vector<Axis> kTranslationAxes = {Axis::x, Axis::y, Axis::z};
PlateMotion transport_motion(const std::vector<double>& p, double T);

// What the rigid fixed point (rigid_fixed_point.cpp) and its broken pair (break_pair.cpp) share.
// Constraints c_k <= 0 on a motion as placed: each axis' peak within its limit times `room`, no
// flight, no coning beyond kConingLimit either way and no tilt drift beyond kTiltDriftLimit
// (kPlacedConstraints entries, and corner_count(opt) more).
constexpr int kPlacedConstraints = kPeakConstraints + 3;
void placed_constraints(const PlateMotion& fin, const DesignOptions& opt, const Scene& part, double room, double* c);
// The field xi_a at q and its Jacobian by central differences (steps 3 mm and 0.1 rad), warm-started
// from the cycle at q. False if a cycle did not converge.
bool twist_and_jacobian(const Scene& sc, const Vec3& q, const LimitCycleOptions& cyc, Vec3& xi, Mat3& J,
                        std::atomic<long>& cycles);
// A centred motion whose fixed point is q, placed so that it lands on (at, THETA - theta_offset).
PlateMotion placed_motion(const PlateMotion& centred, const Vec3& q, const Vec2& at, double theta, double theta_offset = 0);
// A rigid design's last stages, shared: the fixed point of `centred` near q0, placed exactly on the
// target, checked against the limits, and verified (rigid_fixed_point.cpp).
DesignSummary& place_and_verify_rigid(DesignSummary& sum, const Scene& part_scene, const PlateMotion& centred_motion,
                                      const Vec3& q0, const DesignTarget& target, const DesignOptions& opt,
                                      std::atomic<long>& cycles, Clock::time_point t0, bool pair = false, double run_seconds = 0,
                                      double theta_offset = 0);
// theta' along the position's fixed points s*(theta) on n orientations theta_k = -pi + 2 pi k / n,
// linearised about `base` (break_pair.cpp; bench_orientation_robustness reads it too). False where a
// cycle did not converge.
bool reduced_ring(const Scene& sc, const Vec2& base, int n, const LimitCycleOptions& cyc, long& own, double* w);
// The half-turn pair broken by rz about its centre (break_pair.cpp).
DesignSummary break_pair(const Scene& part_scene, const PlateMotion& pair_motion, const DesignTarget& target,
                         const DesignOptions& opt, double T, std::atomic<long>& cycles, Clock::time_point t0);

}   // namespace plate::design_detail
