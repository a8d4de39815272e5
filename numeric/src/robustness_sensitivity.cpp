// First-order sensitivities of a fixed point to the uncertainty spec's parameters (robustness.hpp),
// and the two statistics the summary states them in.
#include "plate/robustness.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace plate {
namespace {

// The field's twist at q for the nominal with deviations p, warm-started from `warm` (not updated:
// every evaluation starts from the nominal fixed point's cycle).
Vec3 twist(const Scene& sc, const Vec3& q, const LimitCycleOptions& lo, const Vec3& warm) {
    Vec3 w = warm;
    return field_at(sc, q, lo, &w);
}

}   // namespace

void fixed_point_sensitivities(const Scene& nominal, const UncertaintySpec& spec, const Vec3& q_star,
                               const LimitCycleOptions& cycle, RobustnessSummary& out, const SensitivityOptions& so) {
    const auto t0 = std::chrono::steady_clock::now();
    const bool point = nominal.part.point;
    const int dim = point ? 2 : 3;
    // The derivatives need a field far less noisy than their differences: the refinement's accuracy
    // (FixedPointOptions), cycles to 1e-8 v_ref and steps to 1e-9.
    LimitCycleOptions lo = cycle;
    if (so.refine) {
        lo.tol = std::min(lo.tol, 1e-8);
        lo.integration.rtol = std::min(lo.integration.rtol, 1e-9);
    }
    const double rho = point ? 1 : nominal.part.rho();
    // Differences of 1e-4 m in position and 1e-4 / rho rad in theta: a hundredth of the field's
    // variation length (a centimetre) and a few hundred times the field's noise relative to them.
    const Vec3 hq(1e-4, 1e-4, 1e-4 / rho);
    Vec3 q = q_star, warm = Vec3::Zero();
    field_at(nominal, q, lo, &warm);
    auto jacobian = [&](const Vec3& at) {
        Eigen::Matrix3d J = Eigen::Matrix3d::Identity();
        for (int c = 0; c < dim; ++c) {
            Vec3 qp = at, qm = at;
            qp[c] += hq[c];
            qm[c] -= hq[c];
            J.col(c) = (twist(nominal, qp, lo, warm) - twist(nominal, qm, lo, warm)) / (2 * hq[c]);
        }
        if (point) J.row(2).setZero(), J(2, 2) = 1;   // theta is no coordinate of a point part
        return J;
    };
    // Two Newton steps put q* on the tighter field's zero (the grid's refinement stopped at 1e-6 v_ref).
    Eigen::Matrix3d J = jacobian(q);
    for (int it = 0; it < (so.refine ? 2 : 0); ++it) {
        Vec3 f = twist(nominal, q, lo, warm);
        if (point) f[2] = 0;
        q -= J.lu().solve(f);
        J = jacobian(q);
    }
    out.jacobian = J;
    const auto lu = J.lu();
    const std::vector<UncertainParameter> params = uncertain_parameters(nominal, spec);
    std::vector<double> zero(params.size(), 0.0);
    out.sensitivities.clear();
    out.predicted_covariance.setZero();
    for (std::size_t k = 0; k < params.size(); ++k) {
        Sensitivity s;
        s.parameter = params[k];
        const double sd = params[k].standard_deviation;
        if (sd > 0) {
            // A tenth of the parameter's spread: within the linear range the Monte Carlo compares.
            const double h = 0.1 * sd;
            std::vector<double> pp = zero, pm = zero;
            pp[k] = h;
            pm[k] = -h;
            Vec3 dxi =
                (twist(perturbed(nominal, spec, pp), q, lo, warm) - twist(perturbed(nominal, spec, pm), q, lo, warm)) / (2 * h);
            if (point) dxi[2] = 0;
            s.dq = -lu.solve(dxi);
            out.predicted_covariance += s.dq * s.dq.transpose() * sd * sd;
        }
        out.sensitivities.push_back(s);
    }
    const double xy = out.predicted_covariance(0, 0) + out.predicted_covariance(1, 1);
    for (auto& s : out.sensitivities) {
        const double sd = s.parameter.standard_deviation;
        s.variance_share = xy > 0 ? (s.dq[0] * s.dq[0] + s.dq[1] * s.dq[1]) * sd * sd / xy : 0;
    }
    out.predicted_radius95 = normal_radius(out.predicted_covariance.topLeftCorner<2, 2>());
    out.predicted_angle95 = point ? 0 : 1.959963984540054 * std::sqrt(out.predicted_covariance(2, 2));
    out.sensitivity_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

double normal_radius(const Eigen::Matrix2d& C, double level) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(C);
    const double s1 = std::sqrt(std::max(0.0, es.eigenvalues()[1])), s2 = std::sqrt(std::max(0.0, es.eigenvalues()[0]));
    if (s1 == 0) return 0;
    // P(|x| <= r) = int phi(z) P(|s2 z2| <= sqrt(r^2 - s1^2 z^2)) dz over |z| <= r / s1; with
    // z = (r / s1) sin u the integrand is smooth on [-pi/2, pi/2] (Simpson's rule, 400 panels).
    auto P = [&](double r) {
        const int n = 400;
        const double a = -kPi / 2, du = kPi / n;
        double sum = 0;
        for (int i = 0; i <= n; ++i) {
            const double u = a + i * du, z = r / s1 * std::sin(u), c = std::cos(u);
            const double inner = s2 > 0 ? std::erf(r * c / (std::sqrt(2.0) * s2)) : (c > 0 ? 1.0 : 0.0);
            const double f = std::exp(-z * z / 2) / std::sqrt(2 * kPi) * inner * r / s1 * c;
            sum += f * (i == 0 || i == n ? 1 : i % 2 ? 4 : 2);
        }
        return sum * du / 3;
    };
    double lo = 0, hi = std::sqrt((s1 * s1 + s2 * s2) / (1 - level));   // Chebyshev: P(hi) >= level
    for (int it = 0; it < 200 && hi - lo > 1e-15 * hi; ++it) {
        const double mid = (lo + hi) / 2;
        (P(mid) < level ? lo : hi) = mid;
    }
    return (lo + hi) / 2;
}

}   // namespace plate
