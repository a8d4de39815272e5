// The search's coarse first steps (IdentifyOptions::coarse_iterations; docs/decisions/identification.md,
// "Coarse steps first"): Levenberg-Marquardt on the whole tracks, every track's start held at its first
// frame, the kinetic coefficients and offsets moved and the static coefficients' excesses held, the
// Jacobian by central differences kCoarseFactor times the fine steps (Layout::step). From a guess, the
// search's own first stage (pieces, starts fitted, every parameter) could end with the kinetic
// coefficients short of the truth and the static ones bent to fit; these steps, from the same guess,
// reach the chi-square's bowl around the truth. The statics are held because moving them here left the
// later stages in worse places (the docs).
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
// tries a step gets (damping x10 each) before the coarse stage ends.
constexpr double kFirstDamping = 1e-3;
constexpr int kTries = 6;

double chi2_of(const Eigen::VectorXd& r) { return r.size() ? r.squaredNorm() : std::numeric_limits<double>::infinity(); }

}   // namespace

CoarseResult coarse_steps(const std::vector<TrackCost*>& costs, const Layout& layout, const IdentifyOptions& o,
                          std::vector<double>& x, const std::vector<std::vector<double>>& q0, const std::vector<int>& held,
                          const std::vector<double>& lo, const std::vector<double>& hi, double seconds, double factor) {
    using Clock = std::chrono::steady_clock;
    const auto t0 = Clock::now();
    const int n = static_cast<int>(x.size());
    std::vector<int> free;
    for (int j = 0; j < n; ++j)
        if (std::find(held.begin(), held.end(), j) == held.end() && layout.p[j].kind != Param::Static) free.push_back(j);
    const int nf = static_cast<int>(free.size());
    CoarseResult res;
    const auto out_of_time = [&] { return std::chrono::duration<double>(Clock::now() - t0).count() >= seconds; };
    const auto done = [&] {
        res.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
        return res;
    };
    Eigen::VectorXd r = stacked_residuals(costs, {x}, {q0}, o.threads, res.simulations)[0];
    res.chi2_before = res.chi2_after = chi2_of(r);
    if (!std::isfinite(res.chi2_before) || nf == 0) return done();
    double damping = kFirstDamping;
    for (int it = 0; it < o.coarse_iterations && !out_of_time(); ++it) {
        // The coarse Jacobian: each free coordinate moved both ways within its bounds.
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
        const std::vector<Eigen::VectorXd> rm = stacked_residuals(costs, moved, {q0}, o.threads, res.simulations);
        Eigen::MatrixXd J = Eigen::MatrixXd::Zero(r.size(), nf);
        for (int k = 0; k < nf; ++k) {   // (a side whose simulation stopped: the coordinate not moved this time)
            const Eigen::VectorXd& up = rm[2 * static_cast<std::size_t>(k)];
            const Eigen::VectorXd& down = rm[2 * static_cast<std::size_t>(k) + 1];
            if (up.size() && down.size() && width[static_cast<std::size_t>(k)] > 0)
                J.col(k) = (up - down) / width[static_cast<std::size_t>(k)];
        }
        const Eigen::MatrixXd A = J.transpose() * J;
        const Eigen::VectorXd g = J.transpose() * r;
        bool stepped = false;
        for (int tries = 0; tries < kTries && !stepped && !out_of_time(); ++tries) {
            Eigen::MatrixXd B = A;
            for (int k = 0; k < nf; ++k) B(k, k) = A(k, k) > 0 ? A(k, k) * (1 + damping) : 1;
            const Eigen::VectorXd dx = -B.ldlt().solve(g);
            std::vector<double> y = x;
            for (int k = 0; k < nf; ++k) {
                const int j = free[static_cast<std::size_t>(k)];
                y[j] = std::min(std::max(x[j] + dx[k], lo[j]), hi[j]);
            }
            const Eigen::VectorXd ry = stacked_residuals(costs, {y}, {q0}, o.threads, res.simulations)[0];
            if (chi2_of(ry) < chi2_of(r)) {
                x = y;
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

}   // namespace plate::identify_detail
