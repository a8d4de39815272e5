// The search's coarse first steps, and its wide and line steps last (internal.hpp, coarse_steps and line_steps).
//
// Coarse (IdentifyOptions::coarse_iterations; docs/decisions/identification.md, "Coarse steps first"):
// Levenberg-Marquardt on the whole tracks, every track's start held at its first
// frame, the kinetic coefficients and offsets moved and the static coefficients' excesses held, the
// Jacobian by central differences kCoarseFactor times the fine steps (Layout::step). From a guess, the
// search's own first stage (pieces, starts fitted, every parameter) could end with the kinetic
// coefficients short of the truth and the static ones bent to fit; these steps, from the same guess,
// reach the chi-square's bowl around the truth. The statics are held because moving them here left the
// later stages in worse places (the docs).
//
// Wide (IdentifyOptions::wide_iterations; "Wide steps across the cells"): after the search, every
// coordinate and start moved, the differences kWideFactor times the fine steps: a secant over the
// chi-square's cells, where the fine steps' tangent sees one cell's floor.
//
// Line steps (the wide steps' second rung; "Line steps over the cells"): Gauss-Newton steps on secants
// wider still, each step's length the one of kLineLengths whose chi-square is lowest: along a step the
// chi-square leaves the bowl the cells' floors lie in wherever an arrest is held or slipped through, and
// Marquardt's damping (the wide steps') only shortens a step into such a band.
#include "internal.hpp"

#include "plate/tasks.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace plate::identify_detail {

namespace {

// Levenberg-Marquardt's damping: its first value (relative to each parameter's information), and the
// tries a step gets (damping x10 each) before the stage ends.
constexpr double kFirstDamping = 1e-3;
// The line steps' damping, relative as the wide steps' first (it only keeps a step finite along a direction
// the secant does not see).
constexpr double kLineDamping = kFirstDamping;
constexpr int kTries = 6;

double chi2_of(const Eigen::VectorXd& r) { return r.size() ? r.squaredNorm() : std::numeric_limits<double>::infinity(); }

// The damped normal equations' step -(A + damping diag A)^-1 g, A = J^T J, g = J^T r (a column of zeros: no step).
Eigen::VectorXd damped_step(const Eigen::MatrixXd& A, const Eigen::VectorXd& g, double damping) {
    Eigen::MatrixXd B = A;
    for (int k = 0; k < A.cols(); ++k) B(k, k) = A(k, k) > 0 ? A(k, k) * (1 + damping) : 1;
    return -B.ldlt().solve(g);
}

// x and q0 moved by `length` times dx (over c's columns): the named coordinates kept within [lo, hi], the
// tracks' starts moved with `starts` (c's columns must hold them).
void moved(const std::vector<double>& x, const std::vector<std::vector<double>>& q0, const Columns& c, const Eigen::VectorXd& dx,
           double length, const std::vector<double>& lo, const std::vector<double>& hi, bool starts, std::vector<double>& y,
           std::vector<std::vector<double>>& qy) {
    const int nf = static_cast<int>(c.free.size());
    y = x;
    for (int k = 0; k < nf; ++k) {
        const int j = c.free[static_cast<std::size_t>(k)];
        y[j] = std::min(std::max(x[j] + length * dx[k], lo[j]), hi[j]);
    }
    qy = q0;
    for (std::size_t t = 0, k = static_cast<std::size_t>(nf); starts && t < qy.size(); ++t)
        for (double& v : qy[t]) v += length * dx[static_cast<Eigen::Index>(k++)];
}

}   // namespace

Columns columns_of(const std::vector<TrackCost*>& costs, const std::vector<std::vector<double>>& q0, std::vector<int> free,
                   bool starts) {
    Columns c;
    const int nt = static_cast<int>(costs.size());
    c.count = static_cast<int>(free.size());
    c.free = std::move(free);
    c.starts = starts;
    c.rows.assign(static_cast<std::size_t>(nt) + 1, 0);
    for (int t = 0; t < nt; ++t) {
        c.rows[t + 1] = c.rows[t] + costs[t]->num_residuals();
        if (starts) c.count += static_cast<int>(q0[t].size());
    }
    return c;
}

