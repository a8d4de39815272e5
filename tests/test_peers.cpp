// The peer engines' drivers (issue 19, point 4) are checked before their numbers are trusted: on a
// plate at rest the part stays at rest, and on a plate translating uniformly (no vertical motion) it
// rides the plate. Both are exact consequences of the model (no slip is ever needed: the contact
// forces balance gravity alone), so what is left is each engine's own creep.
#include "peers.hpp"

#include "plate/scene_io.hpp"
#include "plate/simulate.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace plate;

namespace {

Scene scene(const std::string& name) { return load_scene(PLATE_SOURCE_DIR "/scenes/" + name + ".json"); }

// Drift bound over 2 s: 0.1 mm and 1 mrad. The spheres sink ~mg/k into the plate in the engines'
// soft contacts (microns) and the contact solve leaves a residual slip velocity of the solver's
// tolerance; a creep of 50 um/s (what a pyramid or a lost friction row gives) is 1 mm in 2 s.
constexpr double kDrift = 1e-4, kTurn = 1e-3, kDuration = 2;

void require_engines() { REQUIRE(!peers::engines().empty()); }

}   // namespace

TEST_CASE("peers: on a plate at rest every engine keeps the part at rest", "[peers]") {
    require_engines();
    Scene sc = scene("fig4");
    sc.plate.harmonics.clear();
    const Vec3 q0(0.01, -0.02, 0.7);
    for (const auto& e : peers::engines()) {
        const peers::PeerRun r = e.run(sc, q0, kDuration, 0.1, peers::PeerOptions{});
        INFO(r.engine << ": " << r.failure);
        REQUIRE(r.failure.empty());
        REQUIRE(r.q.size() == 21u);
        for (const Vec3& q : r.q) {
            CHECK((q.head<2>() - q0.head<2>()).norm() < kDrift);
            CHECK(std::abs(q[2] - q0[2]) < kTurn);
        }
    }
}

// A plate rocking about x and y with period 1 s (angular amplitude 6 rad/s^2: tilt up to 0.152 rad, below
// the friction angle atan 0.3 = 0.29 rad; the accelerations of plate points near the centre are
// ~0.1 m/s^2): static friction holds the part, q stays q0. An engine given the plate's angular velocity
// in the wrong frame moves it by millimetres (about 6 mm and 0.28 rad).
TEST_CASE("peers: on a slowly rocking plate every engine keeps the part stuck", "[peers]") {
    require_engines();
    Scene sc = scene("fig4");
    sc.plate.T = 1;
    sc.plate.harmonics = {{Axis::rx, 1, 6, 0}, {Axis::ry, 1, 6, kPi / 2}};
    const Vec3 q0(0.01, -0.02, 0.7);
    for (const auto& e : peers::engines()) {
        peers::PeerOptions o;
        o.dt = 1e-3;
        const peers::PeerRun r = e.run(sc, q0, kDuration, 0.1, o);
        INFO(r.engine << ": " << r.failure);
        REQUIRE(r.failure.empty());
        for (const Vec3& q : r.q) {
            CHECK((q.head<2>() - q0.head<2>()).norm() < kDrift);
            CHECK(std::abs(q[2] - q0[2]) < kTurn);
        }
    }
}

// A plate translating in x alone, p_x'' = 20 sin wt + 10 sin(2 wt + pi/2) (fig4's period): every contact
// slips along x with the same velocity, the normal forces' centre stays on the slip's line through the
// centre of mass, so theta stays 0 and u = s_x' obeys u' = -p_x'' - mu g sgn u, held where u = 0 and
// |p_x''| <= mu g. Integrated here on its own (fixed steps of 2e-7 s, the exact plate velocity):
// s_x(0.5 s) from 0.04 at rest. Bullet and ODE within a fifth of the 2.3 mm travelled (measured 1-3e-5 m
// off). MuJoCo's soft friction lets the part travel 1.4-1.6 times as far whatever its settings (contact
// time constant 2e-4 to 1e-3 s, impratio 1 or 100: measured), an error of the engine the study
// reports: within the travel itself. A driver with friction mu^2 ends near 0.009 m, one without
// friction at -0.04 m: far outside either bound.
TEST_CASE("peers: a plate translating harmonically in x drags the part as the 1-D Coulomb law says", "[peers]") {
    require_engines();
    Scene sc = scene("fig4");
    sc.plate.harmonics = {{Axis::x, 1, 20, 0}, {Axis::x, 2, 10, kPi / 2}};
    const double w = 2 * kPi / sc.plate.T, f = sc.part.friction().kinetic(0) * sc.g, t_end = 0.5;
    auto vel = [&](double t) { return -20 / w * std::cos(w * t) - 10 / (2 * w) * std::cos(2 * w * t + kPi / 2); };
    auto acc = [&](double t) { return 20 * std::sin(w * t) + 10 * std::sin(2 * w * t + kPi / 2); };
    double u = 0, s = 0.04, t = 0;
    const double h = 2e-7;
    for (long i = 0; i < std::lround(t_end / h); ++i, t += h) {
        const double a = acc(t + h / 2);
        if (u == 0 && std::abs(a) <= f) continue;   // held
        const double sg = u != 0 ? std::copysign(1.0, u) : -std::copysign(1.0, a);
        const double un = u - (vel(t + h) - vel(t)) - f * sg * h;   // relative velocity: minus the plate's change
        if (u != 0 && std::copysign(1.0, un) != std::copysign(1.0, u)) {
            s += u * h / 2;   // (stops within the step)
            u = 0;
        } else {
            s += (u + un) / 2 * h;
            u = un;
        }
    }
    const double travel = std::abs(s - 0.04);
    REQUIRE(travel > 0.001);
    for (const auto& e : peers::engines()) {
        peers::PeerOptions o;
        o.dt = 1e-4;
        const peers::PeerRun r = e.run(sc, Vec3(0.04, 0, 0), t_end, t_end, o);
        INFO(r.engine << ": " << r.failure << "; s_x " << r.q.back()[0] << ", the 1-D law's " << s << ", theta "
                      << r.q.back()[2]);
        REQUIRE(r.failure.empty());
        const bool soft = r.engine.rfind("MuJoCo", 0) == 0;
        CHECK(std::abs(r.q.back()[0] - s) < (soft ? 1.0 : 0.2) * travel);
        CHECK(std::abs(r.q.back()[1]) < 0.2 * travel);
        CHECK(std::abs(r.q.back()[2]) < 0.05);
    }
}

