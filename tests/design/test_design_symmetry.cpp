// The exact symmetries and drifts of plate motions inverse design rests on (design/src/symmetry.cpp):
// turning, shifting and odd harmonics checked against fields computed both ways; coning about z and the
// tilt drifts along x and y against their closed forms and the full dynamics.
#include "design_test_helpers.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace plate;
using namespace design_tests;

// The cycles are converged to 1e-10 v_ref at rtol 1e-11: the identities hold to ~1e-8 v_ref (the
// integrator's error, ~60 rtol v_ref, at differently placed steps), far below the field's variation.
TEST_CASE("turning the plate motion about z turns the field with it", "[design][symmetry]") {
    for (const char* name : {"fig4", "fig6", "fig5"}) {
        INFO(name);
        const Scene sc = scene(name);
        for (double a : {0.7, -2.0}) {
            Scene rot = sc;
            rot.plate = rotate_motion(sc.plate, a);
            const Eigen::Rotation2Dd R(a);
            for (const Vec3& q : {Vec3(0.03, -0.02, 1.0), Vec3(-0.01, 0.02, 2.5)}) {
                const Vec3 v = xi(sc, q);
                const Vec2 s = R * q.head<2>();
                const Vec3 w = xi(rot, Vec3(s.x(), s.y(), q[2] + a));
                CHECK((w.head<2>() - R * v.head<2>()).norm() < 1e-8 * sc.v_ref());
                CHECK(std::abs(w[2] - v[2]) < 1e-8 * sc.v_ref() / sc.part.rho());
                // (not vacuous: the unturned twist differs)
                CHECK((w.head<2>() - v.head<2>()).norm() > 1e-3 * sc.v_ref());
            }
        }
    }
}

TEST_CASE("adding -alpha x D to the linear acceleration shifts the field by D", "[design][symmetry]") {
    const Vec2 D(0.02, -0.01);
    for (const char* name : {"fig4", "fig1_point", "heave_yaw"}) {
        INFO(name);
        const Scene sc = scene(name);
        Scene shifted = sc;
        shifted.plate = shift_motion(sc.plate, D);
        // A wrong shift: only the horizontal part of -alpha x D (the vertical one dropped).
        Scene wrong = shifted;
        wrong.plate.harmonics.erase(
            std::remove_if(wrong.plate.harmonics.begin() + sc.plate.harmonics.size(), wrong.plate.harmonics.end(),
                           [](const Harmonic& h) { return h.axis == Axis::z; }),
            wrong.plate.harmonics.end());
        const bool has_vertical = wrong.plate.harmonics.size() < shifted.plate.harmonics.size();
        for (const Vec3& q : {Vec3(0.03, -0.02, 1.0), Vec3(0.0, 0.0, 0.3)}) {
            const Vec3 v = xi(sc, q);
            const Vec3 at = Vec3(q[0] + D.x(), q[1] + D.y(), q[2]);
            const Vec3 w = xi(shifted, at);
            CHECK((w - v).head<2>().norm() < 1e-8 * sc.v_ref());
            CHECK(std::abs(w[2] - v[2]) < 1e-8 * sc.v_ref() / sc.part.rho());
            CHECK((xi(sc, at) - v).norm() > 1e-3 * sc.v_ref());   // the field does vary over D
            if (has_vertical) CHECK((xi(wrong, at) - v).head<2>().norm() > 1e-4 * sc.v_ref());
        }
    }
}

TEST_CASE("odd harmonics without z or rz: the field is odd, (s, theta) and (-s, theta + pi) pair up", "[design][symmetry]") {
    // fig4: first harmonics on x, y, rx, ry. Turning the motion by pi is a half-period shift, which
    // leaves the asymptotic field unchanged: xi(-s, theta + pi) = (-v, omega).
    const Scene sc = scene("fig4");
    for (const Vec3& q : {Vec3(0.03, -0.02, 1.0), Vec3(-0.01, 0.04, -2.0)}) {
        const Vec3 v = xi(sc, q), w = xi(sc, Vec3(-q[0], -q[1], q[2] + kPi));
        CHECK((w.head<2>() + v.head<2>()).norm() < 1e-8 * sc.v_ref());
        CHECK(std::abs(w[2] - v[2]) < 1e-8 * sc.v_ref() / sc.part.rho());
    }
    // A z harmonic breaks it (the half-period shift flips z, the turn does not).
    Scene heave = sc;
    heave.plate.harmonics.push_back({Axis::z, 1, 3.0, 0.4});
    const Vec3 q(0.03, -0.02, 1.0);
    const Vec3 v = xi(heave, q), w = xi(heave, Vec3(-q[0], -q[1], q[2] + kPi));
    CHECK((w.head<2>() + v.head<2>()).norm() > 1e-4 * sc.v_ref());
}

