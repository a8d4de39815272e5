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

}  // namespace

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
// moves as plate's full dynamics say: its position within a fifth of the distance travelled (~4.6 cm;
// the engines' compliant contacts and steps put them ~1 cm/s off at most, measured in the study),
// and it turns the same way in yaw. A plate driven with the wrong velocity or
// rotation moves the part elsewhere, and a friction pyramid turns it the wrong way (the test below).
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
        INFO(r.engine << ": " << r.settings << " " << r.failure << "; end " << r.q.back().transpose() << ", plate's " << end.transpose());
        REQUIRE(r.failure.empty());
        CHECK((r.q.back().head<2>() - end.head<2>()).norm() < 0.2 * moved);
        const double t = r.q.back()[2] - q0[2];
        // The same way (MuJoCo's soft contacts creep while the part sticks at first: it turns a
        // quarter of plate's angle at dt = 1e-4; Bullet and ODE within 30 %): a pyramid turns it back.
        CHECK(t / turned > 0.1);
        CHECK(t / turned < 3.0);
    }
}

}  // namespace

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
