#include "plate/field.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <cmath>
#include <exception>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace plate {

double wrap_angle(double th) {
    th = std::remainder(th, 2 * kPi);   // [-pi, pi]
    return th <= -kPi ? th + 2 * kPi : th;
}

Vec3 field_at(const Scene& sc, const Vec3& q, const LimitCycleOptions& opt, Vec3* warm, long* rhs_evals) {
    const Vec3 qd0 = warm ? *warm : Vec3::Zero();
    LimitCycleSummary lc = limit_cycle(sc, q, opt, qd0);
    if (rhs_evals) *rhs_evals += lc.stats.rhs_evals;
    if (!lc.converged && warm && !warm->isZero()) {   // retry from rest
        lc = limit_cycle(sc, q, opt);
        if (rhs_evals) *rhs_evals += lc.stats.rhs_evals;
    }
    if (!lc.converged) {
        const bool stopped = lc.stop.reason != StopReason::None;
        throw FieldUndefined("asymptotic twist undefined at (" + std::to_string(q[0]) + ", " + std::to_string(q[1]) + ", " +
                                 std::to_string(q[2]) + "): " + (stopped ? lc.stop.describe() : "limit cycle not converged"),
                             stopped ? lc.stop.reason : StopReason::NotConverged);
    }
    if (warm) *warm = lc.qd_start;
    return lc.twist;
}

namespace {

// Extrapolation to index n from n-1, n-2, n-3 along a line, order 0-2 (backward differences).
constexpr double kExtrap[3][3] = {{1, 0, 0}, {2, -1, 0}, {3, -3, 1}};

// A plate that moves only along z and about z (fig6, heave_yaw) looks the same turned about its
// origin (FieldRun::turned_warm).
bool is_rotation_invariant(const Scene& sc) {
    bool invariant = !sc.plate.harmonics.empty();
    for (const Harmonic& h : sc.plate.harmonics) invariant = invariant && (h.axis == Axis::z || h.axis == Axis::rz);
    return invariant;
}

// One of the shooting field's lines (FieldRun): 'A': k; 'B': i; 'C': i, k.
struct Line {
    char kind;
    int i, k;
};

// A solved start near the one predicted (FieldRun::turned_warm).
struct Near {
    double d;   // squared distance in p
    Vec2 p;
    Vec3 x;   // the solved start in the part's frame (scaled)
};

// One compute_field: the grid's points, what their predictions and schedules share, and the stages
// -- prediction (warm, turned_warm), solving (solve, run_line, run_task), scheduling (lines, threads
// or a task runner), a task's result as text and back -- over them.
struct FieldRun {
    const Scene& sc;
    const GridSpec& grid;
    const FieldOptions& opt;
    Field& f;
    const bool shooting;
    // Cycle starts found so far (scaled by v_ref, v_ref, v_ref / rho; NaN: none), for predictors.
    const Vec3 S;
    std::vector<Vec3> start;
    std::atomic<int> next{0}, done{0};
    std::mutex progress_mutex;
    std::atomic<long> spent{0};
    bool report_progress = true;   // (with a task runner, the runner's done reports)
    std::atomic<bool> over{false};
    std::atomic<bool> failed{false};   // a worker threw (Interrupted): the others take no more work
    const bool rotation_invariant;
    std::vector<double> hint;      // each point's step hint (run_line)
    std::vector<char> switching;   // the point's cycle changes mode (or failed)
    std::vector<Line> lines;       // in an order that respects the predecessors
    int phase1_lines = 0;          // the A and B lines, first in `lines`
    // A runner's task t: with shooting the plane x_t (its lines C_tk), else the line
    // (x_i, y_j, theta) with t = i ny + j.
    const int tasks;

    FieldRun(const Scene& sc, const GridSpec& grid, const FieldOptions& opt, Field& f)
        : sc(sc),
          grid(grid),
          opt(opt),
          f(f),
          shooting(opt.warm_start && opt.cycle.solver == CycleSolver::Shooting),
          S(sc.v_ref(), sc.v_ref(), sc.v_ref() / sc.part.rho()),
          start(grid.size(), Vec3::Constant(std::numeric_limits<double>::quiet_NaN())),
          rotation_invariant(is_rotation_invariant(sc)),
          hint(grid.size(), 0.0),
          switching(grid.size(), 0),
          tasks(shooting ? grid.nx : grid.nx * grid.ny) {
        make_lines();
    }

