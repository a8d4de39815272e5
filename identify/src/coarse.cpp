// The search's coarse first steps and wide last ones (internal.hpp, coarse_steps).
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
// Line steps (the wide steps' later rungs; "Line steps over the cells"): Gauss-Newton steps on secants
// wider still, each step's length the one of kLineLengths whose chi-square is lowest: between the cells'
// floors and the bowl they lie in, the chi-square along a step jumps up and down by tens, and Marquardt's
// damping (the wide steps') only shortens a step into the next jump.
#include "internal.hpp"

#include "plate/tasks.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace plate::identify_detail {

namespace {

// Levenberg-Marquardt's damping: its first value (relative to each parameter's information), and the
// tries a step gets (damping x10 each) before the stage ends.
constexpr double kFirstDamping = 1e-3;
constexpr int kTries = 6;

double chi2_of(const Eigen::VectorXd& r) { return r.size() ? r.squaredNorm() : std::numeric_limits<double>::infinity(); }

}   // namespace

Eigen::MatrixXd secant_jacobian(const std::vector<TrackCost*>& costs, const Layout& layout, const IdentifyOptions& o,
                                const std::vector<double>& x, const std::vector<std::vector<double>>& q0,
                                const std::vector<int>& free, const std::vector<double>& lo, const std::vector<double>& hi,
                                double factor, bool starts, const std::vector<int>& rows, int columns, long& simulations) {
    const int nf = static_cast<int>(free.size()), nt = static_cast<int>(costs.size());
    std::vector<std::vector<double>> moved;
    std::vector<double> width(static_cast<std::size_t>(nf));
    for (int k = 0; k < nf; ++k) {
        const int j = free[static_cast<std::size_t>(k)];
        const double h = factor * layout.step(j);
        std::vector<double> up = x, down = x;
        up[j] = std::min(x[j] + h, hi[j]);
        down[j] = std::max(x[j] - h, lo[j]);
        width[static_cast<std::size_t>(k)] = up[j] - down[j];
        moved.push_back(up);
        moved.push_back(down);
    }
    const std::vector<Eigen::VectorXd> rm = stacked_residuals(costs, moved, {q0}, o.threads, simulations);
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(rows[static_cast<std::size_t>(nt)], columns);
    for (int k = 0; k < nf; ++k) {
        const Eigen::VectorXd& up = rm[2 * static_cast<std::size_t>(k)];
        const Eigen::VectorXd& down = rm[2 * static_cast<std::size_t>(k) + 1];
        if (up.size() && down.size() && width[static_cast<std::size_t>(k)] > 0)
            J.col(k) = (up - down) / width[static_cast<std::size_t>(k)];
    }
    if (!starts) return J;
    // Each track's start columns: task i moves track t's coordinate c up (even i) or down.
    std::vector<int> first_column(static_cast<std::size_t>(nt) + 1, nf);
    for (int t = 0; t < nt; ++t) first_column[t + 1] = first_column[t] + static_cast<int>(q0[t].size());
    std::vector<std::pair<int, int>> which;   // (track, coordinate)
    for (int t = 0; t < nt; ++t)
        for (int c = 0; c < static_cast<int>(q0[t].size()); ++c) which.emplace_back(t, c);
    const int tasks = 2 * static_cast<int>(which.size());
    std::vector<Eigen::VectorXd> side(static_cast<std::size_t>(tasks));
    std::vector<char> ok(static_cast<std::size_t>(tasks), 0);
    thread_tasks(std::max(1, std::min(o.threads, tasks)))(
        tasks,
        [&](int i) {
            const auto [t, c] = which[static_cast<std::size_t>(i / 2)];
            std::vector<double> q = q0[t];
            q[c] += (i % 2 ? -1 : 1) * factor * start_step(c);
            side[static_cast<std::size_t>(i)].resize(costs[t]->num_residuals());
            ok[static_cast<std::size_t>(i)] = costs[t]->residuals(x.data(), q.data(), side[static_cast<std::size_t>(i)].data());
            return std::string();
        },
        [](int, const std::string&) {});
    simulations += tasks;
    for (std::size_t w = 0; w < which.size(); ++w) {
        const auto [t, c] = which[w];
        if (!ok[2 * w] || !ok[2 * w + 1]) continue;
        const double h = factor * start_step(c);
        J.block(rows[t], first_column[t] + c, side[2 * w].size(), 1) = (side[2 * w] - side[2 * w + 1]) / (2 * h);
    }
    return J;
}

