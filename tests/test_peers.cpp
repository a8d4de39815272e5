// The peer engines' drivers (issue 19, point 4) are checked before their numbers are trusted: on a
// plate at rest the part stays at rest, and on a plate translating uniformly (no vertical motion) it
// rides the plate. Both are exact consequences of the model (no slip is ever needed: the contact
// forces balance gravity alone), so what is left is each engine's own creep.
#include "peers.hpp"

#include "plate/scene_io.hpp"
#include "plate/simulate.hpp"
#include "shipped_scenes.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace plate;

namespace {

using plate_tests::scene;

// Each engine's bounds, about three times what it measured (Bullet 3.24 double, ODE 0.16, MuJoCo 2.2.2
// with peers.cpp's settings; 1e-13 where it measured rounding, 0 or ~1e-16), or the physical bound
// where that is tighter (marked). Over 2 s at rest, rocking and carried: a creep of 50 um/s (what a
// pyramid or a lost friction row gives) is 1 mm in 2 s.
struct Bounds {
    double rest_xy, rest_th;          // at rest [m, rad]
    double rock_xy, rock_th;          // on the slowly rocking plate
    double carried_xy, carried_th;    // on the uniformly translating plate
    double drag_x, drag_y, drag_th;   // the 1-D Coulomb drag: s_x off the 1-D law's, s_y, theta [m, m, rad]
    double follow;                    // fig4's second: off plate's end [m]
    double turn_lo, turn_hi;          // and its turn, relative to plate's
};

Bounds bounds(const std::string& engine) {
    // Measured: at rest 1.5e-8 m, 9.1e-8 rad; rocking 1.8e-5 m, 2.5e-4 rad; carried 2.1e-8 m, 2.0e-8
    // rad; drag 3.1e-5 m off, 3.7e-8 m, 2.3e-7 rad; follow 1.9e-4 m, turn 1.08.
    if (engine.rfind("Bullet", 0) == 0) return {5e-8, 3e-7, 6e-5, 8e-4, 6e-8, 6e-8, 1e-4, 1.2e-7, 7e-7, 6e-4, 0.75, 1.25};
    // Measured: at rest 8.8e-16 m, 0 rad; rocking 4.2e-5 m, 4.8e-4 rad (bounds 0.1 mm and 1 mrad, the creep's);
    // carried 2.9e-13 m, 5.6e-17 rad; drag 7.7e-6 m off, 1.3e-14 m, 7.0e-12 rad; follow 1.5e-4 m, turn
    // 0.981.
    if (engine.rfind("ODE", 0) == 0) return {1e-13, 1e-13, 1e-4, 1e-3, 9e-13, 1e-13, 2.5e-5, 1e-13, 2.1e-11, 4.5e-4, 0.94, 1.06};
    // Measured: at rest 7.1e-10 m, 5.6e-16 rad; rocking 3.1e-5 m, 6.5e-6 rad; carried 7.1e-10 m, 1.1e-16
    // rad; drag 1.3e-3 m off (its soft friction: below), 3.3e-5 m, 2.7e-3 rad; follow 5.7e-4 m (bound
    // 8e-4, 2 % of the distance), turn 0.61 (bound 0.5 to 1.5).
    if (engine.rfind("MuJoCo", 0) == 0) return {2.1e-9, 1e-13, 1e-4, 2e-5, 2.1e-9, 1e-13, -1, 1e-4, 8e-3, 8e-4, 0.5, 1.5};
    FAIL("no bounds measured for " << engine);
    return {};
}

constexpr double kDuration = 2;

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
        const Bounds b = bounds(r.engine);
        for (const Vec3& q : r.q) {
            CHECK((q.head<2>() - q0.head<2>()).norm() < b.rest_xy);
            CHECK(std::abs(q[2] - q0[2]) < b.rest_th);
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
        const Bounds b = bounds(r.engine);
        for (const Vec3& q : r.q) {
            CHECK((q.head<2>() - q0.head<2>()).norm() < b.rock_xy);
            CHECK(std::abs(q[2] - q0[2]) < b.rock_th);
        }
    }
}

// A plate translating in x alone, p_x'' = 20 sin wt + 10 sin(2 wt + pi/2) (fig4's period): every contact
// slips along x with the same velocity, the normal forces' centre stays on the slip's line through the
// centre of mass, so theta stays 0 and u = s_x' obeys u' = -p_x'' - mu g sgn u, held where u = 0 and
// |p_x''| <= mu g. Integrated here on its own (fixed steps of 2e-7 s, the exact plate velocity):
// s_x(0.5 s) from 0.04 at rest. Bullet and ODE within three times what they measured (bounds()): 3.1e-5
// and 7.7e-6 m off the 2.3 mm travelled. MuJoCo's soft friction lets the part travel 1.4-1.6 times as far whatever its settings
// (contact time constant 2e-4 to 1e-3 s, impratio 1 or 100: measured), an error of the engine the study reports: within the
// travel itself. A driver with friction mu^2 ends near 0.009 m, one without friction at -0.04 m: far outside either bound.
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
        const Bounds b = bounds(r.engine);
        CHECK(std::abs(r.q.back()[0] - s) < (b.drag_x < 0 ? travel : b.drag_x));   // (MuJoCo: within the travel)
        CHECK(std::abs(r.q.back()[1]) < b.drag_y);
        CHECK(std::abs(r.q.back()[2]) < b.drag_th);
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
        const Bounds b = bounds(r.engine);
        for (const Vec3& q : r.q) {
            CHECK((q.head<2>() - q0.head<2>()).norm() < b.carried_xy);
            CHECK(std::abs(q[2] - q0[2]) < b.carried_th);
        }
    }
}

namespace {

// And they are engines of the same model: fig4's part under fig4's plate for one second from rest
// (plate's full dynamics: it moves 4.0 cm and turns -0.063 rad) ends near plate's position and turns by
// about plate's angle, each engine within its bounds() (measured at dt 1e-4: Bullet 0.19 mm, ODE 0.15 mm,
// MuJoCo 0.57 mm off; turns 1.08, 0.98, 0.61 times plate's). With the engines' friction pyramids (boxes)
// Bullet and ODE turn it the wrong way (-2.0) and MuJoCo 1.8 times too far, 1.6 mm off: the test below
// fails for all three even at the loose bounds it keeps (2 % of the distance, 0.5 to 1.5 times the turn). A plate driven with the
// wrong velocity or rotation also misses.
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
        const Bounds b = pyramid ? Bounds{0, 0, 0, 0, 0, 0, 0, 0, 0, 0.02 * moved, 0.5, 1.5} : bounds(r.engine);
        CHECK((r.q.back().head<2>() - end.head<2>()).norm() < b.follow);
        const double t = r.q.back()[2] - q0[2];
        CHECK(t / turned > b.turn_lo);
        CHECK(t / turned < b.turn_hi);
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
