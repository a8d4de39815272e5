// Internal: exponential coordinates of the plate orientation. R1 = exp(phi^); with the spatial
// angular velocity omega1 (R1' = omega1^ R1, eq. 7), phi' = dexp_{phi}^{-1} omega1, which keeps R1 on
// SO(3) exactly (R1 is never integrated as nine numbers). |phi| stays far below pi here.
#pragma once

#include "plate/model.hpp"

#include <Eigen/Geometry>

#include <cmath>

namespace plate::detail {

inline Mat3 hat(const Vec3& w) {
    Mat3 W;
    W << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
    return W;
}
// |phi| with its sine and cosine, taken once where exp_so3 and dexp_inv meet the same phi (the full
// dynamics' right-hand side: one sincos an evaluation instead of two).
struct So3Angle {
    Vec3 phi;
    double a, s, c;
    explicit So3Angle(const Vec3& p) : phi(p), a(p.norm()), s(0.0), c(1.0) {
        if (a != 0) {   // (NaN included: the NaNs propagate as AngleAxis's did)
            s = std::sin(a);
            c = std::cos(a);
        }
    }
};
// R1 = exp(phi^) by Rodrigues' formula, in the arithmetic of Eigen's AngleAxis::toRotationMatrix
// (the same bits as the AngleAxis it replaces).
inline Mat3 exp_so3(const So3Angle& g) {
    const Vec3 n = g.a > 0 ? Vec3(g.phi.normalized()) : Vec3::UnitZ();
    const Vec3 sn = g.s * n, cn = (1.0 - g.c) * n;
    Mat3 R;
    double tmp = cn.x() * n.y();
    R(0, 1) = tmp - sn.z();
    R(1, 0) = tmp + sn.z();
    tmp = cn.x() * n.z();
    R(0, 2) = tmp + sn.y();
    R(2, 0) = tmp - sn.y();
    tmp = cn.y() * n.z();
    R(1, 2) = tmp - sn.x();
    R(2, 1) = tmp + sn.x();
    R.diagonal() = cn.cwiseProduct(n).array() + g.c;
    return R;
}
inline Mat3 exp_so3(const Vec3& phi) { return exp_so3(So3Angle(phi)); }
inline Vec3 dexp_inv(const So3Angle& g, const Vec3& w) {
    const double a = g.a;
    const Vec3& phi = g.phi;
    // 1/a^2 - (1 + cos a) / (2 a sin a), series 1/12 + a^2/720 + a^4/30240 near 0.
    const double k = a < 1e-3 ? 1.0 / 12 + a * a / 720 + a * a * a * a / 30240 : 1 / (a * a) - (1 + g.c) / (2 * a * g.s);
    return w - 0.5 * phi.cross(w) + k * phi.cross(phi.cross(w));
}
inline Vec3 dexp_inv(const Vec3& phi, const Vec3& w) { return dexp_inv(So3Angle(phi), w); }

}   // namespace plate::detail
