// The corner limits (design.hpp, corner_displacement_limit and corner_velocity_limit; corner_peaks in
// plate/peaks.hpp): closed forms of the corners' peaks, an independent sampling of PlateMotion's own
// displacement and velocity, the searches kept within the limits, and design() failing a motion beyond
// them whatever built it.
#include "design_test_helpers.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <string>

using namespace plate;
using namespace design_tests;

namespace {

// max over N samples and the four corners of |p + phi x r| and |p' + omega x r| from PlateMotion's
// displacement and velocity (model.cpp, evaluated harmonic by harmonic in time): corner_peaks'
// independent reference, never above the true peaks.
CornerPeaks sampled_corner_peaks(const PlateMotion& u, const Vec2& h, int N) {
    CornerPeaks s;
    for (int k = 0; k < N; ++k) {
        Vec3 p, phi, v, w;
        u.displacement(u.T * k / N, p, phi);
        u.velocity(u.T * k / N, v, w);
        for (double sx : {-1.0, 1.0})
            for (double sy : {-1.0, 1.0}) {
                const Vec3 r(sx * h.x(), sy * h.y(), 0);
                s.displacement = std::max(s.displacement, (p + phi.cross(r)).norm());
                s.velocity = std::max(s.velocity, (v + w.cross(r)).norm());
            }
    }
    return s;
}

}   // namespace

TEST_CASE("the corners' peaks: closed forms of one axis, a circle, and a turn added to a slide", "[design][peaks][corners]") {
    // A harmonic a sin(n w t + phase) moves by a / (n w)^2 at a speed of a / (n w); a turn alpha about z
    // moves a corner at distance r by alpha r / (n w)^2; a tilt alpha about x lifts the corners at +-hy
    // by alpha hy / (n w)^2 (hx plays no part: a rectangle 0.1 x 0.04 m tells x from y); x and y in
    // quadrature draw a circle, |p| = a / w^2 all period long; x and rz in phase add along x at the
    // corners y = -hy, where the turn also moves them along y: |(a + alpha hy, alpha hx)| / w^2.
    // (measured: within 3e-16 relative)
    const double T = 0.05, w = 2 * kPi / T;
    const Vec2 h(0.1, 0.04);
    const double r = h.norm();
    struct Case {
        PlateMotion u;
        double d, v;
    };
    const Case cases[] = {
        {harmonic_motion({{Axis::z, 1, 5.0, 0.3}}, T), 5 / (w * w), 5 / w},
        {harmonic_motion({{Axis::x, 3, -4.0, 1.1}}, T), 4 / (9 * w * w), 4 / (3 * w)},
        {harmonic_motion({{Axis::rz, 1, 80.0, -0.7}}, T), 80 * r / (w * w), 80 * r / w},
        {harmonic_motion({{Axis::rx, 2, 60.0, 0.0}}, T), 60 * h.y() / (4 * w * w), 60 * h.y() / (2 * w)},
        {harmonic_motion({{Axis::ry, 2, 60.0, 0.0}}, T), 60 * h.x() / (4 * w * w), 60 * h.x() / (2 * w)},
        {harmonic_motion({{Axis::x, 1, 3.0, kPi / 2}, {Axis::y, 1, 3.0, 0}}, T), 3 / (w * w), 3 / w},
        {harmonic_motion({{Axis::x, 1, 3.0, 0.4}, {Axis::rz, 1, 50.0, 0.4}}, T), std::hypot(3 + 50 * h.y(), 50 * h.x()) / (w * w),
         std::hypot(3 + 50 * h.y(), 50 * h.x()) / w},
    };
    for (const Case& c : cases) {
        INFO("axis " << axis_name(c.u.harmonics[0].axis) << " n " << c.u.harmonics[0].n);
        const CornerPeaks p = corner_peaks(c.u, h);
        CHECK(p.displacement == Approx(c.d).epsilon(1e-12));
        CHECK(p.velocity == Approx(c.v).epsilon(1e-12));
    }
    // A point plate (half size zero) sees the translation alone.
    CHECK(corner_peaks(harmonic_motion({{Axis::rz, 1, 80.0, 0}, {Axis::z, 1, 2.0, 0}}, T), Vec2::Zero()).displacement ==
          Approx(2 / (w * w)).epsilon(1e-12));
}