    LimitCycleSummary solve(int i, int j, int k, const Vec3& warm, double& h0, bool tight);
    Vec3 X(int i, int j, int k) const { return start[grid.index(i, j, k)]; }
    Vec3 warm(int i, int j, int k) const;
    Vec2 part_frame(int i, int j, int k) const {
        const Vec3 q = grid.at(i, j, k);
        return Vec2(Eigen::Rotation2Dd(-q[2]) * Vec2(q[0], q[1]));
    }
    bool turned_warm(int i, int j, int k, Vec3& out) const;
    void make_lines();
    std::vector<int> line_points(const Line& l) const;
    std::vector<int> predecessors(const Line& l) const;
    void run_line(const Line& l);
    std::vector<int> task_points(int t) const;
    void run_task(int t);
    std::string task_text(int t) const;
    int read_task_text(int t, const std::string& text);
    void run_tasks(int first_done);
    void run_workers(int threads, int units, const std::function<void()>& worker);
    void run_lines_on_threads(int threads);
    void settle_budget();
};

// Solves one point from `warm`; with warm starts, the first step is the one the previous point of
// the same task ended with (h0: its step hint, updated here), which saves the step-size ramp-up.
// `tight`: the point solved before it in its line changed mode, so this one likely does too: its
// first period at one tolerance (LimitCycleOptions::first_period_tight; a cycle that changes mode
// goes on tight, and a loose period that changed mode would be one spent in vain).
LimitCycleSummary FieldRun::solve(int i, int j, int k, const Vec3& warm, double& h0, bool tight) {
    const int idx = grid.index(i, j, k);
    FieldPoint& p = f.points[idx];
    p.q = grid.at(i, j, k);
    throw_if_stopped();
    if (opt.max_rhs_evaluations > 0 && spent.load() >= opt.max_rhs_evaluations) {
        over = true;
        LimitCycleSummary none;
        none.stop = StopEvent{StopReason::StepLimit, -1, 0};
        p.twist.setConstant(std::numeric_limits<double>::quiet_NaN());
        p.converged = false;
        p.stop = StopReason::StepLimit;
        ++done;
        return none;
    }
    LimitCycleOptions o = opt.cycle;
    if (opt.warm_start) o.integration.h0 = h0;
    o.first_period_tight = tight;
    LimitCycleSummary lc = limit_cycle(sc, p.q, o, warm);
    if (!lc.converged && !warm.isZero()) {
        const long spent = lc.stats.rhs_evals;
        lc = limit_cycle(sc, p.q, opt.cycle);
        lc.stats.rhs_evals += spent;
    }
    if (lc.converged) h0 = lc.step_hint;
    p.twist = lc.twist;
    p.converged = lc.converged;
    p.periods = lc.periods;
    p.residual = lc.residual;
    p.min_normal_force = lc.min_normal_force;
    p.stop = lc.stop.reason;
    p.rhs_evals = lc.stats.rhs_evals;
    spent += lc.stats.rhs_evals;
    p.stick_fraction = lc.stick_fraction;
    if (lc.converged) start[idx] = lc.qd_start.cwiseQuotient(S);
    const int d = ++done;
    if (opt.progress && report_progress) {
        std::lock_guard<std::mutex> lock(progress_mutex);
        opt.progress(d, grid.size());
    }
    return lc;
}

// Anderson and period by period (no shooting): lines along theta, each start the previous theta's
// cycle (neighbouring cycles along theta are the closest, ~0.025 v_ref apart on fig4).
// Shooting converges in two periods from a start within ~1e-2 v_ref of its cycle, so each start is
// predicted from solved neighbours: extrapolated along one grid line by a polynomial through up
// to three points, plus the difference between the neighbouring parallel line's value and the
// same extrapolation on it (for order 0 the parallelogram rule x(a) + x(b) - x(c)). The cycle start
// is nearly additive in the coordinates and smooth along y, so this leaves on fig4 (max over the
// grid, against the 1e-11 cycles, in v_ref): along y with theta's line 3.6e-4 (cubic), 6.3e-4
// (quadratic), 2.7e-3 (parallelogram); along y with x's line 2.6e-3 (quadratic) and 8.2e-3
// (parallelogram); along x with theta's line 2.6e-3 (quadratic); the nearest neighbour alone
// 0.03-0.08. The lines and their order: make_lines.
Vec3 FieldRun::warm(int i, int j, int k) const {
    // Along y (j > 0) or, on the first line j = 0, along x; the neighbouring parallel line is
    // theta's (k - 1) if there is one, else x's (i - 1) for lines along y.
    const bool along_y = j > 0;
    const int n = along_y ? j : i;
    auto at = [&](int m, bool nb) {   // the point at index m on the line (nb: on the neighbour line)
        const int kk = nb && k > 0 ? k - 1 : k;
        const int ii = nb && k == 0 ? i - 1 : i;
        return along_y ? X(ii, m, kk) : X(m, 0, kk);
    };
    const bool has_nb = k > 0 || (along_y && i > 0);
    for (int order = std::min(n, 3) - 1; order >= 0; --order) {
        for (bool nb : {true, false}) {
            if (nb && !has_nb) continue;
            Vec3 x = Vec3::Zero();
            for (int l = 0; l <= order; ++l) {
                x += kExtrap[order][l] * at(n - 1 - l, false);
                if (nb) x -= kExtrap[order][l] * at(n - 1 - l, true);
            }
            if (nb) x += at(n, true);
            if (x.allFinite()) return x.cwiseProduct(S);
        }
    }
    // The first point of the first line: its theta neighbour, else none (a cold start).
    if (n == 0 && k > 0 && X(i, j, k - 1).allFinite()) return X(i, j, k - 1).cwiseProduct(S);
    return Vec3::Zero();
}

// A plate that moves only along z and about z (fig6, heave_yaw) looks the same turned about its
// origin, so the cycle at (R_a s, theta + a) is the cycle at (s, theta) turned by a: (R_a v, theta').
// A configuration's cycle then depends only on where the plate's origin sits in the part's frame,
// p = R(-theta) s, and its start (in the part's frame) is predicted from the points solved before it
// in every schedule (the lines' predecessors, below) by a quadratic in p fitted to the eight whose p
// are nearest (least squares; fewer than eight: the plane through the three nearest, else the
// nearest), turned back. fig6's 7^3 field, median prediction error against the solved start:
// sliding configurations 0.34 -> 0.045 v_ref, sticking 0.44 -> 0.076; right-hand sides 1.69e6 ->
// 1.46e6 (the nearest alone 1.64e6, the plane through three 1.53e6, quadratics through 6, 12, 20:
// 1.51e6, 1.50e6, 1.53e6); heave_yaw's 1.67e6 -> 1.40e6.
bool FieldRun::turned_warm(int i, int j, int k, Vec3& out) const {
    const Vec2 p = part_frame(i, j, k);
    std::vector<Near> near;
    auto consider = [&](int m, int n, int l) {
        const Vec3 x = X(m, n, l);
        if (!x.allFinite()) return;
        const Vec2 pm = part_frame(m, n, l);
        const Vec2 v = Eigen::Rotation2Dd(-grid.at(m, n, l)[2]) * Vec2(x[0], x[1]);
        near.push_back({(pm - p).squaredNorm(), pm, Vec3(v[0], v[1], x[2])});
    };
    // Solved before (i, j, k) whatever the schedule: the lines A_l up to l = k (on A_k itself the
    // points before it), for lines along y the B lines up to i (B_i: the points before it), and
    // on C_ik the plane's C lines before k and the points of C_ik before it.
    for (int l = 0; l <= k; ++l)
        for (int m = 0; m < grid.nx; ++m)
            if (l < k || j > 0 || m < i) consider(m, 0, l);
    if (j > 0) {
        for (int m = 0; m <= (k == 0 ? i - 1 : i); ++m)
            for (int n = 1; n < grid.ny; ++n) consider(m, n, 0);
        for (int l = 1; l < k; ++l)
            for (int n = 1; n < grid.ny; ++n) consider(i, n, l);
        for (int n = 1; n < j; ++n) consider(i, n, k);
    }
    if (near.empty()) return false;
    std::stable_sort(near.begin(), near.end(), [](const Near& a, const Near& b) { return a.d < b.d; });
    Vec3 x = near[0].x;
    auto fit = [&](int n, int terms) {   // least squares, the value at p (false: degenerate)
        Eigen::MatrixXd A(n, terms), B(n, 3);
        for (int r = 0; r < n; ++r) {
            const double dx = near[r].p.x() - p.x(), dy = near[r].p.y() - p.y();
            const double row[6] = {1, dx, dy, dx * dx, dx * dy, dy * dy};
            for (int c = 0; c < terms; ++c) A(r, c) = row[c];
            B.row(r) = near[r].x.transpose();
        }
        const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeThinU | Eigen::ComputeThinV);
        if (!(svd.singularValues()[terms - 1] > 1e-6 * svd.singularValues()[0])) return false;
        x = svd.solve(B).row(0).transpose();
        return true;
    };
    const int n = static_cast<int>(near.size());
    if (!(n >= 8 && fit(8, 6)) && n >= 3) fit(3, 3);
    const Vec2 v = Eigen::Rotation2Dd(grid.at(i, j, k)[2]) * Vec2(x[0], x[1]);
    out = Vec3(v[0], v[1], x[2]).cwiseProduct(S);
    return true;
}