CoarseResult coarse_steps(const std::vector<TrackCost*>& costs, const Layout& layout, const IdentifyOptions& o,
                          std::vector<double>& x, std::vector<std::vector<double>>& q0, const std::vector<int>& held,
                          const std::vector<double>& lo, const std::vector<double>& hi, double seconds, int iterations,
                          double factor, bool wide) {
    using Clock = std::chrono::steady_clock;
    const auto t0 = Clock::now();
    const int n = static_cast<int>(x.size()), nt = static_cast<int>(costs.size());
    std::vector<int> free;
    for (int j = 0; j < n; ++j)
        if (std::find(held.begin(), held.end(), j) == held.end() && (wide || layout.p[j].kind != Param::Static))
            free.push_back(j);
    const int nf = static_cast<int>(free.size());
    std::vector<int> rows(static_cast<std::size_t>(nt) + 1, 0);
    int columns = nf;
    for (int t = 0; t < nt; ++t) {
        rows[t + 1] = rows[t] + costs[t]->num_residuals();
        if (wide) columns += static_cast<int>(q0[t].size());
    }
    CoarseResult res;
    const auto out_of_time = [&] { return std::chrono::duration<double>(Clock::now() - t0).count() >= seconds; };
    const auto done = [&] {
        res.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
        return res;
    };
    Eigen::VectorXd r = stacked_residuals(costs, {x}, {q0}, o.threads, res.simulations)[0];
    res.chi2_before = res.chi2_after = chi2_of(r);
    if (!std::isfinite(res.chi2_before) || columns == 0) return done();
    double damping = kFirstDamping;
    for (int it = 0; it < iterations && !out_of_time(); ++it) {
        const Eigen::MatrixXd J =
            secant_jacobian(costs, layout, o, x, q0, free, lo, hi, factor, wide, rows, columns, res.simulations);
        const Eigen::MatrixXd A = J.transpose() * J;
        const Eigen::VectorXd g = J.transpose() * r;
        bool stepped = false;
        for (int tries = 0; tries < kTries && !stepped && !out_of_time(); ++tries) {
            Eigen::MatrixXd B = A;
            for (int k = 0; k < columns; ++k) B(k, k) = A(k, k) > 0 ? A(k, k) * (1 + damping) : 1;
            const Eigen::VectorXd dx = -B.ldlt().solve(g);
            std::vector<double> y = x;
            for (int k = 0; k < nf; ++k) {
                const int j = free[static_cast<std::size_t>(k)];
                y[j] = std::min(std::max(x[j] + dx[k], lo[j]), hi[j]);
            }
            std::vector<std::vector<double>> qy = q0;
            for (int t = 0, k = nf; wide && t < nt; ++t)
                for (double& c : qy[t]) c += dx[k++];
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
                        const std::vector<double>& lo, const std::vector<double>& hi, double seconds, int iterations,
                        double factor) {
    using Clock = std::chrono::steady_clock;
    const auto t0 = Clock::now();
    const int n = static_cast<int>(x.size()), nt = static_cast<int>(costs.size());
    std::vector<int> free;
    for (int j = 0; j < n; ++j)
        if (std::find(held.begin(), held.end(), j) == held.end()) free.push_back(j);
    const int nf = static_cast<int>(free.size());
    std::vector<int> rows(static_cast<std::size_t>(nt) + 1, 0);
    int columns = nf;
    for (int t = 0; t < nt; ++t) {
        rows[t + 1] = rows[t] + costs[t]->num_residuals();
        columns += static_cast<int>(q0[t].size());
    }
    CoarseResult res;
    const auto out_of_time = [&] { return std::chrono::duration<double>(Clock::now() - t0).count() >= seconds; };
    Eigen::VectorXd r = stacked_residuals(costs, {x}, {q0}, o.threads, res.simulations)[0];
    res.chi2_before = res.chi2_after = chi2_of(r);
    for (int it = 0; it < iterations && std::isfinite(res.chi2_after) && !out_of_time(); ++it) {
        const Eigen::MatrixXd J =
            secant_jacobian(costs, layout, o, x, q0, free, lo, hi, factor, true, rows, columns, res.simulations);
        Eigen::MatrixXd A = J.transpose() * J;
        for (int k = 0; k < columns; ++k) A(k, k) = A(k, k) > 0 ? A(k, k) * (1 + kFirstDamping) : 1;
        const Eigen::VectorXd dx = -A.ldlt().solve(J.transpose() * r);
        if (!dx.allFinite()) break;
        // Every length's point at once; the lowest kept where it lowers the chi-square.
        std::vector<std::vector<double>> ys;
        std::vector<std::vector<std::vector<double>>> qs;
        for (const double length : kLineLengths) {
            std::vector<double> y = x;
            for (int k = 0; k < nf; ++k) {
                const int j = free[static_cast<std::size_t>(k)];
                y[j] = std::min(std::max(x[j] + length * dx[k], lo[j]), hi[j]);
            }
            std::vector<std::vector<double>> qy = q0;
            for (int t = 0, k = nf; t < nt; ++t)
                for (double& c : qy[t]) c += length * dx[k++];
            ys.push_back(std::move(y));
            qs.push_back(std::move(qy));
        }
        const std::vector<Eigen::VectorXd> rl = stacked_residuals(costs, ys, qs, o.threads, res.simulations);
        int best = -1;
        for (int k = 0; k < static_cast<int>(rl.size()); ++k)
            if (chi2_of(rl[k]) < (best < 0 ? chi2_of(r) : chi2_of(rl[best]))) best = k;
        if (best < 0) break;
        x = ys[best];
        q0 = qs[best];
        r = rl[best];
        ++res.iterations;
    }
    res.chi2_after = chi2_of(r);
    res.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return res;
}

}   // namespace plate::identify_detail