TEST_CASE("peers: on a plate translating uniformly every engine carries the part along", "[peers]") {
    require_engines();
    Scene sc = scene("fig4");
    sc.plate.harmonics.clear();
    const Vec3 q0(-0.02, 0.01, -0.4);
    peers::PeerOptions o;
    o.drift = Vec3(0.3, -0.2, 0);   // [m/s]: 0.72 m in 2 s
    for (const auto& e : peers::engines()) {
        const peers::PeerRun r = e.run(sc, q0, kDuration, 0.1, o);
        INFO(r.engine << ": " << r.failure);
        REQUIRE(r.failure.empty());
        for (const Vec3& q : r.q) {
            CHECK((q.head<2>() - q0.head<2>()).norm() < kDrift);
            CHECK(std::abs(q[2] - q0[2]) < kTurn);
        }
    }
}

namespace {

// And they are engines of the same model: fig4's part under fig4's plate for one second from rest
// (plate's full dynamics: it moves 4.6 cm and turns -0.063 rad) ends within 1 mm of plate's position
// (2 % of the distance; measured at dt 1e-4: Bullet 0.19 mm, ODE 0.15 mm, MuJoCo 0.57 mm) and turns
// by 0.5 to 1.5 times plate's angle (measured 1.08, 0.98, 0.61). With the engines' friction pyramids
// (boxes) Bullet and ODE turn it the wrong way (-2.0) and MuJoCo 1.8 times too far, 1.6 mm off: the
// test below fails for all three. A plate driven with the wrong velocity or rotation also misses.
void require_follows_plate(bool pyramid) {
    const Scene sc = scene("fig4");
    const Vec3 q0(0.04, -0.04, 1.0);
    IntegrationOptions io;
    io.rtol = 1e-10;
    const Trajectory ref = simulate(sc, Dynamics::Full, q0, Vec3::Zero(), 1.0, 1.0, io);
    REQUIRE(ref.samples.size() == 2u);
    const Vec3 end = ref.samples.back().q;
    const double moved = (end.head<2>() - q0.head<2>()).norm(), turned = end[2] - q0[2];
    REQUIRE(moved > 0.02);
    REQUIRE(std::abs(turned) > 0.03);
    for (const auto& e : peers::engines()) {
        peers::PeerOptions o;
        o.dt = 1e-4;
        o.pyramid = pyramid;
        const peers::PeerRun r = e.run(sc, q0, 1.0, 1.0, o);
        INFO(r.engine << ": " << r.settings << " " << r.failure << "; end " << r.q.back().transpose() << ", plate's "
                      << end.transpose());
        REQUIRE(r.failure.empty());
        CHECK((r.q.back().head<2>() - end.head<2>()).norm() < 0.02 * moved);
        const double t = r.q.back()[2] - q0[2];
        CHECK(t / turned > 0.5);
        CHECK(t / turned < 1.5);
    }
}

}   // namespace

TEST_CASE("peers: fig4 for one second follows plate's full dynamics", "[peers]") {
    require_engines();
    require_follows_plate(false);
}

// The check above fails for the pitfall it guards against: the same drivers with the engines'
// friction pyramids (not run by default: it must fail; `peer_tests "[.pyramid]"` shows it does).
TEST_CASE("peers: with friction pyramids the part goes wrong (shown failing once)", "[.pyramid]") {
    require_engines();
    require_follows_plate(true);
}
