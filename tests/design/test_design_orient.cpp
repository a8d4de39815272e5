// Orienting (design/src/orient.cpp): the translating plate it rests on, and a part with a rubber foot
// turned to THETA from anywhere.
#include "design_test_helpers.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace plate;
using namespace design_tests;

TEST_CASE(
    "a translating plate: the same twist everywhere, full = U dynamics, no turn with one friction "
    "coefficient, a weathervane with a rubber foot",
    "[design][orient]") {
    // foot.json: fig4's triangle (mirror symmetric about its y axis) with its lone contact, on that
    // axis, at mu 0.6 and the pair at 0.2; the plate shaken along x with a heave in phase (x 15, z 7
    // m/s^2), mirror symmetric about the x axis.
    const Scene foot = scene("foot");
    Scene plain = foot;   // every contact at 0.3: sum_i N_i r_i is parallel to the common slip, no torque
    plain.part.mu = Vec3(0.3, 0.3, 0.3);
    const Vec3 S(foot.v_ref(), foot.v_ref(), foot.v_ref() / foot.part.rho());
    const Vec3 xi0 = xi(plain, Vec3(0, 0, 0));
    CHECK(std::abs(xi0[0]) > 0.01);   // it is carried along x...
    CHECK(std::abs(xi0[2]) < 1e-8 * S[2]);
    for (int k = 0; k < 8; ++k) {
        const double th = 2 * kPi * k / 8;
        INFO("theta " << th);
        // ...the same way at every orientation and position, and never turned.
        CHECK((xi(plain, Vec3(0.03 * std::cos(3 * th), -0.02, th)) - xi0).cwiseQuotient(S).cwiseAbs().maxCoeff() < 1e-8);
    }
    // With the foot: by the two mirror symmetries theta' vanishes at theta = +-pi/2 (the part's axis
    // along the shaking); the foot tows the part, so the orientation with the foot ahead of the
    // travel (+x), theta = -pi/2, is the stable one, the other unstable.
    const Vec3 lead = xi(foot, Vec3(0, 0, -kPi / 2)), trail = xi(foot, Vec3(0, 0, kPi / 2));
    CHECK(lead[0] > 0.01);   // travels along +x: R(-pi/2) (0, 0.03) = (0.03, 0), the foot ahead
    CHECK(std::abs(lead[2]) < 1e-8 * S[2]);
    CHECK(std::abs(trail[2]) < 1e-8 * S[2]);
    CHECK(xi(foot, Vec3(0, 0, -kPi / 2 - 0.2))[2] > 0);
    CHECK(xi(foot, Vec3(0, 0, -kPi / 2 + 0.2))[2] < 0);
    CHECK(xi(foot, Vec3(0, 0, kPi / 2 - 0.2))[2] < 0);
    CHECK(xi(foot, Vec3(0, 0, kPi / 2 + 0.2))[2] > 0);
    // Nothing depends on position or tilt: the full dynamics are the U-dynamics (to the integrator's
    // tolerance; rtol 1e-10 over 2 s).
    IntegrationOptions io;
    io.rtol = 1e-10;
    const Vec3 q0(0.01, -0.02, 0.4);
    const Trajectory f = simulate(foot, Dynamics::Full, q0, Vec3::Zero(), 2, 2, io);
    const Trajectory u = simulate(foot, Dynamics::U, q0, Vec3::Zero(), 2, 2, io);
    REQUIRE(f.stop.reason == StopReason::None);
    REQUIRE(u.stop.reason == StopReason::None);
    CHECK((f.samples.back().q - u.samples.back().q).norm() < 1e-7);
}

TEST_CASE("orient: a part with a rubber foot is turned to THETA from anywhere, by a plate that only translates",
          "[design][orient]") {
    const Scene foot = scene("foot");
    const DesignTarget t = foot_orient_target();
    DesignOptions o = foot_orient_options();
    const DesignSummary s = design(foot, t, o);
    INFO(s.failure);
    REQUIRE(s.verified);
    CHECK(s.unique);
    CHECK(s.basin_share == 1.0);
    CHECK(std::abs(wrap_angle(s.fixed_point[2] - t.theta)) <= 0.02);
    // Independently of the design's own verification: the designed scene's twist at tight tolerances
    // turns the part towards THETA from either side and vanishes there (the refinement put the zero
    // within 1e-7 rad; the turn onto THETA is exact), at a position the design never looked at.
    const Vec3 S(foot.v_ref(), foot.v_ref(), foot.v_ref() / foot.part.rho());
    CHECK(std::abs(xi(s.scene, Vec3(0.03, -0.04, t.theta))[2]) < 1e-3 * s.rate + 1e-8 * S[2]);
    CHECK(xi(s.scene, Vec3(0.03, -0.04, t.theta - 0.2))[2] > 0);
    CHECK(xi(s.scene, Vec3(0.03, -0.04, t.theta + 0.2))[2] < 0);
    // The unstable orientation on the design's ring (theta' rising through zero), and full dynamics
    // from just beside it on both sides and from half a turn away: all end at THETA within 60 s.
    double unstable = 0;
    for (std::size_t k = 0; k < s.ring_twist.size(); ++k)
        if (s.ring_twist[k][2] < 0 && s.ring_twist[(k + 1) % s.ring_twist.size()][2] >= 0) unstable = s.ring_theta[k];
    for (double start : {unstable - 0.1, unstable + 0.15, t.theta + kPi}) {
        INFO("start " << start);
        const Trajectory tr = simulate(s.scene, Dynamics::Full, Vec3(-0.02, 0.01, start), Vec3::Zero(), 60, 60);
        REQUIRE(tr.stop.reason == StopReason::None);
        CHECK(std::abs(wrap_angle(tr.samples.back().q[2] - t.theta)) < 0.05);
    }
    // Within the peak limits, translating only, no flight; every run ends turned to THETA.
    for (const Harmonic& h : s.scene.plate.harmonics) CHECK(static_cast<int>(h.axis) < 3);
    check_peaks(s, o);
    CHECK(s.min_vertical_margin >= o.flight_margin - 1e-9);
    for (const DesignStartRun& r : s.runs) CHECK(std::abs(wrap_angle(r.end[2] - t.theta)) <= 0.05);
    // Reproducible by seed.
    const DesignSummary again = design(foot, t, o);
    CHECK(scene_to_json(again.scene).dump() == scene_to_json(s.scene).dump());
}
