// What the design tests share (tests/design/test_design_*.cpp): scenes by name, tight cycle options,
// short searches, the targets used more than once, and the field's twist and Jacobian at tight tolerances.
#pragma once

#include "plate/design.hpp"
#include "plate/scene_io.hpp"
#include "../shipped_scenes.hpp"

#include <catch2/catch.hpp>

#include <initializer_list>
#include <string>
#include <vector>

namespace design_tests {
using namespace plate;

using plate_tests::scene;

inline LimitCycleOptions tight() {
    LimitCycleOptions o;
    o.tol = 1e-10;
    o.integration.rtol = 1e-11;
    return o;
}

// A short search: `starts` seeded starts of `evaluations` each, verified by `runs` full-dynamics runs.
inline DesignOptions searched(int starts, int evaluations, int runs, int threads = 0) {
    DesignOptions o;
    o.starts = starts;
    o.local_evaluations = evaluations;
    o.verify_starts = runs;
    o.threads = threads;
    return o;
}

// The README's rigid fixed point: fig4's part at (0.02, -0.01), THETA 0.5.
inline DesignTarget fig4_fixed_point() {
    DesignTarget t;
    t.kind = DesignTargetKind::FixedPoint;
    t.at = Vec2(0.02, -0.01);
    t.theta = 0.5;
    return t;
}

// foot.json turned to THETA = 2 by a plate that only translates (the orient tests' design).
inline DesignTarget foot_orient_target() {
    DesignTarget t;
    t.kind = DesignTargetKind::Orient;
    t.theta = 2.0;
    return t;
}
inline DesignOptions foot_orient_options() { return searched(2, 80, 8, 2); }

inline DesignTarget transport(const Vec2& velocity) {
    DesignTarget t;
    t.kind = DesignTargetKind::Transport;
    t.velocity = velocity;
    return t;
}

// A transport design at `velocity` under 15 m/s^2, which must verify.
inline DesignSummary verified_transport(const Scene& part, const Vec2& velocity, DesignOptions o) {
    o.lin_limit = 15;
    const DesignSummary s = design(part, transport(velocity), o);
    INFO(s.failure);
    REQUIRE(s.verified);
    return s;
}

// A plate motion of the given harmonics and period T [s].
inline PlateMotion harmonic_motion(std::initializer_list<Harmonic> h, double T = 0.05) {
    PlateMotion u;
    u.T = T;
    u.harmonics = h;
    return u;
}

// Registers a point-part target kind `name` whose designer reports success, unjudged, with these
// harmonics at period T (0: the design's): what design() itself checks is then all that stands between
// the motion and the user.
inline void register_unjudged_motion(const std::string& name, std::vector<Harmonic> harmonics, double T = 0) {
    DesignTargetType type;
    type.name = name;
    type.numbers = "";
    type.count = 0;
    type.rigid = false;
    type.default_starts = 1;
    type.design = [harmonics, T](const Scene& p, const DesignTarget&, const DesignOptions&, double design_T) {
        DesignSummary s;
        s.scene = p;
        s.scene.plate.T = T > 0 ? T : design_T;
        s.scene.plate.harmonics = harmonics;
        s.verified = true;
        return s;
    };
    register_design_target(type);
}

// max over N equally spaced samples of |u_a(t)| per axis (the acceleration as the model evaluates it):
// axis_peaks' independent reference, below the true peak by at most sum |amp| (2 pi n_max / N)^2 / 8.
inline Vec6 sampled_peaks(const PlateMotion& u, int N) {
    Vec6 p = Vec6::Zero();
    for (int k = 0; k < N; ++k) {
        Vec3 a, b;
        u.acceleration(u.T * k / N, a, b);
        for (int i = 0; i < 3; ++i) p[i] = std::max(p[i], std::abs(a[i])), p[3 + i] = std::max(p[3 + i], std::abs(b[i]));
    }
    return p;
}

// Each axis' peak of the designed motion within the limits (sampled_peaks at 10^5 points, which never
// exceeds the true peak) and the summary's peaks the same (within 1e-6 of the limit: the sampling's
// error for harmonics up to n = 3 is 5e-9 of the amplitudes' sum).
inline void check_peaks(const DesignSummary& s, const DesignOptions& o) {
    const Vec6 sampled = sampled_peaks(s.scene.plate, 100'000);
    for (int a = 0; a < 6; ++a) {
        const double limit = a < 3 ? o.lin_limit : o.ang_limit;
        INFO(axis_name(static_cast<Axis>(a)) << ": sampled peak " << sampled[a] << ", reported " << s.peaks[a]);
        CHECK(sampled[a] <= limit * (1 + 1e-9));
        CHECK(s.peaks[a] == Approx(sampled[a]).margin(1e-6 * limit));
    }
}

inline Vec3 xi(const Scene& sc, const Vec3& q) {
    const LimitCycleSummary lc = limit_cycle(sc, q, tight());
    REQUIRE(lc.converged);
    return lc.twist;
}

// A point part's field Jacobian at s by central differences of 1 mm at tight tolerances (the field
// is smooth there: truncation ~ (1 mm)^2 |d^3 v| ~ 1e-3 of the entries, noise 1e-8 v_ref / 1 mm).
inline Eigen::Matrix2d jacobian(const Scene& sc, const Vec2& s) {
    Eigen::Matrix2d J;
    const double h = 1e-3;
    for (int d = 0; d < 2; ++d) {
        Vec3 e = Vec3::Zero();
        e[d] = h;
        const Vec3 q(s.x(), s.y(), 0);
        J.col(d) = (xi(sc, q + e) - xi(sc, q - e)).head<2>() / (2 * h);
    }
    return J;
}

}   // namespace design_tests