std::vector<int> not_held(int n, const std::vector<int>& held) {
    std::vector<int> free;
    for (int j = 0; j < n; ++j)
        if (std::find(held.begin(), held.end(), j) == held.end()) free.push_back(j);
    return free;
}

Eigen::MatrixXd secant_jacobian(const std::vector<TrackCost*>& costs, const Layout& layout, const IdentifyOptions& o,
                                const std::vector<double>& x, const std::vector<std::vector<double>>& q0, const Columns& c,
                                const std::vector<double>& lo, const std::vector<double>& hi, double factor, long& simulations) {
    const std::vector<int>& free = c.free;
    const int nf = static_cast<int>(free.size()), nt = static_cast<int>(costs.size());
    std::vector<std::vector<double>> sides;
    std::vector<double> width(static_cast<std::size_t>(nf));
    for (int k = 0; k < nf; ++k) {
        const int j = free[static_cast<std::size_t>(k)];
        const double h = factor * layout.step(j);
        std::vector<double> up = x, down = x;
        up[j] = std::min(x[j] + h, hi[j]);
        down[j] = std::max(x[j] - h, lo[j]);
        width[static_cast<std::size_t>(k)] = up[j] - down[j];
        sides.push_back(up);
        sides.push_back(down);
    }
    const std::vector<Eigen::VectorXd> rm = stacked_residuals(costs, sides, {q0}, o.threads, simulations);
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(c.rows[static_cast<std::size_t>(nt)], c.count);
    for (int k = 0; k < nf; ++k) {
        const Eigen::VectorXd& up = rm[2 * static_cast<std::size_t>(k)];
        const Eigen::VectorXd& down = rm[2 * static_cast<std::size_t>(k) + 1];
        if (up.size() && down.size() && width[static_cast<std::size_t>(k)] > 0)
            J.col(k) = (up - down) / width[static_cast<std::size_t>(k)];
    }
    if (!c.starts) return J;
    // Each track's start columns: task i moves track t's coordinate k up (even i) or down.
    std::vector<int> first_column(static_cast<std::size_t>(nt) + 1, nf);
    for (int t = 0; t < nt; ++t) first_column[t + 1] = first_column[t] + static_cast<int>(q0[t].size());
    std::vector<std::pair<int, int>> which;   // (track, coordinate)
    for (int t = 0; t < nt; ++t)
        for (int k = 0; k < static_cast<int>(q0[t].size()); ++k) which.emplace_back(t, k);
    const int tasks = 2 * static_cast<int>(which.size());
    std::vector<Eigen::VectorXd> side(static_cast<std::size_t>(tasks));
    std::vector<char> ok(static_cast<std::size_t>(tasks), 0);
    thread_tasks(std::max(1, std::min(o.threads, tasks)))(
        tasks,
        [&](int i) {
            const auto [t, k] = which[static_cast<std::size_t>(i / 2)];
            std::vector<double> q = q0[t];
            q[k] += (i % 2 ? -1 : 1) * factor * start_step(k);
            side[static_cast<std::size_t>(i)].resize(costs[t]->num_residuals());
            ok[static_cast<std::size_t>(i)] = costs[t]->residuals(x.data(), q.data(), side[static_cast<std::size_t>(i)].data());
            return std::string();
        },
        [](int, const std::string&) {});
    simulations += tasks;
    for (std::size_t w = 0; w < which.size(); ++w) {
        const auto [t, k] = which[w];
        if (!ok[2 * w] || !ok[2 * w + 1]) continue;
        const double h = factor * start_step(k);
        J.block(c.rows[t], first_column[t] + k, side[2 * w].size(), 1) = (side[2 * w] - side[2 * w + 1]) / (2 * h);
    }
    return J;
}