TEST_CASE("the corners' peaks match an independent sampling of the plate's displacement and velocity",
          "[design][peaks][corners]") {
    // Random motions on every axis, harmonics n = 1..3 (some entries repeated, some amplitudes negative),
    // a rectangular plate. The sampling at N = 10^5 points is below the true peaks by at most
    // |f''| (T / N)^2 / 8 for f = |d|, whose curvature at its peak is at most (|d''| + |d'|^2 / |d|),
    // about 2 (2 pi 3 / T)^2 |d|: 2 (2 pi 3 / N)^2 / 8 = 9e-9 of the peak, never above: corner_peaks must lie in
    // [sampled (1 - 1e-12), sampled (1 + 1e-7)]. (measured: within 6.5e-10 above the sampling)
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> U(-1, 1);
    const Vec2 h(0.12, 0.07);
    for (int trial = 0; trial < 3; ++trial) {
        PlateMotion u;
        u.T = 0.04;
        for (int a = 0; a < 6; ++a)
            for (int n = 1; n <= 3; ++n)
                for (int rep = 0; rep < (n == 2 ? 2 : 1); ++rep)
                    u.harmonics.push_back({static_cast<Axis>(a), n, (a < 3 ? 10 : 100) * U(rng) / n, kPi * U(rng)});
        const CornerPeaks p = corner_peaks(u, h), s = sampled_corner_peaks(u, h, 100'000);
        INFO("trial " << trial << ": displacement " << p.displacement << " sampled " << s.displacement << "; velocity "
                      << p.velocity << " sampled " << s.velocity);
        CHECK(p.displacement >= s.displacement * (1 - 1e-12));
        CHECK(p.displacement <= s.displacement * (1 + 1e-7));
        CHECK(p.velocity >= s.velocity * (1 - 1e-12));
        CHECK(p.velocity <= s.velocity * (1 + 1e-7));
    }
}

TEST_CASE("a sink designed under corner limits keeps its corners within them and verifies", "[design][corners]") {
    // fig1_point's sink at (0.02, -0.01): unconstrained, its corners (the flight check's square, +-0.05 m)
    // move by 1.10 mm at 0.140 m/s (measured). Under limits of 0.5 mm and 0.07 m/s, both bind: the design
    // must still verify, with its corners within the limits (by sampling, which never exceeds the true
    // peak) and every axis within its peak limit. A search blind to the limits returns a motion beyond
    // them, which design() fails.
    const Scene part = scene("fig1_point");
    DesignTarget t;
    t.kind = DesignTargetKind::Sink;
    t.at = Vec2(0.02, -0.01);
    DesignOptions o = searched(4, 400, 20, 2);
    const DesignSummary free = design(part, t, o);
    REQUIRE(free.verified);
    CHECK(free.corner_half_size.isApprox(Vec2(0.05, 0.05)));
    o.corner_displacement_limit = 0.0005;
    o.corner_velocity_limit = 0.07;
    REQUIRE(free.corner_peaks.displacement > 1.5 * o.corner_displacement_limit);
    REQUIRE(free.corner_peaks.velocity > 1.5 * o.corner_velocity_limit);
    const DesignSummary held = design(part, t, o);
    INFO(held.failure);
    REQUIRE(held.verified);
    const CornerPeaks s = sampled_corner_peaks(held.scene.plate, held.corner_half_size, 100'000);
    CHECK(s.displacement <= o.corner_displacement_limit * (1 + 1e-9));
    CHECK(s.velocity <= o.corner_velocity_limit * (1 + 1e-9));
    CHECK(held.corner_peaks.displacement == Approx(s.displacement).epsilon(1e-6));
    CHECK(held.corner_peaks.velocity == Approx(s.velocity).epsilon(1e-6));
    check_peaks(held, o);
    CHECK(held.rate > 0);
    // A larger plate (+-0.15 m): the same limits leave less room for the tilts.
    o.plate_half_size = Vec2(0.15, 0.15);
    const DesignSummary big = design(part, t, o);
    INFO(big.failure);
    REQUIRE(big.verified);
    CHECK(big.corner_half_size.isApprox(Vec2(0.15, 0.15)));
    CHECK(sampled_corner_peaks(big.scene.plate, Vec2(0.15, 0.15), 100'000).displacement <=
          o.corner_displacement_limit * (1 + 1e-9));
}

TEST_CASE("a transport and an orienter designed under a corner velocity limit keep within it", "[design][corners]") {
    // Translation alone (x, y, z): the corners move as the plate's centre, so the limit bounds |p'|.
    // fig1_point carried at 0.01 m/s under a corner speed of 0.05 m/s (unconstrained: 0.106 m/s, measured);
    // foot.json turned to THETA = 2 (its own constraints, orient.cpp) under 0.12 m/s (unconstrained: 0.164).
    const Scene part = scene("fig1_point");
    DesignOptions o = searched(4, 200, 8, 2);
    o.lin_limit = 15;
    const DesignSummary free = design(part, transport(Vec2(0.01, 0)), o);
    REQUIRE(free.verified);
    o.corner_velocity_limit = 0.05;
    REQUIRE(free.corner_peaks.velocity > o.corner_velocity_limit);
    const DesignSummary held = design(part, transport(Vec2(0.01, 0)), o);
    INFO(held.failure);
    REQUIRE(held.verified);
    CHECK(sampled_corner_peaks(held.scene.plate, held.corner_half_size, 100'000).velocity <= 0.05 * (1 + 1e-9));
    const Scene foot = scene("foot");
    DesignOptions oo = foot_orient_options();
    const DesignSummary turned_free = design(foot, foot_orient_target(), oo);
    REQUIRE(turned_free.verified);
    oo.corner_velocity_limit = 0.12;
    REQUIRE(turned_free.corner_peaks.velocity > oo.corner_velocity_limit);
    const DesignSummary turned = design(foot, foot_orient_target(), oo);
    INFO(turned.failure);
    REQUIRE(turned.verified);
    CHECK(sampled_corner_peaks(turned.scene.plate, turned.corner_half_size, 100'000).velocity <= 0.12 * (1 + 1e-9));
}

TEST_CASE("a design whose corners move beyond a corner limit fails verification, naming it", "[design][corners][target]") {
    // A registered kind whose designer reports success with z at 5 m/s^2, n = 1, T = 0.05 s: every corner
    // moves by 5 / w^2 = 0.3166 mm at 5 / w = 39.8 mm/s. design() judges every designer's motion.
    register_unjudged_motion("heaving", {{Axis::z, 1, 5.0, 0.2}}, 0.05);
    const Scene part = scene("fig1_point");
    const DesignTarget t = parse_design_target("heaving", {}, true);
    DesignOptions o;
    o.corner_displacement_limit = 0.0003;
    DesignSummary d = design(part, t, o);
    CHECK(d.corner_peaks.displacement == Approx(5 / std::pow(2 * kPi / 0.05, 2)).epsilon(1e-12));
    CHECK_FALSE(d.verified);
    CHECK(d.failure.find("corner displacement peaks at 0.3166 mm, above the limit 0.3 mm") != std::string::npos);
    o.corner_displacement_limit = 0.00032;
    o.corner_velocity_limit = 0.035;
    d = design(part, t, o);
    CHECK_FALSE(d.verified);
    CHECK(d.failure.find("corner velocity peaks at 0.03979 m/s, above the limit 0.035 m/s") != std::string::npos);
    o.corner_velocity_limit = 0.04;
    CHECK(design(part, t, o).verified);
    // Limits are lengths and speeds >= 0 (0: none); the plate's half size both zero or both set.
    o.corner_velocity_limit = -1;
    CHECK_THROWS_WITH(validate_design_options(o), Catch::Contains("corner_limits"));
    o.corner_velocity_limit = 0;
    o.plate_half_size = Vec2(0.1, 0);
    CHECK_THROWS_WITH(validate_design_options(o), Catch::Contains("plate_half_size"));
}
