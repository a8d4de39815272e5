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
inline Mat3 exp_so3(const Vec3& phi) {
    return Eigen::AngleAxisd(phi.norm(), phi.norm() > 0 ? Vec3(phi.normalized()) : Vec3::UnitZ()).toRotationMatrix();
}
inline Vec3 dexp_inv(const Vec3& phi, const Vec3& w) {
    const double a = phi.norm();
    // 1/a^2 - (1 + cos a) / (2 a sin a), series 1/12 + a^2/720 + a^4/30240 near 0.
    const double k =
        a < 1e-3 ? 1.0 / 12 + a * a / 720 + a * a * a * a / 30240 : 1 / (a * a) - (1 + std::cos(a)) / (2 * a * std::sin(a));
    return w - 0.5 * phi.cross(w) + k * phi.cross(phi.cross(w));
}

}   // namespace plate::detail
