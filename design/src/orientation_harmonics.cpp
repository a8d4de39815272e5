// Orientation harmonics (design.hpp): theta'(theta) at a position as a Fourier series.
#include "internal.hpp"

namespace plate {

using namespace design_detail;

// --- orientation harmonics ------------------------------------------------------------------------

double OrientationHarmonics::rest() const {
    double r = amplitude.empty() ? 0.0 : amplitude[0];
    for (std::size_t k = 2; k < amplitude.size(); ++k) r += amplitude[k];
    return r;
}

double OrientationHarmonics::slope_bound() const {
    double r = 0;
    for (std::size_t k = 2; k < amplitude.size(); ++k) r += k * amplitude[k];
    return r;
}

bool OrientationHarmonics::one_stable() const {
    return defined && first() * first() > rest() * rest() + slope_bound() * slope_bound();
}

OrientationHarmonics harmonics_of(const std::vector<double>& w) {
    const int n = static_cast<int>(w.size());
    if (n < 4) throw std::invalid_argument("orientation harmonics: a ring of at least 4 orientations");
    OrientationHarmonics h;
    h.defined = true;
    h.amplitude.resize(n / 2 + 1);
    for (int m = 0; m <= n / 2; ++m) {   // c_m = (1/n) sum_k w_k e^{-i 2 pi m k / n}; B_m = 2 |c_m| (|c_m| at 0 and n/2)
        std::complex<double> c = 0;
        for (int k = 0; k < n; ++k) c += w[k] * std::polar(1.0, -2 * kPi * m * k / n);
        c /= n;
        if (m == 0) h.mean = c.real();
        h.amplitude[m] = (m == 0 || 2 * m == n ? 1.0 : 2.0) * std::abs(c);
    }
    return h;
}

OrientationHarmonics orientation_harmonics(const Scene& scene, const Vec2& s, const LimitCycleOptions& opt, int n) {
    if (n < 4) throw std::invalid_argument("orientation harmonics: a ring of at least 4 orientations");
    std::vector<double> w(n);
    Vec3 warm = Vec3::Zero();
    for (int k = 0; k < n; ++k) {
        const LimitCycleSummary lc = limit_cycle(scene, Vec3(s.x(), s.y(), 2 * kPi * k / n), opt, warm);
        if (!lc.converged) return {};
        w[k] = lc.twist[2];
        warm = lc.qd_start;
    }
    return harmonics_of(w);
}


}   // namespace plate
