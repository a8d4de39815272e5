#include "plate/random_scene.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace plate {

Scene random_scene(std::uint64_t seed, const RandomSceneOptions& opt) {
    Rng r(seed);
    Scene sc;
    sc.name = std::string(opt.point ? "random-point-" : opt.thin ? "random-thin-" : "random-thick-") + std::to_string(seed);
    sc.g = 9.81;
    Part& P = sc.part;
    P.point = opt.point;
    P.m = r.uniform(0.01, 0.1);
    double reach = 0;
    if (opt.point) {
        P.mu.setConstant(r.uniform(0.15, 0.4));
    } else {
        // Triangle around the centre of mass: angles spread over the circle, and the centre of
        // mass a convex combination of the corners with weights >= 0.15 (so N_i > 0 at rest).
        std::array<Vec2, 3> c2;
        for (int i = 0; i < 3; ++i) {
            const double a = 2 * kPi * i / 3 + r.uniform(-0.5, 0.5);
            const double rad = r.uniform(0.01, 0.05);
            c2[i] = rad * Vec2(std::cos(a), std::sin(a));
        }
        double w[3] = {r.uniform(0.15, 1), r.uniform(0.15, 1), r.uniform(0.15, 1)};
        const double ws = w[0] + w[1] + w[2];
        const Vec2 com = (w[0] * c2[0] + w[1] * c2[1] + w[2] * c2[2]) / ws;
        const double h = opt.thin ? 0.0 : r.uniform(0.001, 0.01);
        double lx = 0, ly = 0;
        for (int i = 0; i < 3; ++i) {
            const Vec2 c = c2[i] - com;
            P.c[i] = Vec3(c.x(), c.y(), -h);
            lx = std::max(lx, 2 * std::abs(c.x()));
            ly = std::max(ly, 2 * std::abs(c.y()));
            reach = std::max(reach, c.norm());
            P.mu[i] = r.uniform(0.15, 0.4);
        }
        // A box of lx x ly x H about its centre, turned about z (and tilted if thick).
        const double H = 2 * h;
        const Vec3 d(P.m * (ly * ly + H * H) / 12, P.m * (lx * lx + H * H) / 12, P.m * (lx * lx + ly * ly) / 12);
        Mat3 R = Eigen::AngleAxisd(r.uniform(0, 2 * kPi), Vec3::UnitZ()).toRotationMatrix();
        if (!opt.thin) R = R * Eigen::AngleAxisd(r.uniform(-0.3, 0.3), Vec3::UnitX()).toRotationMatrix();
        P.J = R * d.asDiagonal() * R.transpose();
        P.J = 0.5 * (P.J + P.J.transpose()).eval();
        if (opt.thin) P.J(0, 2) = P.J(2, 0) = P.J(1, 2) = P.J(2, 1) = 0;
    }

    PlateMotion& U = sc.plate;
    U.T = 0.05;
    const Axis axes[] = {Axis::x, Axis::y, Axis::z, Axis::rx, Axis::ry, Axis::rz};
    const double amp[] = {r.uniform(8, 25), r.uniform(8, 25), r.uniform(0, 3),
                          r.uniform(0, 60), r.uniform(0, 60), r.uniform(0, 120)};
    for (int a = 0; a < 6; ++a)
        for (int n = 1; n <= opt.max_harmonic; ++n) {
            const double share = n == 1 ? 1.0 : r.uniform(0, 0.35);
            U.harmonics.push_back(Harmonic{axes[a], n, amp[a] * share, r.uniform(0, 2 * kPi)});
        }
    // Keep contact with margin: the vertical plate acceleration at any contact of a part within
    // config_radius of the centre stays below 0.6 g (|z| + |rx, ry| (radius + reach)).
    double az = 0, arot = 0;
    for (const auto& h : U.harmonics) {
        if (h.axis == Axis::z) az += std::abs(h.amp);
        if (h.axis == Axis::rx || h.axis == Axis::ry) arot += std::abs(h.amp);
    }
    const double lever = opt.config_radius + reach;
    const double budget = 0.6 * sc.g;
    if (az + arot * lever > budget) {
        const double k = budget / (az + arot * lever);
        for (auto& h : U.harmonics)
            if (h.axis == Axis::z || h.axis == Axis::rx || h.axis == Axis::ry) h.amp *= k;
    }
    return sc;
}

}   // namespace plate