// The shooting field's lines and what each start is predicted from (warm above):
//   A_k (k = 0..nth-1): the points (x_i, y_0, theta_k), i = 0..nx-1, along x; after A_{k-1};
//   B_i (i = 0..nx-1):  the points (x_i, y_j, theta_0), j >= 1, along y;    after A_0, B_{i-1};
//   C_ik (k >= 1):      the points (x_i, y_j, theta_k), j >= 1, along y;    after A_k and
//                       C_i,k-1 (B_i for k = 1).
// Every prediction reads only points of lines before it in that order, and each line's first step
// is the step hint of a fixed point of a line before it (A_k: (x_0, y_0, theta_k-1); B_i and C_ik:
// (x_i, y_0, theta_k)), then each point's goes to the next. So the field is the same however the
// lines are scheduled: threads take a line whose predecessors are done (critical path ~ a
// quarter of the 7^3 grid), a task runner gets the planes {C_ik, k >= 1} after every process has
// solved the A and B lines.
void FieldRun::make_lines() {
    if (shooting) {
        for (int k = 0; k < grid.nth; ++k) lines.push_back({'A', 0, k});
        for (int i = 0; i < grid.nx; ++i) lines.push_back({'B', i, 0});
    }
    phase1_lines = static_cast<int>(lines.size());
    if (shooting)
        for (int i = 0; i < grid.nx; ++i)
            for (int k = 1; k < grid.nth; ++k) lines.push_back({'C', i, k});
}

