// The exact symmetries and drifts of plate motions (design.hpp).
#include "internal.hpp"

namespace plate {

using namespace design_detail;

// --- exact symmetries ------------------------------------------------------------------------------

PlateMotion rotate_motion(const PlateMotion& u, double a) {
    PlateMotion r;
    r.T = u.T;
    const double c = std::cos(a), s = std::sin(a);
    for (const Harmonic& h : u.harmonics) {
        // (x, y) and (rx, ry) are vectors in the plane: e_x -> (c, s), e_y -> (-s, c).
        auto pair = [&](Axis ax, Axis ay, bool is_x) {
            r.harmonics.push_back({ax, h.n, h.amp * (is_x ? c : -s), h.phase});
            r.harmonics.push_back({ay, h.n, h.amp * (is_x ? s : c), h.phase});
        };
        switch (h.axis) {
            case Axis::x:
                pair(Axis::x, Axis::y, true);
                break;
            case Axis::y:
                pair(Axis::x, Axis::y, false);
                break;
            case Axis::rx:
                pair(Axis::rx, Axis::ry, true);
                break;
            case Axis::ry:
                pair(Axis::rx, Axis::ry, false);
                break;
            default:
                r.harmonics.push_back(h);
        }
    }
    return r;
}

PlateMotion shift_motion(const PlateMotion& u, const Vec2& D) {
    PlateMotion r = u;
    const Vec3 d(D.x(), D.y(), 0);
    for (const Harmonic& h : u.harmonics) {
        if (h.axis != Axis::rx && h.axis != Axis::ry && h.axis != Axis::rz) continue;
        Vec3 alpha = Vec3::Zero();
        alpha[static_cast<int>(h.axis) - 3] = h.amp;
        const Vec3 add = -alpha.cross(d);   // the same harmonic, on the linear axes
        for (int k = 0; k < 3; ++k)
            if (add[k] != 0) r.harmonics.push_back({static_cast<Axis>(k), h.n, add[k], h.phase});
    }
    return r;
}

double pair_basin_bound(const Vec2& D, double region) {
    // R = [-a, a]^2 and its image 2 D - R = [2 D - a, 2 D + a]^2 overlap over (2 a - 2 |D_i|) per axis.
    double overlap = 1;
    for (int i = 0; i < 2; ++i) overlap *= std::max(0.0, 2 * region - 2 * std::abs(D[i]));
    return 1 - overlap / (2 * 4 * region * region);
}

}   // namespace plate

namespace plate::design_detail {

// sum_n Im(A_a,n conj(A_b,n)) / (2 (n w)^3) over the phasors amp e^{i phase} of each (axis, n): the
// second-order drift about the third axis of (a, b) in the cross product's cyclic order.
double drift_sum(const PlateMotion& u, Axis a, Axis b) {
    const auto ph = phasors(u);
    double r = 0;
    for (const auto& [k, za] : ph) {
        if (k.first != static_cast<int>(a)) continue;
        const auto zb = ph.find({static_cast<int>(b), k.second});
        if (zb == ph.end()) continue;
        const double nw = k.second * 2 * kPi / u.T;
        r += std::imag(za * std::conj(zb->second)) / (2 * nw * nw * nw);
    }
    return r;
}

}   // namespace plate::design_detail

namespace plate {

using namespace design_detail;

double coning_rate(const PlateMotion& u) { return drift_sum(u, Axis::rx, Axis::ry); }

Vec2 tilt_drift_rate(const PlateMotion& u) { return Vec2(drift_sum(u, Axis::ry, Axis::rz), drift_sum(u, Axis::rz, Axis::rx)); }

}   // namespace plate