TEST_CASE("coning: rx and ry out of phase turn the plate about z at the closed-form rate, which the full dynamics shows",
          "[design][coning]") {
    // fig4's 100 rad/s^2 on rx and ry, a quarter period apart: psi' = Im(A_rx conj A_ry) / (2 w^3)
    // = -1e4 / (2 (40 pi)^3) = -2.5197e-3 rad/s (design.hpp). The asymptotic field has a stable fixed
    // point at (0, 0, 0) that does not move; in the full dynamics the plate frame turns, the field
    // with it, and the part follows at that rate: theta's slope over 50..200 s (after the part has
    // settled onto the turning fixed point). Tolerance 1%: the formula is second order in the tilt
    // amplitude (6e-3 rad), the next order ~1e-4 relative.
    const Scene fig4 = scene("fig4");
    const double w = 2 * kPi / fig4.plate.T;
    const double expected = -1e4 / (2 * w * w * w);
    CHECK(coning_rate(fig4.plate) == Approx(expected).epsilon(1e-12));
    auto slope = [](const Scene& sc) {
        IntegrationOptions io;
        io.rtol = 1e-8;
        const Trajectory tr = simulate(sc, Dynamics::Full, Vec3::Zero(), Vec3::Zero(), 200, 50, io);
        REQUIRE(tr.stop.reason == StopReason::None);
        REQUIRE(tr.samples.size() == 5);
        return (tr.samples[4].q[2] - tr.samples[1].q[2]) / 150;
    };
    CHECK(slope(fig4) == Approx(coning_rate(fig4.plate)).epsilon(0.01));
    // The mirror image x -> -x (fig4's part is symmetric under it): x and ry (a pseudovector's
    // component) change sign; the coning and the drift reverse (formula and dynamics).
    Scene mirrored = fig4;
    for (Harmonic& h : mirrored.plate.harmonics)
        if (h.axis == Axis::x || h.axis == Axis::ry) h.phase += kPi;
    CHECK(coning_rate(mirrored.plate) == Approx(-expected).epsilon(1e-12));
    CHECK(slope(mirrored) == Approx(-expected).epsilon(0.01));
    // rx and ry in phase: no coning (the tilt keeps one axis), and different harmonics average out.
    Scene planar = fig4;
    for (Harmonic& h : planar.plate.harmonics)
        if (h.axis == Axis::ry) h.phase = 3.368621810196868;
    CHECK(std::abs(coning_rate(planar.plate)) < 1e-15);
    Scene mixed = fig4;
    for (Harmonic& h : mixed.plate.harmonics)
        if (h.axis == Axis::ry) h.n = 2;
    CHECK(coning_rate(mixed.plate) == 0.0);
}

TEST_CASE("tilt drift: rotations about two axes a quarter period apart turn the plate steadily (x and y as coning does z)",
          "[design][symmetry]") {
    // The same second-order average as coning_rate, for the pairs (ry, rz) -> x and (rz, rx) -> y.
    PlateMotion u;
    u.T = 0.05;
    const double w = 2 * kPi / u.T;
    u.harmonics = {{Axis::rz, 1, 100, 0}, {Axis::rx, 1, 50, kPi / 2}};
    const Vec2 d = tilt_drift_rate(u);
    CHECK(d.x() == Approx(0).margin(1e-15));
    CHECK(d.y() == Approx(100 * 50 * std::sin(-kPi / 2) / (2 * w * w * w)));   // Im(A_rz conj A_rx)
    PlateMotion v = u;
    v.harmonics = {{Axis::ry, 1, 80, 0.3}, {Axis::rz, 1, 60, 1.1}};   // (ry, rz) -> x
    CHECK(tilt_drift_rate(v).x() == Approx(80 * 60 * std::sin(0.3 - 1.1) / (2 * w * w * w)));
    CHECK(tilt_drift_rate(v).y() == Approx(0).margin(1e-15));
    // In phase (or opposite): the rotations share one axis, nothing accumulates.
    u.harmonics[1].phase = kPi;
    CHECK(tilt_drift_rate(u).norm() <= 1e-18);
    // Different harmonics average out.
    u.harmonics[1] = {Axis::ry, 2, 50, kPi / 2};
    CHECK(tilt_drift_rate(u).norm() <= 1e-18);
    // The full dynamics sees it: the plate's tilt grows as d t, and a part resting on it is held while
    // mu g exceeds g d t and then slides downhill. Point part, mu 0.05, rz and rx at n = 1 (150 rad/s^2
    // each) a quarter period apart: d = 150^2 / (2 w^3) = 5.7e-3 rad/s, break-away near 8.8 s, then
    // the slip accelerates at g d (t - 8.8 s): metres by 20 s. In phase the same shaking leaves it held
    // (the tilt oscillates by 150 / w^2 = 0.0095 rad, its pull 0.09 m/s^2 against mu g = 0.49).
    Scene sc = scene("fig1_point");
    sc.part.mu[0] = 0.05;
    sc.plate.harmonics = {{Axis::rz, 1, 150, 0}, {Axis::rx, 1, 150, kPi / 2}};
    const double drift = std::abs(tilt_drift_rate(sc.plate).y());
    REQUIRE(drift > 1e-3);
    const Trajectory tr = simulate(sc, Dynamics::Full, Vec3::Zero(), Vec3::Zero(), 20, 20);
    REQUIRE_FALSE(tr.samples.empty());
    const Vec3 end = tr.samples.back().q;
    INFO("end " << end.transpose() << ", drift " << tilt_drift_rate(sc.plate).transpose());
    CHECK(end.head<2>().norm() > 0.01);                   // it slid off downhill:
    CHECK(std::abs(end.y()) < 0.1 * std::abs(end.x()));   // along x (the tilt is about y)
    // the sign, as coning_rate's, is the world's axes' turn seen from the plate: the plate itself turns
    // about y at -d_y, and a turn about +y lowers its +x side, so with d_y < 0 the part slides to +x
    CHECK(end.x() * tilt_drift_rate(sc.plate).y() < 0);
    sc.plate.harmonics[1].phase = 0;   // in line: no drift, no slide beyond the shaking's own motion
    const Trajectory flat = simulate(sc, Dynamics::Full, Vec3::Zero(), Vec3::Zero(), 20, 20);
    REQUIRE_FALSE(flat.samples.empty());
    CHECK(flat.samples.back().q.head<2>().norm() < 0.1 * tr.samples.back().q.head<2>().norm());
}
