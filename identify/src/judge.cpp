// What the fit can say at its optimum: the named parameters' covariance with the tracks' starts
// eliminated (Schur complement of the Gauss-Newton information J^T J; the residuals are in noise
// sds, so no scale is estimated), the combinations the tracks cannot place within the physical
// ranges, and the 95 % intervals of the rest.
#include "internal.hpp"

#include "plate/profile.hpp"
#include "plate/tasks.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace plate::identify_detail {

// A direction of the range-scaled parameters is not identifiable when its 95 % half-width exceeds
// the whole range (the tracks cannot place it anywhere narrower than the bounds already do); a
// parameter belongs to such a direction when its weight in it exceeds kLoading (its share of the
// direction's variance above 1 %).
constexpr double kLoading = 0.1;

Eigen::MatrixXd natural_jacobian(const Layout& layout, const std::vector<double>& x) {
    // The named values are linear in the internal coordinates wherever no two kinetic coefficients tie
    // for a shared static's base: central differences are exact there.
    const int n = layout.size();
    Eigen::MatrixXd A(n, n);
    for (int k = 0; k < n; ++k) {
        std::vector<double> xp = x, xm = x;
        xp[k] += 1e-6;
        xm[k] -= 1e-6;
        const std::vector<double> vp = layout.natural(xp), vm = layout.natural(xm);
        for (int j = 0; j < n; ++j) A(j, k) = (vp[j] - vm[j]) / 2e-6;
    }
    return A;
}

Eigen::MatrixXd start_regression(const Eigen::MatrixXd& F, int n) {
    const int ns = static_cast<int>(F.rows()) - n;
    if (ns == 0) return Eigen::MatrixXd(0, n);
    return -F.bottomRightCorner(ns, ns).completeOrthogonalDecomposition().solve(F.bottomLeftCorner(ns, n));
}

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

Eigen::MatrixXd identifiable_covariance(const Layout& layout, const IdentifyOptions& o, const Eigen::MatrixXd& J, int starts_size,
                                        std::vector<std::pair<double, Eigen::VectorXd>>* weak) {
    const int n = layout.size();
    Eigen::VectorXd range(n);
    for (int j = 0; j < n; ++j) range[j] = layout.range(j, o);
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(scaled_information(layout, o, J, starts_size));
    Eigen::MatrixXd pinv = Eigen::MatrixXd::Zero(n, n);
    for (int i = 0; i < n; ++i) {
        const double lambda = eig.eigenvalues()[i];
        const Eigen::VectorXd v = eig.eigenvectors().col(i);
        const double half = lambda > 0 ? kZ95 / std::sqrt(lambda) : std::numeric_limits<double>::infinity();
        if (half <= 1)
            pinv += v * v.transpose() / lambda;
        else if (weak)
            weak->emplace_back(half, v);
    }
    return range.asDiagonal() * pinv * range.asDiagonal();
}

Eigen::MatrixXd judge(const Layout& layout, const IdentifyOptions& o, const std::vector<double>& x, const Eigen::MatrixXd& J,
                      int starts_size, IdentifySummary& s) {
    const int n = layout.size();
    const double nan = std::numeric_limits<double>::quiet_NaN();
    std::vector<std::pair<double, Eigen::VectorXd>> weak;
    const Eigen::MatrixXd cov_internal = identifiable_covariance(layout, o, J, starts_size, &weak);
    std::vector<bool> internal_ok(n, true);
    for (const auto& [half, v] : weak) {
        Unidentifiable u;
        u.half_width = half;
        for (int j = 0; j < n; ++j) {
            if (std::abs(v[j]) > kLoading) internal_ok[j] = false;
            if (std::abs(v[j]) > 1e-3) u.combination.emplace_back(layout.p[j].name, v[j]);
        }
        s.unidentifiable.push_back(u);
    }
    const std::vector<double> v0 = layout.natural(x);
    const Eigen::MatrixXd A = natural_jacobian(layout, x);
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
        p.sd_cells = p.identifiable ? 0.0 : nan;
        p.sd_envelope = p.identifiable ? 0.0 : nan;
        p.lo = p.estimate - kZ95 * p.sd;
        p.hi = p.estimate + kZ95 * p.sd;
        s.params.push_back(p);
    }
    for (int j = 0; j < n; ++j)
        if (!s.params[j].identifiable) {
            s.covariance.row(j).setConstant(nan);
            s.covariance.col(j).setConstant(nan);
        }
    return cov_internal;
}

