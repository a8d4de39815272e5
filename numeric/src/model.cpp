#include "plate/model.hpp"

#include "plate/friction.hpp"

#include <algorithm>
#include <cmath>

namespace plate {

double Part::rho() const { return point ? 1.0 : std::sqrt(J(2, 2) / m); }

bool Part::thin(double rel_tol) const {
    if (point) return false;
    double size = 0;
    for (const auto& ci : c) size = std::max(size, ci.head<2>().norm());
    const double jscale = J.diagonal().maxCoeff();
    return std::abs(c[0].z()) <= rel_tol * size && std::abs(J(0, 2)) <= rel_tol * jscale && std::abs(J(1, 2)) <= rel_tol * jscale;
}

const char* axis_name(Axis a) {
    static const char* names[] = {"x", "y", "z", "rx", "ry", "rz"};
    return names[static_cast<int>(a)];
}

// Each harmonic a sin(k t + phi), k = n omega, integrates to the zero-mean velocity
// -a/k cos(k t + phi) and the zero-mean position -a/k^2 sin(k t + phi).
void PlateMotion::acceleration(double t, Vec3& pdd, Vec3& wd) const {
    pdd.setZero();
    wd.setZero();
    const double w = omega();
    for (const auto& h : harmonics) {
        const double v = h.amp * std::sin(h.n * w * t + h.phase);
        const int a = static_cast<int>(h.axis);
        if (a < 3)
            pdd[a] += v;
        else
            wd[a - 3] += v;
    }
}

void PlateMotion::velocity(double t, Vec3& pd, Vec3& w1) const {
    pd.setZero();
    w1.setZero();
    const double w = omega();
    for (const auto& h : harmonics) {
        const double k = h.n * w;
        const double v = -h.amp / k * std::cos(k * t + h.phase);
        const int a = static_cast<int>(h.axis);
        if (a < 3)
            pd[a] += v;
        else
            w1[a - 3] += v;
    }
}

void PlateMotion::displacement(double t, Vec3& p, Vec3& phi) const {
    p.setZero();
    phi.setZero();
    const double w = omega();
    for (const auto& h : harmonics) {
        const double k = h.n * w;
        const double v = -h.amp / (k * k) * std::sin(k * t + h.phase);
        const int a = static_cast<int>(h.axis);
        if (a < 3)
            p[a] += v;
        else
            phi[a - 3] += v;
    }
}

double PlateMotion::horizontal_amplitude() const {
    double ax = 0, ay = 0;
    for (const auto& h : harmonics) {
        if (h.axis == Axis::x) ax += std::abs(h.amp);
        if (h.axis == Axis::y) ay += std::abs(h.amp);
    }
    return std::max(ax, ay);
}

double PlateMotion::angular_amplitude() const {
    double a = 0;
    for (const auto& h : harmonics)
        if (static_cast<int>(h.axis) >= 3) a = std::max(a, std::abs(h.amp));
    return a;
}

double Scene::v_ref() const {
    const double mu = part.friction().largest_kinetic();
    double a = std::max(mu * g, plate.horizontal_amplitude());
    if (a <= 0) a = g;
    return a / plate.omega();
}

}   // namespace plate