std::vector<int> FieldRun::line_points(const Line& l) const {
    std::vector<int> idx;
    if (l.kind == 'A')
        for (int i = 0; i < grid.nx; ++i) idx.push_back(grid.index(i, 0, l.k));
    else
        for (int j = 1; j < grid.ny; ++j) idx.push_back(grid.index(l.i, j, l.kind == 'B' ? 0 : l.k));
    return idx;
}

std::vector<int> FieldRun::predecessors(const Line& l) const {
    std::vector<int> d;   // indices into lines
    if (l.kind == 'A' && l.k > 0) d.push_back(l.k - 1);
    if (l.kind == 'B') {
        d.push_back(0);
        if (l.i > 0) d.push_back(grid.nth + l.i - 1);
    }
    if (l.kind == 'C') {
        d.push_back(l.k);
        d.push_back(l.k == 1 ? grid.nth + l.i : phase1_lines + l.i * (grid.nth - 1) + l.k - 2);
    }
    return d;
}

void FieldRun::run_line(const Line& l) {
    const std::vector<int> idx = line_points(l);
    if (idx.empty()) return;
    const int before = l.kind == 'A' ? (l.k > 0 ? grid.index(0, 0, l.k - 1) : -1) : grid.index(l.i, 0, l.kind == 'B' ? 0 : l.k);
    double h0 = before >= 0 ? hint[before] : 0.0;
    bool tight = before >= 0 && switching[before];
    for (int id : idx) {
        const int i = id / (grid.ny * grid.nth), j = (id / grid.nth) % grid.ny, k = id % grid.nth;
        Vec3 w;
        if (!(rotation_invariant && turned_warm(i, j, k, w))) w = warm(i, j, k);
        const LimitCycleSummary lc = solve(i, j, k, w, h0, tight);
        hint[id] = h0;
        switching[id] = !lc.converged || lc.start_mode.kind != ModeKind::Slide || !lc.mode_events.empty();
        tight = switching[id];
    }
}