CoarseResult coarse_steps(const std::vector<TrackCost*>& costs, const Layout& layout, const IdentifyOptions& o,
                          std::vector<double>& x, std::vector<std::vector<double>>& q0, const std::vector<int>& held,
                          const std::vector<double>& lo, const std::vector<double>& hi, double seconds, int iterations,
                          double factor, bool wide) {
    using Clock = std::chrono::steady_clock;
    const auto t0 = Clock::now();
    const int n = static_cast<int>(x.size());
    std::vector<int> free;
    for (const int j : not_held(n, held))
        if (wide || layout.p[j].kind != Param::Static) free.push_back(j);
    const Columns c = columns_of(costs, q0, std::move(free), wide);
    CoarseResult res;
    const auto out_of_time = [&] { return std::chrono::duration<double>(Clock::now() - t0).count() >= seconds; };
    const auto done = [&] {
        res.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
        return res;
    };
    Eigen::VectorXd r = stacked_residuals(costs, {x}, {q0}, o.threads, res.simulations)[0];
    res.chi2_before = res.chi2_after = chi2_of(r);
    if (!std::isfinite(res.chi2_before) || c.count == 0) return done();
    double damping = kFirstDamping;
    for (int it = 0; it < iterations && !out_of_time(); ++it) {
        const Eigen::MatrixXd J = secant_jacobian(costs, layout, o, x, q0, c, lo, hi, factor, res.simulations);
        const Eigen::MatrixXd A = J.transpose() * J;
        const Eigen::VectorXd g = J.transpose() * r;
        bool stepped = false;
        for (int tries = 0; tries < kTries && !stepped && !out_of_time(); ++tries) {
            std::vector<double> y;
            std::vector<std::vector<double>> qy;
            moved(x, q0, c, damped_step(A, g, damping), 1.0, lo, hi, wide, y, qy);
            const Eigen::VectorXd ry = stacked_residuals(costs, {y}, {qy}, o.threads, res.simulations)[0];
            if (chi2_of(ry) < chi2_of(r)) {
                x = y;
                q0 = qy;
                r = ry;
                stepped = true;
                damping = std::max(damping / 10, 1e-6);
            } else {
                damping *= 10;
            }
        }
        if (!stepped) break;
        ++res.iterations;
    }
    res.chi2_after = chi2_of(r);
    return done();
}

CoarseResult line_steps(const std::vector<TrackCost*>& costs, const Layout& layout, const IdentifyOptions& o,
                        std::vector<double>& x, std::vector<std::vector<double>>& q0, const std::vector<int>& held,
                        const std::vector<double>& lo, const std::vector<double>& hi, double seconds, int iterations) {
    using Clock = std::chrono::steady_clock;
    const auto t0 = Clock::now();
    const Columns c = columns_of(costs, q0, not_held(static_cast<int>(x.size()), held), true);
    CoarseResult res;
    const auto out_of_time = [&] { return std::chrono::duration<double>(Clock::now() - t0).count() >= seconds; };
    Eigen::VectorXd r = stacked_residuals(costs, {x}, {q0}, o.threads, res.simulations)[0];
    res.chi2_before = chi2_of(r);
    for (const double factor : kLineFactors) {
        for (int it = 0; it < iterations && std::isfinite(chi2_of(r)) && !out_of_time(); ++it) {
            const Eigen::MatrixXd J = secant_jacobian(costs, layout, o, x, q0, c, lo, hi, factor, res.simulations);
            const Eigen::VectorXd dx = damped_step(J.transpose() * J, J.transpose() * r, kLineDamping);
            if (!dx.allFinite()) break;
            // Every length's point as one set of tasks; the lowest kept where it lowers the chi-square.
            std::vector<std::vector<double>> points(std::size(kLineLengths));
            std::vector<std::vector<std::vector<double>>> starts(std::size(kLineLengths));
            for (std::size_t k = 0; k < std::size(kLineLengths); ++k)
                moved(x, q0, c, dx, kLineLengths[k], lo, hi, true, points[k], starts[k]);
            const std::vector<Eigen::VectorXd> along = stacked_residuals(costs, points, starts, o.threads, res.simulations);
            int best = -1;
            for (int k = 0; k < static_cast<int>(along.size()); ++k)
                if (chi2_of(along[k]) < (best < 0 ? chi2_of(r) : chi2_of(along[best]))) best = k;
            if (best < 0) break;
            x = points[best];
            q0 = starts[best];
            r = along[best];
            ++res.iterations;
        }
    }
    res.chi2_after = chi2_of(r);
    res.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return res;
}

}   // namespace plate::identify_detail