void add_cells(const Layout& layout, const std::vector<double>& x, const Eigen::MatrixXd& cov_cells, IdentifySummary& s) {
    const int n = layout.size();
    const Eigen::MatrixXd A = natural_jacobian(layout, x);
    const Eigen::MatrixXd cells = A * cov_cells * A.transpose();
    for (int j = 0; j < n; ++j) {
        FittedParameter& p = s.params[j];
        if (!p.identifiable) continue;
        for (int k = 0; k < n; ++k)
            if (s.params[k].identifiable) s.covariance(j, k) += cells(j, k);
        p.sd_cells = std::sqrt(std::max(cells(j, j), 0.0));
        p.sd = std::sqrt(std::max(s.covariance(j, j), 0.0));
        p.lo = p.estimate - kZ95 * p.sd;
        p.hi = p.estimate + kZ95 * p.sd;
    }
}

void add_envelope(const std::vector<double>& sd_envelope, IdentifySummary& s) {
    const int n = static_cast<int>(s.params.size());
    Eigen::VectorXd widen = Eigen::VectorXd::Ones(n), sd(n);
    for (int j = 0; j < n; ++j) {
        const FittedParameter& p = s.params[j];
        sd[j] = std::hypot(std::max(within_cell_sd(p), sd_envelope[j]), p.sd_cells);
        if (p.identifiable && p.sd > 0 && sd[j] > p.sd) widen[j] = sd[j] / p.sd;
    }
    for (int j = 0; j < n; ++j) {
        FittedParameter& p = s.params[j];
        if (!p.identifiable || widen[j] == 1) continue;
        for (int k = 0; k < n; ++k)
            if (s.params[k].identifiable) {
                s.covariance(j, k) *= widen[j];
                s.covariance(k, j) *= widen[j];
            }
        const double within = within_cell_sd(p);
        p.sd = sd[j];
        p.sd_envelope = std::sqrt(std::max(sd_envelope[j] * sd_envelope[j] - within * within, 0.0));
        p.lo = p.estimate - kZ95 * p.sd;
        p.hi = p.estimate + kZ95 * p.sd;
    }
}