std::vector<int> FieldRun::task_points(int t) const {
    std::vector<int> idx;
    if (shooting) {
        for (int k = 1; k < grid.nth; ++k)
            for (int j = 1; j < grid.ny; ++j) idx.push_back(grid.index(t, j, k));
    } else {
        for (int k = 0; k < grid.nth; ++k) idx.push_back(grid.index(t / grid.ny, t % grid.ny, k));
    }
    return idx;
}

void FieldRun::run_task(int t) {
    if (shooting) {
        for (int k = 1; k < grid.nth; ++k) run_line({'C', t, k});
    } else {
        double h0 = 0;
        Vec3 w = Vec3::Zero();
        for (int k = 0; k < grid.nth; ++k) {
            const LimitCycleSummary lc = solve(t / grid.ny, t % grid.ny, k, opt.warm_start ? w : Vec3::Zero(), h0, true);
            w = lc.converged ? lc.qd_start : Vec3::Zero();
        }
    }
}

// A task's text: its points' results, doubles exact (q follows from the grid).
std::string FieldRun::task_text(int t) const {
    std::string text;
    for (int idx : task_points(t)) {
        const FieldPoint& p = f.points[idx];
        for (double x : {p.twist[0], p.twist[1], p.twist[2], p.residual, p.min_normal_force, p.stick_fraction[0],
                         p.stick_fraction[1], p.stick_fraction[2]})
            text += exact_text(x) + ' ';
        text += std::to_string(p.converged) + ' ' + std::to_string(p.periods) + ' ' + std::to_string(static_cast<int>(p.stop)) +
                ' ' + std::to_string(p.rhs_evals) + '\n';
    }
    return text;
}

// Task t's points from its text (task_text); the number of points read.
int FieldRun::read_task_text(int t, const std::string& text) {
    std::istringstream in(text);
    const std::vector<int> idx = task_points(t);
    for (int i : idx) {
        FieldPoint& p = f.points[i];
        std::string x[8];
        int converged = 0, stop = 0;
        for (auto& w : x) in >> w;
        in >> converged >> p.periods >> stop >> p.rhs_evals;
        if (!in) throw std::runtime_error("compute_field: a task's result is damaged");
        p.q = grid.at(i / (grid.ny * grid.nth), (i / grid.nth) % grid.ny, i % grid.nth);
        p.twist = Vec3(exact_value(x[0]), exact_value(x[1]), exact_value(x[2]));
        p.residual = exact_value(x[3]);
        p.min_normal_force = exact_value(x[4]);
        for (int c = 0; c < 3; ++c) p.stick_fraction[c] = exact_value(x[5 + c]);
        p.converged = converged != 0;
        p.stop = static_cast<StopReason>(stop);
        if (p.stop == StopReason::StepLimit && !p.converged && p.rhs_evals == 0) over = true;
    }
    return static_cast<int>(idx.size());
}

// The tasks through the runner (FieldOptions::tasks), after the first_done points this process
// solved itself (the A and B lines).
void FieldRun::run_tasks(int first_done) {
    report_progress = false;
    int reported = 0;
    opt.tasks(
        tasks,
        [&](int t) {
            run_task(t);
            return task_text(t);
        },
        [&](int t, const std::string& text) {
            reported += read_task_text(t, text);
            if (opt.progress) opt.progress(first_done + reported, grid.size());
        });
    f.threads = 0;
}

