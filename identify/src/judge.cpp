// What the fit can say at its optimum: the named parameters' covariance with the tracks' starts
// eliminated (Schur complement of the Gauss-Newton information J^T J; the residuals are in noise
// sds, so no scale is estimated), the combinations the tracks cannot place within the physical
// ranges, and the 95 % intervals of the rest.
#include "internal.hpp"

#include <cmath>
#include <limits>

namespace plate::identify_detail {

// A direction of the range-scaled parameters is not identifiable when its 95 % half-width exceeds
// the whole range (the tracks cannot place it anywhere narrower than the bounds already do); a
// parameter belongs to such a direction when its weight in it exceeds kLoading (its share of the
// direction's variance above 1 %).
constexpr double kZ95 = 1.959963984540054, kLoading = 0.1;

Eigen::MatrixXd scaled_information(const Layout& layout, const IdentifyOptions& o, const Eigen::MatrixXd& J, int starts_size) {
    const int n = layout.size();
    const Eigen::MatrixXd F = J.transpose() * J;
    Eigen::MatrixXd info = F.topLeftCorner(n, n);
    if (starts_size > 0) {
        const Eigen::MatrixXd Fsn = F.topRightCorner(n, starts_size);
        const Eigen::MatrixXd Fnn = F.bottomRightCorner(starts_size, starts_size);
        info -= Fsn * Fnn.completeOrthogonalDecomposition().solve(Fsn.transpose());
    }
    Eigen::VectorXd range(n);
    for (int j = 0; j < n; ++j) range[j] = layout.range(j, o);
    const Eigen::MatrixXd scaled = range.asDiagonal() * info * range.asDiagonal();
    return 0.5 * (scaled + scaled.transpose());
}

void judge(const Layout& layout, const IdentifyOptions& o, const std::vector<double>& x, const Eigen::MatrixXd& J,
           int starts_size, IdentifySummary& s) {
    const int n = layout.size();
    const double nan = std::numeric_limits<double>::quiet_NaN();
    Eigen::VectorXd range(n);
    for (int j = 0; j < n; ++j) range[j] = layout.range(j, o);
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(scaled_information(layout, o, J, starts_size));
    Eigen::MatrixXd pinv = Eigen::MatrixXd::Zero(n, n);
    std::vector<bool> internal_ok(n, true);
    for (int i = 0; i < n; ++i) {
        const double lambda = eig.eigenvalues()[i];
        const Eigen::VectorXd v = eig.eigenvectors().col(i);
        const double half = lambda > 0 ? kZ95 / std::sqrt(lambda) : std::numeric_limits<double>::infinity();
        if (half <= 1) {
            pinv += v * v.transpose() / lambda;
            continue;
        }
        Unidentifiable u;
        u.half_width = half;
        for (int j = 0; j < n; ++j) {
            if (std::abs(v[j]) > kLoading) internal_ok[j] = false;
            if (std::abs(v[j]) > 1e-3) u.combination.emplace_back(layout.p[j].name, v[j]);
        }
        s.unidentifiable.push_back(u);
    }
    const Eigen::MatrixXd cov_internal = range.asDiagonal() * pinv * range.asDiagonal();
    // The named values are linear in the internal coordinates wherever no two kinetic coefficients
    // tie for a shared static's base: A by central differences is exact there.
    const std::vector<double> v0 = layout.natural(x);
    Eigen::MatrixXd A(n, n);
    for (int k = 0; k < n; ++k) {
        std::vector<double> xp = x, xm = x;
        xp[k] += 1e-6;
        xm[k] -= 1e-6;
        const std::vector<double> vp = layout.natural(xp), vm = layout.natural(xm);
        for (int j = 0; j < n; ++j) A(j, k) = (vp[j] - vm[j]) / 2e-6;
    }
    s.covariance = A * cov_internal * A.transpose();
    s.params.clear();
    for (int j = 0; j < n; ++j) {
        FittedParameter p;
        p.name = layout.p[j].name;
        p.unit = layout.unit(j);
        p.estimate = v0[j];
        for (int k = 0; k < n; ++k)
            if (std::abs(A(j, k)) > 1e-9 && !internal_ok[k]) p.identifiable = false;
        p.at_bound = x[j] <= layout.lower(j, o) + 1e-9 || x[j] >= layout.upper(j, o) - 1e-9;
        p.sd = p.identifiable ? std::sqrt(std::max(s.covariance(j, j), 0.0)) : nan;
        p.lo = p.estimate - kZ95 * p.sd;
        p.hi = p.estimate + kZ95 * p.sd;
        s.params.push_back(p);
    }
    for (int j = 0; j < n; ++j)
        if (!s.params[j].identifiable) {
            s.covariance.row(j).setConstant(nan);
            s.covariance.col(j).setConstant(nan);
        }
}

}   // namespace plate::identify_detail