void check_linearity(const Layout& layout, const IdentifyOptions& o, const std::vector<TrackCost*>& costs,
                     const std::vector<double>& x, const std::vector<std::vector<double>>& q0, const Eigen::MatrixXd& J,
                     const Eigen::MatrixXd& cov_internal, IdentifySummary& s, PathEnd& better) {
    better = PathEnd{};
    const int n = layout.size(), nt = static_cast<int>(costs.size()), ns = static_cast<int>(J.cols()) - n;
    const int d = nt > 0 ? ns / nt : 0;
    const Eigen::MatrixXd F = J.transpose() * J;
    const Eigen::MatrixXd regress = start_regression(F, n);
    const Eigen::MatrixXd A = natural_jacobian(layout, x);
    // Each identifiable parameter's path: per linearised sd of it, the internal coordinates move by
    // C a^T / sqrt(a C a^T) (a its row of A), which the quadratic model climbs as the square.
    std::vector<int> checked;
    std::vector<Eigen::VectorXd> step;   // per checked parameter, over the named coordinates then the starts
    for (int j = 0; j < n; ++j) {
        FittedParameter& p = s.params[j];
        const double var = A.row(j) * cov_internal * A.row(j).transpose();
        if (!p.identifiable || !(var > 0)) continue;
        Eigen::VectorXd v(n + ns);
        v.head(n) = cov_internal * A.row(j).transpose() / std::sqrt(var);
        v.tail(ns) = regress * v.head(n);
        bool inside = true;
        for (int k = 0; k < n; ++k)
            for (const double sign : {-1.0, 1.0}) {
                const double xe = x[k] + sign * kZ95 * v[k];
                inside = inside && xe >= layout.lower(k, o) && xe <= layout.upper(k, o);
            }
        if (!inside) continue;
        checked.push_back(j);
        step.push_back(v);
    }
    // An end of a path: the named coordinates and track t's start.
    const auto end_point = [&](const Eigen::VectorXd& v, int end, std::vector<double>& xe, std::vector<double>& qe, int t) {
        const double sign = end == 0 ? -kZ95 : kZ95;
        for (int k = 0; k < n; ++k) xe[k] = x[k] + sign * v[k];
        for (int k = 0; k < d; ++k) qe[k] = q0[t][k] + sign * v[n + d * t + k];
    };
    // Every (parameter, end, track) prediction as a task; a stopped simulation gives NaN.
    const int tasks = static_cast<int>(checked.size()) * 2 * nt;
    std::vector<double> chi2(tasks, 0.0);
    thread_tasks(std::max(1, std::min(o.threads, std::max(tasks, 1))))(
        tasks,
        [&](int i) {
            const int c = i / (2 * nt), end = (i / nt) % 2, t = i % nt;
            std::vector<double> xe(n), qe(d);
            end_point(step[c], end, xe, qe, t);
            std::vector<double> r(costs[t]->num_residuals());
            if (!costs[t]->residuals(xe.data(), qe.data(), r.data())) {
                chi2[i] = std::numeric_limits<double>::quiet_NaN();
                return std::string();
            }
            for (double ri : r) chi2[i] += ri * ri;
            return std::string();
        },
        [](int, const std::string&) {});
    // A quadratic profile crossing within a fifth of the half-width of the ends (ProfileOptions' agreement).
    const double low = kProfileThreshold95 / (1.2 * 1.2), high = kProfileThreshold95 / (0.8 * 0.8);
    for (std::size_t c = 0; c < checked.size(); ++c) {
        FittedParameter& p = s.params[checked[c]];
        double ends[2] = {0, 0};
        for (int end = 0; end < 2; ++end)
            for (int t = 0; t < nt; ++t) ends[end] += chi2[(c * 2 + end) * nt + t];
        if (!std::isfinite(ends[0]) || !std::isfinite(ends[1])) continue;
        for (int end = 0; end < 2; ++end) {
            if (!(ends[end] < better.chi2)) continue;
            better.chi2 = ends[end];
            better.x.assign(n, 0.0);
            better.q0.assign(nt, std::vector<double>(d));
            for (int t = 0; t < nt; ++t) end_point(step[c], end, better.x, better.q0[t], t);
        }
        p.dchi2_lo = ends[0] - s.chi2;
        p.dchi2_hi = ends[1] - s.chi2;
        const double lo = std::min(p.dchi2_lo, p.dchi2_hi), hi = std::max(p.dchi2_lo, p.dchi2_hi);
        p.linearity = lo < low ? Linearity::TooNarrow : hi > high ? Linearity::Unconfirmed : Linearity::Holds;
    }
}

}   // namespace plate::identify_detail

namespace plate {

double within_cell_sd(const FittedParameter& p) {
    return std::sqrt(std::max(p.sd * p.sd - p.sd_cells * p.sd_cells - p.sd_envelope * p.sd_envelope, 0.0));
}

const char* to_string(Linearity l) {
    switch (l) {
        case Linearity::Holds:
            return "holds";
        case Linearity::TooNarrow:
            return "too narrow";
        case Linearity::Unconfirmed:
            return "unconfirmed";
        case Linearity::NotChecked:
            break;
    }
    return "not checked";
}

}   // namespace plate