// min(threads, units) workers, this thread one of them, each polling this thread's stop request.
// The first exception a worker throws (Interrupted) is rethrown once all have returned.
void FieldRun::run_workers(int threads, int units, const std::function<void()>& worker) {
    threads = std::max(1, std::min(threads, units));
    f.threads = threads;
    const StopRequest* request = current_stop_request();
    std::exception_ptr error;
    std::mutex error_mutex;
    auto guarded = [&] {
        const StopScope scope(request);
        try {
            worker();
        } catch (...) {
            const std::lock_guard<std::mutex> lock(error_mutex);
            if (!error) error = std::current_exception();
            failed = true;
        }
    };
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t) pool.emplace_back(guarded);
    guarded();
    for (auto& t : pool) t.join();
    if (error) std::rethrow_exception(error);
}

// Threads take a line whose predecessors are done (the one with the most behind it).
void FieldRun::run_lines_on_threads(int threads) {
    const int n = static_cast<int>(lines.size());
    std::vector<int> waiting(n, 0);
    std::vector<std::vector<int>> after(n);
    for (int l = 0; l < n; ++l)
        for (int d : predecessors(lines[l])) {
            ++waiting[l];
            after[d].push_back(l);
        }
    // Of the ready lines, the one with the most points still behind it (itself and its
    // longest chain of successors) goes first: fig6's 7^3 field (its costs per point
    // replayed on 2 workers) 1.85x -> 1.95x the one-thread time, against "first in order".
    std::vector<int> behind(n, 0);
    for (int l = n - 1; l >= 0; --l) {
        int most = 0;
        for (int a : after[l]) most = std::max(most, behind[a]);
        behind[l] = static_cast<int>(line_points(lines[l]).size()) + most;
    }
    std::vector<char> taken(n, 0);
    int finished = 0;
    std::mutex m;
    std::condition_variable cv;
    auto worker = [&]() {
        std::unique_lock<std::mutex> lock(m);
        for (;;) {
            int l = -1;
            cv.wait(lock, [&] {
                for (int c = 0; c < n; ++c)
                    if (!taken[c] && waiting[c] == 0 && (l < 0 || behind[c] > behind[l])) l = c;
                return l >= 0 || finished == n || failed;
            });
            if (l < 0 || failed) return;
            taken[l] = 1;
            lock.unlock();
            try {
                run_line(lines[l]);
            } catch (...) {   // (the line is never finished: wake the workers waiting for it)
                lock.lock();
                failed = true;
                cv.notify_all();
                throw;
            }
            lock.lock();
            ++finished;
            for (int a : after[l]) --waiting[a];
            cv.notify_all();
        }
    };
    run_workers(threads, n, worker);
}

// Over budget when the work exceeded it, however it was shared: each process cuts its own work
// once *it* has spent the budget (then the total is over too), and the total is compared here,
// so that one process and any number of ranks agree on whether the field is a result.
void FieldRun::settle_budget() {
    for (const auto& p : f.points) f.rhs_evals += p.rhs_evals;
    f.budget_spent = over || (opt.max_rhs_evaluations > 0 && f.rhs_evals > opt.max_rhs_evaluations);
}

}   // namespace

Field compute_field(const Scene& sc, GridSpec grid, const FieldOptions& opt) {
    if (sc.part.point) {
        grid.nth = 1;
        grid.th0 = 0;
    }
    if (grid.nx < 1 || grid.ny < 1 || grid.nth < 1) throw std::invalid_argument("grid sizes must be >= 1");
    Field f;
    f.grid = grid;
    f.point_part = sc.part.point;
    f.points.resize(grid.size());
    const auto t_start = std::chrono::steady_clock::now();
    const int threads = opt.threads > 0 ? opt.threads : static_cast<int>(std::thread::hardware_concurrency());
    const StopScope scope(opt.stop);
    FieldRun run(sc, grid, opt, f);
    if (opt.tasks) {
        // With shooting every process solves the A and B lines, the runner shares the planes.
        int first_done = 0;
        if (run.shooting) {
            for (int n = 0; n < run.phase1_lines; ++n) run.run_line(run.lines[n]);
            first_done = run.done.load();
        }
        run.run_tasks(first_done);
    } else if (run.shooting) {
        run.run_lines_on_threads(threads);
    } else {
        run.run_workers(threads, run.tasks, [&]() {
            for (int t; !run.failed && (t = run.next.fetch_add(1)) < run.tasks;) run.run_task(t);
        });
    }
    run.settle_budget();
    f.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count();
    return f;
}

