// The spread of the estimate over the chi-square's cells near the fit. Under static friction the
// chi-square is piecewise smooth on cells smaller than the parameters' sds (an arrest held or slipped
// through moves every later frame); the search ends in one cell, whose curvature is the linearised
// covariance. Which cell the noise makes the lowest is a second, larger spread: it is found here from the
// cells' minima about the fit (docs/decisions/identification.md, "The spread over the chi-square's cells").
#include "internal.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace plate::identify_detail {

std::vector<Eigen::VectorXd> cell_moves(const Layout& layout, const IdentifyOptions& o, const std::vector<double>& x,
                                        const Eigen::MatrixXd& J, const Eigen::MatrixXd& cov_internal) {
    const int n = layout.size(), ns = static_cast<int>(J.cols()) - n, samples = o.cell_samples;
    const Eigen::MatrixXd regress = start_regression(J.transpose() * J, n);
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(0.5 * (cov_internal + cov_internal.transpose()));
    const Eigen::MatrixXd root = eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
    std::mt19937_64 gen(o.seed ^ 0x63656c6cULL);
    std::normal_distribution<double> normal;
    std::vector<Eigen::VectorXd> moves(samples, Eigen::VectorXd::Zero(n + ns));
    for (int k = 0; k < samples; ++k) {
        Eigen::VectorXd z(n);
        for (int j = 0; j < n; ++j) z[j] = normal(gen);
        Eigen::VectorXd& v = moves[k];
        v.head(n) = (2 * k < samples ? 1.0 : 2.0) * root * z;
        for (int j = 0; j < n; ++j) v[j] = std::clamp(x[j] + v[j], layout.lower(j, o), layout.upper(j, o)) - x[j];
        v.tail(ns) = regress * v.head(n);
    }
    return moves;
}

Eigen::MatrixXd cell_mixture(const Eigen::MatrixXd& J, const Eigen::VectorXd& r0, const Eigen::MatrixXd& cov_internal,
                             const std::vector<double>& lower, const std::vector<double>& upper,
                             const std::vector<Eigen::VectorXd>& moves, const std::vector<Eigen::VectorXd>& r) {
    const int n = static_cast<int>(cov_internal.rows()), ns = static_cast<int>(J.cols()) - n;
    const Eigen::MatrixXd F = J.transpose() * J;
    const Eigen::MatrixXd regress = start_regression(F, n);
    const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> Fqq(
        ns > 0 ? Eigen::MatrixXd(F.bottomRightCorner(ns, ns)) : Eigen::MatrixXd::Identity(1, 1));   // (unused without starts)
    const Eigen::MatrixXd Jx = J.leftCols(n), Jq = J.rightCols(ns);
    // The linear model's chi-square from residuals u, the starts at their best: |u|^2 - h^T F_qq^+ h, h = J_q^T u.
    const auto over_starts = [&](const Eigen::VectorXd& u) {
        if (ns == 0) return u.squaredNorm();
        const Eigen::VectorXd h = Jq.transpose() * u;
        return u.squaredNorm() - h.dot(Fqq.solve(h));
    };
    // Each draw's cell minimum: the shift from the fit -- the named coordinates', the starts eliminated,
    // along the identifiable directions only: -cov_internal (g_x + regress^T g_q), g = J^T d for the
    // residuals' departure d from the linear model, kept within the bounds -- and the linear model's
    // chi-square there, through the draw's residuals; the fit's own by the same formula (no move, no shift).
    std::vector<Eigen::VectorXd> shift;
    std::vector<double> minimum;
    for (std::size_t k = 0; k < moves.size(); ++k) {
        if (r[k].size() == 0) continue;
        const Eigen::VectorXd g = J.transpose() * (r[k] - r0 - J * moves[k]);
        const Eigen::VectorXd reduced = g.head(n) + regress.transpose() * g.tail(ns);
        Eigen::VectorXd sh = -cov_internal * reduced;
        for (int j = 0; j < n; ++j) sh[j] = std::clamp(sh[j], lower[j], upper[j]);
        const double m = over_starts(r[k] + Jx * (sh - moves[k].head(n)) - Jq * moves[k].tail(ns));
        if (!std::isfinite(m) || !sh.allFinite()) continue;
        shift.push_back(sh);
        minimum.push_back(m);
    }
    // The mixture: the fit (no shift) and the minima, each weighted by its likelihood exp(-chi2 / 2).
    const double chi2 = over_starts(r0);
    double lowest = chi2;
    for (const double m : minimum) lowest = std::min(lowest, m);
    double total = std::exp(-0.5 * (chi2 - lowest));
    Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(n, n);
    for (std::size_t k = 0; k < shift.size(); ++k) {
        const double w = std::exp(-0.5 * (minimum[k] - lowest));
        total += w;
        cov += w * shift[k] * shift[k].transpose();
    }
    return cov / total;
}

