// The peaks of a plate motion's signals over the period (peaks.hpp): what actuators saturate on, what
// DesignOptions' limits bound and what identification's suggested motions keep within.
#include "plate/peaks.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <utility>

namespace plate {

// (peaks.hpp) The extrema of f are the zeros of f'(theta) = sum_{|k| <= M} i k F_k e^{i k theta}
// (F_{-k} = conj F_k): z^M f'(theta) is a polynomial of degree 2 M in z = e^{i theta}, whose roots are
// the companion matrix's eigenvalues. Each root's angle, polished by Newton steps on f', is a candidate;
// so are 16 (M + 1) equally spaced samples (a net under the roots); the peak is the largest |f| over the
// candidates. Every candidate is a real angle, so the result never exceeds the true peak, and it misses
// an extremum's value only by f'' dtheta^2 / 2 for a root's angle error dtheta (roundoff after the
// polish: measured 2.2e-16 relative on the tests' closed forms; a double root, ill-conditioned in angle at
// ~1e-8, still ~1e-16 in value).
double trig_peak(const std::vector<std::complex<double>>& F) {
    using cd = std::complex<double>;
    double scale = std::abs(F.empty() ? 0.0 : F[0].real());
    for (std::size_t k = 1; k < F.size(); ++k) scale += 2 * std::abs(F[k]);
    if (!(scale > 0)) return 0.0;
    // f's d-th derivative at theta
    const auto f = [&](double th, int d) {
        double v = d == 0 ? F[0].real() : 0.0;
        for (std::size_t k = 1; k < F.size(); ++k) {
            const double kk = static_cast<double>(k);
            const cd ik_d = d == 0 ? cd(1, 0) : d == 1 ? cd(0, kk) : cd(-kk * kk, 0);   // (i k)^d, d <= 2
            v += 2 * std::real(F[k] * ik_d * cd(std::cos(kk * th), std::sin(kk * th)));
        }
        return v;
    };
    // (harmonics below roundoff of the others left out of the polynomial: its leading coefficient stays
    // well away from zero; they still count in f at every candidate)
    int M = static_cast<int>(F.size()) - 1;
    while (M > 0 && std::abs(F[static_cast<std::size_t>(M)]) <= 1e-15 * scale) --M;
    std::vector<double> candidates;
    for (int k = 0; k < 16 * (M + 1); ++k) candidates.push_back(2 * kPi * k / (16 * (M + 1)));
    if (M > 0) {
        const int n = 2 * M;
        const auto coefficient = [&](int j) {   // of z^j in z^M f'
            const int k = j - M;
            const cd Fk = k >= 0 ? F[static_cast<std::size_t>(k)] : std::conj(F[static_cast<std::size_t>(-k)]);
            return cd(0, k) * Fk;
        };
        Eigen::MatrixXcd C = Eigen::MatrixXcd::Zero(n, n);
        for (int i = 1; i < n; ++i) C(i, i - 1) = 1;
        for (int i = 0; i < n; ++i) C(i, n - 1) = -coefficient(i) / coefficient(n);
        const Eigen::ComplexEigenSolver<Eigen::MatrixXcd> roots(C, false);
        for (int r = 0; r < n; ++r) {
            double th = std::arg(roots.eigenvalues()[r]);
            candidates.push_back(th);
            for (int it = 0; it < 3; ++it) {
                const double d2 = f(th, 2);
                if (d2 == 0) break;
                th -= f(th, 1) / d2;
                candidates.push_back(th);
            }
        }
    }
    double peak = 0;
    for (double th : candidates) peak = std::max(peak, std::abs(f(th, 0)));
    return peak;
}

// One axis' (or a sum of axes') signal as F_k: amp sin(k theta + phase) = 2 Re(-(i/2) amp e^{i phase} e^{i k theta}).
namespace {
std::vector<std::complex<double>> coefficients(const PlateMotion& u, int axis) {
    std::vector<std::complex<double>> F(1, 0.0);
    for (const Harmonic& h : u.harmonics) {
        if (static_cast<int>(h.axis) != axis || h.n < 1) continue;
        if (static_cast<int>(F.size()) <= h.n) F.resize(static_cast<std::size_t>(h.n) + 1, 0.0);
        F[static_cast<std::size_t>(h.n)] +=
            std::complex<double>(0, -0.5) * h.amp * std::complex<double>(std::cos(h.phase), std::sin(h.phase));
    }
    return F;
}
}   // namespace

// max_t |(f_1(t), ..., f_m(t))|: the peak of sum_j f_j^2, whose coefficients are the
// self-convolutions of each f_j's (two-sided, length 2 N + 1; the product has degree 2 N).
double norm_peak(const std::vector<std::vector<std::complex<double>>>& f) {
    std::size_t size = 1;
    for (const auto& A : f) size = std::max(size, A.size());
    const int N = static_cast<int>(size) - 1;
    const auto two_sided = [&](const std::vector<std::complex<double>>& A, int k) -> std::complex<double> {
        const int a = std::abs(k);
        if (a >= static_cast<int>(A.size())) return 0.0;
        return k >= 0 ? A[static_cast<std::size_t>(a)] : std::conj(A[static_cast<std::size_t>(a)]);
    };
    std::vector<std::complex<double>> G(static_cast<std::size_t>(2 * N) + 1, 0.0);
    for (int m = 0; m <= 2 * N; ++m)
        for (int k = m - N; k <= N; ++k) {
            std::complex<double> s = 0.0;
            for (const auto& A : f) s += two_sided(A, k) * two_sided(A, m - k);
            G[static_cast<std::size_t>(m)] += s;
        }
    return std::sqrt(trig_peak(G));
}

// (peaks.hpp) max_t |(u_x, u_y)|.
double horizontal_peak(const PlateMotion& u) { return norm_peak({coefficients(u, 0), coefficients(u, 1)}); }

// (peaks.hpp) A corner r = (x, y, 0) moves by d = p + phi x r = (p_x - y phi_z, p_y + x phi_z, p_z + y phi_x -
// x phi_y), and v likewise from p' and omega. In the coefficients F_n of u (theta = w t), integration in t
// divides F_n by i n w: the velocity's F_n / (i n w), the displacement's -F_n / (n w)^2, both zero-mean as
// PlateMotion::velocity and ::displacement.
CornerPeaks corner_peaks(const PlateMotion& u, const Vec2& half_size) {
    using Coeffs = std::vector<std::complex<double>>;
    const double w = u.omega();
    Coeffs V[6], D[6];
    for (int a = 0; a < 6; ++a) {
        V[a] = D[a] = coefficients(u, a);
        for (std::size_t n = 1; n < V[a].size(); ++n) {
            const double k = static_cast<double>(n) * w;
            V[a][n] /= std::complex<double>(0, k);
            D[a][n] /= -(k * k);
        }
    }
    // sum_j w_j L_j for (axis, w) terms
    const auto combine = [](const Coeffs* L, std::initializer_list<std::pair<int, double>> terms) {
        Coeffs r(1, 0.0);
        for (const auto& [a, wt] : terms) {
            r.resize(std::max(r.size(), L[a].size()), 0.0);
            for (std::size_t n = 0; n < L[a].size(); ++n) r[n] += wt * L[a][n];
        }
        return r;
    };
    const auto peak_at = [&](const Coeffs* L, double x, double y) {   // L: x, y, z, rx, ry, rz's coefficients
        return norm_peak(
            {combine(L, {{0, 1.0}, {5, -y}}), combine(L, {{1, 1.0}, {5, x}}), combine(L, {{2, 1.0}, {3, y}, {4, -x}})});
    };
    CornerPeaks p;
    for (double sx : {-1.0, 1.0})
        for (double sy : {-1.0, 1.0}) {
            const double x = sx * half_size.x(), y = sy * half_size.y();
            p.displacement = std::max(p.displacement, peak_at(D, x, y));
            p.velocity = std::max(p.velocity, peak_at(V, x, y));
        }
    return p;
}

Vec6 axis_peaks(const PlateMotion& u) {
    Vec6 p;
    for (int a = 0; a < 6; ++a) p[a] = trig_peak(coefficients(u, a));
    return p;
}

}   // namespace plate