FieldWorkEstimate estimate_field_work(const Scene& sc, const GridSpec& g, const LimitCycleOptions& lo) {
    const auto t0 = std::chrono::steady_clock::now();
    const double dth = 2 * kPi / 5;
    const Vec3 samples[] = {{(g.x0 + g.x1) / 2, (g.y0 + g.y1) / 2, g.th0},
                            {g.x0 + 0.25 * (g.x1 - g.x0), g.y0 + 0.25 * (g.y1 - g.y0), g.th0 + dth},
                            {g.x0 + 0.75 * (g.x1 - g.x0), g.y0 + 0.25 * (g.y1 - g.y0), g.th0 + 2 * dth},
                            {g.x0 + 0.25 * (g.x1 - g.x0), g.y0 + 0.75 * (g.y1 - g.y0), g.th0 + 3 * dth},
                            {g.x0 + 0.75 * (g.x1 - g.x0), g.y0 + 0.75 * (g.y1 - g.y0), g.th0 + 4 * dth}};
    double total = 0;
    for (const Vec3& q : samples) total += std::max<double>(limit_cycle(sc, q, lo).stats.rhs_evals, 1);
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double n = static_cast<double>(g.size());
    FieldWorkEstimate e;
    e.per_configuration = total / 5;
    e.total = e.per_configuration * n;
    e.seconds = secs / 5 * n;
    return e;
}

void require_field_work(const Scene& sc, const GridSpec& g, const LimitCycleOptions& cycle, long budget,
                        const std::string& raise_with) {
    if (budget <= 0) return;
    const FieldWorkEstimate e = estimate_field_work(sc, g, cycle);
    if (e.total <= static_cast<double>(budget)) return;
    auto fmt = [](double x) {
        std::ostringstream s;
        s.precision(3);
        s << x;
        return s.str();
    };
    throw std::invalid_argument("a " + std::to_string(g.nx) + "x" + std::to_string(g.ny) + "x" + std::to_string(g.nth) +
                                " grid would take about " + fmt(e.total) + " right-hand sides (" + fmt(e.per_configuration) +
                                " per configuration, the mean of five cycles run first: about " + fmt(e.seconds) +
                                " s on one core here), above the budget of " + fmt(static_cast<double>(budget)) +
                                ": raise it with " + raise_with + " or use a coarser grid");
}

Trajectory field_curve(const Scene& sc, const Vec3& q0, double duration, double sample_dt, const LimitCycleOptions& opt,
                       double h) {
    if (!(duration > 0 && sample_dt > 0 && h > 0)) throw std::invalid_argument("field_curve: times must be > 0");
    Trajectory tr;
    Vec3 q = q0, warm = Vec3::Zero();
    double t = 0;
    auto F = [&](const Vec3& x) {
        Vec3 v = field_at(sc, x, opt, &warm);
        if (sc.part.point) v[2] = 0;
        ++tr.stats.steps;
        return v;
    };
    try {
        Vec3 k1 = F(q);
        tr.samples.push_back(Sample{0, q, k1, Vec3::Constant(std::numeric_limits<double>::quiet_NaN()), Mode{}});
        const long count = static_cast<long>(std::ceil(duration / sample_dt - 1e-9));
        for (long s = 1; s <= count; ++s) {
            const double ts = std::min(s * sample_dt, duration);
            while (t < ts - 1e-12 * ts) {
                const double dt = std::min(h, ts - t);
                const Vec3 k2 = F(q + 0.5 * dt * k1), k3 = F(q + 0.5 * dt * k2), k4 = F(q + dt * k3);
                q += dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
                t += dt;
                k1 = F(q);
            }
            tr.samples.push_back(Sample{ts, q, k1, Vec3::Constant(std::numeric_limits<double>::quiet_NaN()), Mode{}});
        }
    } catch (const FieldUndefined& e) {
        tr.stop = StopEvent{e.reason, -1, t};
    }
    return tr;
}

const char* stability_name(Stability s) {
    switch (s) {
        case Stability::Stable:
            return "stable";
        case Stability::Unstable:
            return "unstable";
        case Stability::Saddle:
            return "saddle";
        case Stability::Centre:
            return "centre";
    }
    return "?";
}

}   // namespace plate