Eigen::MatrixXd cell_spread(const Layout& layout, const IdentifyOptions& o, const std::vector<TrackCost*>& costs,
                            const std::vector<double>& x, const std::vector<std::vector<double>>& q0, const Eigen::MatrixXd& J,
                            const Eigen::VectorXd& r0, const Eigen::MatrixXd& cov_internal) {
    const int n = layout.size(), nt = static_cast<int>(costs.size()), ns = static_cast<int>(J.cols()) - n;
    const int d = nt > 0 ? ns / nt : 0;
    if (o.cell_samples <= 0 || n == 0) return Eigen::MatrixXd::Zero(n, n);
    const std::vector<Eigen::VectorXd> moves = cell_moves(layout, o, x, J, cov_internal);
    // Each draw's point and starts; its residuals empty where a simulation stopped (cell_mixture leaves it out).
    std::vector<std::vector<double>> points(moves.size(), x);
    std::vector<std::vector<std::vector<double>>> starts(moves.size(), q0);
    for (std::size_t k = 0; k < moves.size(); ++k) {
        for (int j = 0; j < n; ++j) points[k][j] += moves[k][j];
        for (int t = 0; t < nt; ++t)
            for (int j = 0; j < d; ++j) starts[k][t][j] += moves[k][n + d * t + j];
    }
    long simulations = 0;
    const std::vector<Eigen::VectorXd> r = stacked_residuals(costs, points, starts, o.threads, simulations);
    std::vector<double> lower(n), upper(n);   // (the shifts' bounds: the fit's coordinates within theirs)
    for (int j = 0; j < n; ++j) {
        lower[j] = layout.lower(j, o) - x[j];
        upper[j] = layout.upper(j, o) - x[j];
    }
    return cell_mixture(J, r0, cov_internal, lower, upper, moves, r);
}

std::vector<double> envelope_sds(const Layout& layout, const IdentifyOptions& o, const std::vector<TrackCost*>& costs,
                                 const std::vector<double>& x, const std::vector<std::vector<double>>& q0,
                                 const std::vector<int>& held, const std::vector<double>& lo, const std::vector<double>& hi,
                                 long& simulations) {
    const int n = layout.size();
    std::vector<double> sd(static_cast<std::size_t>(n), 0.0);
    const Columns c = columns_of(costs, q0, not_held(n, held), true);
    const int nf = static_cast<int>(c.free.size()), starts_size = c.count - nf;
    const Eigen::MatrixXd A = natural_jacobian(layout, x);
    for (const double factor : kEnvelopeFactors) {
        const Eigen::MatrixXd Jf = secant_jacobian(costs, layout, o, x, q0, c, lo, hi, factor, simulations);
        // (the named coordinates' columns in their places, a held one's zero, then the starts')
        Eigen::MatrixXd J = Eigen::MatrixXd::Zero(Jf.rows(), n + starts_size);
        for (int k = 0; k < nf; ++k) J.col(c.free[k]) = Jf.col(k);
        J.rightCols(starts_size) = Jf.rightCols(starts_size);
        const Eigen::MatrixXd cov = A * identifiable_covariance(layout, o, J, starts_size, nullptr) * A.transpose();
        for (int j = 0; j < n; ++j)
            if (std::isfinite(cov(j, j))) sd[j] = std::max(sd[j], std::sqrt(std::max(cov(j, j), 0.0)));
    }
    return sd;
}

}   // namespace plate::identify_detail
