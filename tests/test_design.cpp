// Inverse design (issue 16): the exact symmetries it rests on, checked against fields computed both
// ways, and designs verified, reproducible and failing cleanly where the target cannot be had.
#include "plate/design.hpp"
#include "plate/scene_io.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

using namespace plate;

namespace {

Scene scene(const std::string& name) { return load_scene(PLATE_SOURCE_DIR "/scenes/" + name + ".json"); }

LimitCycleOptions tight() {
    LimitCycleOptions o;
    o.tol = 1e-10;
    o.integration.rtol = 1e-11;
    return o;
}

// A short search: `starts` seeded starts of `evaluations` each, verified by `runs` full-dynamics runs.
DesignOptions searched(int starts, int evaluations, int runs, int threads = 0) {
    DesignOptions o;
    o.starts = starts;
    o.local_evaluations = evaluations;
    o.verify_starts = runs;
    o.threads = threads;
    return o;
}

// The README's rigid fixed point: fig4's part at (0.02, -0.01), THETA 0.5.
DesignTarget fig4_fixed_point() {
    DesignTarget t;
    t.kind = DesignTargetKind::FixedPoint;
    t.at = Vec2(0.02, -0.01);
    t.theta = 0.5;
    return t;
}

DesignTarget transport(const Vec2& velocity) {
    DesignTarget t;
    t.kind = DesignTargetKind::Transport;
    t.velocity = velocity;
    return t;
}

// A transport design at `velocity` under 15 m/s^2, which must verify.
DesignSummary verified_transport(const Scene& part, const Vec2& velocity, DesignOptions o) {
    o.lin_limit = 15;
    const DesignSummary s = design(part, transport(velocity), o);
    INFO(s.failure);
    REQUIRE(s.verified);
    return s;
}

Vec3 xi(const Scene& sc, const Vec3& q) {
    const LimitCycleSummary lc = limit_cycle(sc, q, tight());
    REQUIRE(lc.converged);
    return lc.twist;
}

// A point part's field Jacobian at s by central differences of 1 mm at tight tolerances (the field
// is smooth there: truncation ~ (1 mm)^2 |d^3 v| ~ 1e-3 of the entries, noise 1e-8 v_ref / 1 mm).
Eigen::Matrix2d jacobian(const Scene& sc, const Vec2& s) {
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

}  // namespace

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
        wrong.plate.harmonics.erase(std::remove_if(wrong.plate.harmonics.begin() + sc.plate.harmonics.size(),
                                                   wrong.plate.harmonics.end(),
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

TEST_CASE("a point-part sink: designed within the limits, unique, verified in full dynamics, at least the template's rate",
          "[design]") {
    const Scene part = scene("fig1_point");
    DesignTarget t;
    t.at = Vec2(0.02, -0.01);
    DesignOptions o;
    o.lin_limit = 15;
    o.ang_limit = 100;
    const DesignSummary s = design(part, t, o);
    INFO(s.failure << "; rate " << s.rate << " 1/s; " << fixed_points_sentence(s.fixed_points));
    REQUIRE(s.verified);
    CHECK(s.unique);
    CHECK((s.fixed_point.head<2>() - t.at).norm() < 2e-3);
    CHECK(s.rate >= 0.5);   // the hand-made template sink converges at about 0.5 1/s under these limits
    CHECK(s.fixed_point_eigenvalues[0].real() < 0);
    CHECK(s.fixed_point_eigenvalues[1].real() < 0);
    CHECK(s.worst_end_distance <= 0.005);
    CHECK(s.runs.size() == 20u);
    // Judged where they end (only transport's runs are judged over a window; a window sneaking in
    // here once sampled the runs every few ms and took the report's design section from 11 s to hours).
    for (const DesignStartRun& r : s.runs) CHECK(r.from == 0);
    // The limits hold in the scene as written (one harmonic per axis and n), and no flight.
    for (const Harmonic& h : s.scene.plate.harmonics)
        CHECK(std::abs(h.amp) <= (static_cast<int>(h.axis) < 3 ? o.lin_limit : o.ang_limit) * (1 + 1e-9));
    CHECK(s.min_vertical_margin >= o.flight_margin - 1e-9);
    // Independently of what the design reports about itself, at tight tolerances: the field vanishes
    // at the target (1e-8 v_ref: the cycles' noise; the shift is exact), its Jacobian there has both
    // eigenvalues' real parts at or below the template's -0.5 1/s (1 % for the differences' truncation),
    // and the full dynamics from the region's four corners ends within 5 mm after ln(70 mm / 1 mm) /
    // 0.5 s (the template's rate: at least as fast).
    CHECK(xi(s.scene, Vec3(t.at.x(), t.at.y(), 0)).head<2>().norm() < 1e-8 * s.scene.v_ref());
    const Eigen::Vector2cd ev = jacobian(s.scene, t.at).eigenvalues();
    CHECK(ev[0].real() < -0.5 * 0.99);
    CHECK(ev[1].real() < -0.5 * 0.99);
    const double settle = std::log(0.07 / 0.001) / 0.5;
    for (const Vec2& c : {Vec2(-0.05, -0.05), Vec2(0.05, -0.05), Vec2(0.05, 0.05), Vec2(-0.05, 0.05)}) {
        INFO("from (" << c.transpose() << ")");
        const Trajectory tr = simulate(s.scene, Dynamics::Full, Vec3(c.x(), c.y(), 0), Vec3::Zero(), settle, settle);
        REQUIRE(tr.stop.reason == StopReason::None);
        CHECK((tr.samples.back().q.head<2>() - t.at).norm() < 0.005);
    }
    // The scene reads back and gives the same field.
    const Scene back = parse_scene(scene_to_json(s.scene).dump(), "designed");
    CHECK(limit_cycle(back, Vec3(0.01, 0.01, 0)).twist == limit_cycle(s.scene, Vec3(0.01, 0.01, 0)).twist);
    // The hold: coning within the limit the hold sets (5 mm / (2 |D| 120 s) = 9.32e-4 rad/s at |D| =
    // 22.4 mm), and, independently of the design's own hold run, the part released at rest at the
    // target is still within 5 mm after two minutes of full dynamics at the default tolerance.
    CHECK(sink_coning_limit(t.at, o) == Approx(0.005 / (2 * std::sqrt(5e-4) * 120)).epsilon(1e-12));
    CHECK(std::abs(s.coning) <= sink_coning_limit(t.at, o) * (1 + 1e-6));
    CHECK(s.coning == coning_rate(s.scene.plate));
    CHECK(s.held.seconds == o.hold);
    CHECK(s.held.end_distance <= 0.005);
    CHECK(s.held.x == t.at.x());
    CHECK(s.held.y == t.at.y());
    const Trajectory held = simulate(s.scene, Dynamics::Full, Vec3(t.at.x(), t.at.y(), 0), Vec3::Zero(), 120, 120);
    REQUIRE(held.stop.reason == StopReason::None);
    CHECK((held.samples.back().q.head<2>() - t.at).norm() <= 0.005);
    // (the design's own hold ran the same at rtol 1e-7: within 0.1 mm)
    CHECK((held.samples.back().q.head<2>() - s.held.end.head<2>()).norm() < 1e-4);
    // Every verification run arrived before the cap (its length is the field's time to bring it in):
    // none longer than three times the linear estimate ln(d0 / 1 mm) / rate plus 2 s.
    for (const DesignStartRun& r : s.runs) {
        INFO("run from (" << r.x << ", " << r.y << "): " << r.seconds << " s");
        CHECK(r.seconds < 120);
        CHECK(r.seconds <= 3 * std::log((Vec2(r.x, r.y) - t.at).norm() / 0.001) / s.rate + 2);
    }
}

TEST_CASE("without the hold a sink cones: released at the target the part walks about the centre at the coning rate",
          "[design][coning]") {
    // No hold, no coning limit: the fastest sinks tilt in circles. The asymptotic field does not see
    // the coning; the full dynamics turn the field, its sink at D with it, about the plate's centre at
    // psi' (design.hpp), so the part released at D is 2 |D| sin(psi' t / 2) away after t (the arc's
    // chord), plus or minus the full dynamics' own offset of the sink from the field's (measured
    // 0.8-1 mm: 1.5 mm allowed), and a long enough hold catches it. Which of the near-fastest sinks
    // the multistart returns moves with rounding (|psi'| 1.4e-3 and 2.2e-3 rad/s seen: 120 s walked
    // 4.6 and 5.9 mm, either side of the 5 mm verification distance), so the hold here is 400 s:
    // a chord of 12-19 mm for those; the walk, the chord less up to 1.5 mm, is over 5 mm for any
    // |psi'| above 7.3e-4 (2 |D| sin(psi' 200 s) >= 6.5 mm).
    const Scene part = scene("fig1_point");
    DesignTarget t;
    t.at = Vec2(0.02, -0.01);
    DesignOptions o = searched(4, 400, 6);
    o.lin_limit = 15;
    o.ang_limit = 100;
    o.hold = 0;
    const DesignSummary s = design(part, t, o);
    INFO(s.failure << "; rate " << s.rate << " 1/s, coning " << s.coning << " rad/s");
    REQUIRE(s.verified);   // (verified without a hold)
    CHECK(std::isinf(sink_coning_limit(t.at, o)));
    // ... and says so: no hold means no coning limit, not a held sink.
    CHECK(std::any_of(s.notes.begin(), s.notes.end(), [](const std::string& n) { return n.find("coning not limited") != std::string::npos; }));
    CHECK(std::abs(s.coning) > 7.3e-4);
    const double hold = 400;
    const Trajectory held = simulate(s.scene, Dynamics::Full, Vec3(t.at.x(), t.at.y(), 0), Vec3::Zero(), hold, 10);
    REQUIRE(held.stop.reason == StopReason::None);
    REQUIRE(held.samples.size() == 41u);
    const double walked = (held.samples.back().q.head<2>() - t.at).norm();
    const double turn = std::abs(s.coning) * hold;
    CHECK(std::abs(walked - 2 * t.at.norm() * std::sin(turn / 2)) < 1.5e-3);
    CHECK(walked > 0.005);   // beyond the verification distance: the hold would fail this design
    // About the centre, not about the sink: from 10 s to 400 s the part's place turns by psi' 390 s
    // about the plate's origin (the full dynamics' own offset of the sink from the field's, 0.8-1 mm,
    // turns with it; within 10 um: the transient left at 10 s, e^(-rate 10 s) of that offset, is under
    // 1 um, and the coning formula's next order, 1e-4 of the walk, under 2 um) and keeps its
    // distance from the origin (within 1.5 mm: that offset again).
    const Vec2 e10 = held.samples[1].q.head<2>(), e = held.samples.back().q.head<2>();
    CHECK((e - Eigen::Rotation2Dd(s.coning * (hold - 10)) * e10).norm() < 1e-5);
    CHECK(std::abs(e.norm() - t.at.norm()) < 1.5e-3);
    // The hold judges it: the same search with the hold on and coning allowed fails, and says why.
    o.hold = hold;
    o.max_coning = HUGE_VAL;
    const DesignSummary judged = design(part, t, o);
    CHECK_FALSE(judged.verified);
    CHECK(judged.failure.find("released at rest at the target") != std::string::npos);
    CHECK(judged.held.end_distance > 0.005);
    // And with the limit a 120 s hold sets, held.
    o.hold = 120;
    o.max_coning = -1;
    const DesignSummary h = design(part, t, o);
    REQUIRE(h.verified);
    CHECK(h.held.seconds == 120);
    CHECK(std::abs(h.coning) <= sink_coning_limit(t.at, o) * (1 + 1e-6));
    CHECK(h.held.end_distance <= 0.005);
}

TEST_CASE("designs are reproducible by seed whatever the threads, and other seeds search elsewhere", "[design]") {
    const Scene part = scene("fig1_point");
    DesignTarget t;
    t.at = Vec2(-0.01, 0.015);
    DesignOptions o = searched(4, 80, 4, 1);
    const DesignSummary a = design(part, t, o);
    o.threads = 2;
    const DesignSummary b = design(part, t, o);
    CHECK(scene_to_json(a.scene) == scene_to_json(b.scene));
    CHECK(a.rate == b.rate);
    o.seed = 2;
    CHECK(scene_to_json(design(part, t, o).scene) != scene_to_json(a.scene));
}

// Issue 20: under mpirun a design's starts, its verification field's planes and its verification runs
// are computed on some rank and sent as text to all; a rank that computed none of them must reach the
// same design. The replaying runner runs nothing: whatever the design reports came through the texts.
TEST_CASE("a design whose tasks arrive as text from elsewhere is the same design", "[design][tasks]") {
    const Scene part = scene("fig1_point");
    DesignTarget t;
    t.at = Vec2(0.01, -0.02);
    DesignOptions o = searched(3, 60, 3, 2);
    const DesignSummary a = design(part, t, o);
    std::vector<std::vector<std::string>> calls;
    o.tasks = [&](int n, const std::function<std::string(int)>& work, const std::function<void(int, const std::string&)>& done) {
        calls.emplace_back(static_cast<std::size_t>(n));
        for (int i = n - 1; i >= 0; --i) done(i, calls.back()[static_cast<std::size_t>(i)] = work(i));
    };
    const DesignSummary b = design(part, t, o);
    REQUIRE(calls.size() == 3);   // the starts, the verification field, the verification runs
    std::size_t call = 0;
    o.tasks = [&](int n, const std::function<std::string(int)>&, const std::function<void(int, const std::string&)>& done) {
        REQUIRE(calls.at(call).size() == static_cast<std::size_t>(n));
        for (int i = 0; i < n; ++i) done(i, calls[call][static_cast<std::size_t>(i)]);
        ++call;
    };
    const DesignSummary c = design(part, t, o);
    for (const DesignSummary* d : {&b, &c}) {
        CHECK(scene_to_json(d->scene) == scene_to_json(a.scene));
        CHECK(d->verified == a.verified);
        CHECK(d->rate == a.rate);
        CHECK(d->evaluations == a.evaluations);
        CHECK(d->cycles == a.cycles);
        CHECK(d->fixed_point == a.fixed_point);
        CHECK(d->worst_end_distance == a.worst_end_distance);
        REQUIRE(d->runs.size() == a.runs.size());
        for (std::size_t k = 0; k < a.runs.size(); ++k) {
            CHECK(d->runs[k].end_distance == a.runs[k].end_distance);
            CHECK(d->runs[k].stop == a.runs[k].stop);
        }
    }
    CHECK(a.evaluations > 3);
    CHECK(a.cycles >= 2 * a.evaluations);   // (every sink evaluation: at least the Jacobian's two cycles)
}

TEST_CASE("a sink at the centre keeps the signal symmetric: no vertical motion, an odd field", "[design]") {
    const Scene part = scene("fig1_point");
    DesignOptions o = searched(4, 120, 4);
    const DesignSummary s = design(part, DesignTarget{}, o);
    REQUIRE(s.verified);   // (a failed design's plate at rest would pass the rest vacuously)
    REQUIRE_FALSE(s.scene.plate.harmonics.empty());
    const Eigen::Vector2cd ev = jacobian(s.scene, Vec2::Zero()).eigenvalues();
    CHECK(ev[0].real() < 0);   // the centre attracts
    CHECK(ev[1].real() < 0);
    for (const Harmonic& h : s.scene.plate.harmonics) {
        CHECK(h.axis != Axis::z);
        CHECK(h.axis != Axis::rz);
        CHECK(h.n % 2 == 1);
    }
    const Vec3 v = xi(s.scene, Vec3(0.02, -0.03, 0)), w = xi(s.scene, Vec3(-0.02, 0.03, 0));
    CHECK((v + w).head<2>().norm() < 1e-7 * s.scene.v_ref());
    CHECK(xi(s.scene, Vec3::Zero()).head<2>().norm() < 1e-8 * s.scene.v_ref());
}

TEST_CASE("an impossible target fails cleanly, never reported as done", "[design]") {
    const Scene part = scene("fig1_point");
    DesignOptions o = searched(2, 30, 3);
    SECTION("no motion allowed: no sink") {
        o.lin_limit = 0.3;   // below mu g: the part cannot even be moved
        o.ang_limit = 0.3;
        const DesignSummary s = design(part, DesignTarget{}, o);
        CHECK_FALSE(s.verified);
        CHECK_FALSE(s.failure.empty());
        // Stuck all period everywhere: every configuration is fixed, a region and no point; the grid's
        // search says it did not look there, and nothing is called unique.
        INFO(s.failure);
        CHECK(s.fixed_points.stuck_cells > 0);
        CHECK(s.failure.find("not searched: " + std::to_string(s.fixed_points.stuck_cells) +
                             " cell(s) where the part is stuck all period") != std::string::npos);
        CHECK_FALSE(s.unique);
    }
    SECTION("a flight margin no motion can keep") {
        o.flight_margin = 1.1;   // g + a_z >= 1.1 g all period: impossible for zero-mean motion
        const DesignSummary s = design(part, DesignTarget{}, o);
        CHECK_FALSE(s.verified);
        CHECK(s.failure.find("keeps the part on the plate") != std::string::npos);
    }
    SECTION("targets this version does not design say so") {
        DesignTarget line;
        line.kind = DesignTargetKind::LineSink;
        CHECK_THROWS_WITH(design(scene("fig4"), line, o), Catch::Contains("point parts only"));
        DesignTarget turn;
        turn.kind = DesignTargetKind::Orient;
        CHECK_THROWS_WITH(design(part, turn, o), Catch::Contains("no orientation"));
        DesignTarget rigid_transport = transport(Vec2(0.01, 0));   // (a weathervane's velocity turns with it; a turn needs a whirl)
        CHECK_THROWS_WITH(design(scene("foot"), rigid_transport, o), Catch::Contains("friction differs"));
        rigid_transport.omega = 0.1;
        CHECK_THROWS_WITH(design(scene("fig4"), rigid_transport, o), Catch::Contains("transport with a turn"));
        DesignTarget far;
        far.at = Vec2(0.2, 0);
        CHECK_THROWS_WITH(design(part, far, o), Catch::Contains("outside the plate region"));
        DesignOptions unverified = o;   // a design is verified in full dynamics, or not made
        unverified.verify_starts = 0;
        CHECK_THROWS_WITH(design(part, DesignTarget{}, unverified), Catch::Contains("verify_starts must be at least 1"));
    }
}

TEST_CASE("a rigid part's sink: its position ends at the target whatever its orientation, held", "[design][rigid]") {
    // fig4's part under the point sink's construction (odd harmonics n = 1, 3 on x, y, rx, ry; default
    // limits 20 / 150): the position is pulled at every orientation while the part turns on freely.
    const Scene part = scene("fig4");
    DesignTarget t;
    t.at = Vec2(0.02, -0.01);
    const DesignOptions o;
    const DesignSummary s = design(part, t, o);
    INFO(s.failure << "; rate " << s.rate << " 1/s");
    REQUIRE(s.verified);
    CHECK(s.starts == 4);
    REQUIRE(s.pulls.size() == 7u);
    CHECK(s.worst_end_distance <= 0.005);
    CHECK(s.held.end_distance <= 0.005);
    CHECK(std::abs(s.coning) <= sink_coning_limit(t.at, o) * (1 + 1e-6));
    // The flight check covers the plate under the contacts (fig4's reach from its centre of mass: 3.2
    // cm): g + a_z >= 0.2 g over the region widened by it, computed here from the motion.
    double worst = HUGE_VAL;
    const double R = 0.05 + std::hypot(0.01, 0.03);
    for (int k = 0; k < 512; ++k) {
        Vec3 pdd, wd;
        s.scene.plate.acceleration(s.scene.plate.T * k / 512, pdd, wd);
        for (double x : {-R, R})
            for (double y : {-R, R}) worst = std::min(worst, (part.g + pdd.z() + wd.x() * y - wd.y() * x) / part.g);
    }
    CHECK(worst >= o.flight_margin - 1e-3);   // (512 samples against the design's 256)
    CHECK(worst <= o.flight_margin + 0.05);   // (and it binds: the widening shapes this design)
    // Odd harmonics without z or rz: the field is odd about the target, exactly (to the cycles' noise).
    for (const Vec2& d : {Vec2(0.01, 0.004), Vec2(-0.02, 0.015)}) {
        const Vec3 a = xi(s.scene, Vec3(t.at.x() + d.x(), t.at.y() + d.y(), 0.7 + kPi));
        const Vec3 b = xi(s.scene, Vec3(t.at.x() - d.x(), t.at.y() - d.y(), 0.7));
        CHECK((a.head<2>() + b.head<2>()).norm() < 1e-8 * s.scene.v_ref());
    }
    // Independently of the design's report: at tight tolerances, for four orientations off the grid
    // and distinct modulo a half turn (the field at the target repeats after one), the position's
    // field vanishes within 2 mm of the target (a Newton step) and pulls; at theta = 0 and a quarter
    // turn at the rate the design reports (5 %: 1 mm differences here, 3 mm there). From the region's
    // corners at four orientations the full dynamics ends within 5 mm of the target after 20 s (about
    // twice ln(64 mm / 1 mm) / rate: the field weakens away from the centre).
    double slowest = HUGE_VAL;
    for (double th : {0.0, kPi / 2, kPi / 14, 5 * kPi / 14, 9 * kPi / 14, 13 * kPi / 14}) {
        const Vec3 v = xi(s.scene, Vec3(t.at.x(), t.at.y(), th));
        Eigen::Matrix2d J;
        for (int d = 0; d < 2; ++d) {
            Vec3 e = Vec3::Zero();
            e[d] = 1e-3;
            J.col(d) = (xi(s.scene, Vec3(t.at.x(), t.at.y(), th) + e) - xi(s.scene, Vec3(t.at.x(), t.at.y(), th) - e)).head<2>() / 2e-3;
        }
        const Eigen::Vector2cd ev = J.eigenvalues();
        INFO("theta " << th << ": v " << v.head<2>().transpose() << ", eigenvalues " << ev.transpose());
        CHECK(std::max(ev[0].real(), ev[1].real()) < -0.3);
        CHECK(J.fullPivLu().solve(v.head<2>()).norm() < 0.002);
        if (th == 0.0 || th == kPi / 2) slowest = std::min(slowest, -std::max(ev[0].real(), ev[1].real()));
    }
    CHECK(slowest == Approx(s.rate).epsilon(0.05));
    const double c = 0.045;
    int k = 0;
    for (const Vec2& q : {Vec2(-c, -c), Vec2(c, -c), Vec2(c, c), Vec2(-c, c)}) {
        const double th = 1.5 * k++;
        INFO("from (" << q.transpose() << ", " << th << ")");
        const Trajectory tr = simulate(s.scene, Dynamics::Full, Vec3(q.x(), q.y(), th), Vec3::Zero(), 20, 20);
        REQUIRE(tr.stop.reason == StopReason::None);
        CHECK((tr.samples.back().q.head<2>() - t.at).norm() < 0.005);
    }
}

TEST_CASE("transport: a translating plate carries a point part at the target velocity uniformly, and too fast fails cleanly",
          "[design]") {
    const Scene part = scene("fig1_point");
    DesignTarget t = transport(Vec2(0.02, 0.01));
    DesignOptions o = searched(8, 200, 6);
    o.lin_limit = 15;
    const DesignSummary s = verified_transport(part, t.velocity, o);
    CHECK((s.transport_mean - t.velocity).norm() <= 0.02 * t.velocity.norm());
    // Uniform by construction: what remains is the cycles' tolerance (1e-6 v_ref).
    CHECK(s.transport_spread < 1e-5 * s.scene.v_ref());
    for (const Harmonic& h : s.scene.plate.harmonics) {
        CHECK(static_cast<int>(h.axis) < 3);   // it only translates
        CHECK(std::abs(h.amp) <= o.lin_limit * (1 + 1e-9));
    }
    CHECK(s.min_vertical_margin >= o.flight_margin - 1e-9);
    // An independent look, not the design's own cycle: a plate that only translates makes the full
    // dynamics the U-dynamics and the field uniform, so once the transient is over the part moves by
    // the same displacement every period. From a corner, the displacement over periods 20..60 (1-3 s)
    // over its time is the asymptotic velocity: within the design's 2 % of the target (the per-period
    // displacement repeats to the integrator's error, 1e-9 of it).
    const double T = s.scene.plate.T;
    IntegrationOptions io;
    io.rtol = 1e-9;
    const Trajectory tr = simulate(s.scene, Dynamics::Full, Vec3(-0.04, -0.04, 0), Vec3::Zero(), 60 * T, 20 * T, io);
    REQUIRE(tr.stop.reason == StopReason::None);
    REQUIRE(tr.samples.size() == 4u);
    const Vec2 v13 = (tr.samples[3].q - tr.samples[1].q).head<2>() / (40 * T);
    const Vec2 v23 = (tr.samples[3].q - tr.samples[2].q).head<2>() / (20 * T);
    CHECK((v13 - t.velocity).norm() <= 0.02 * t.velocity.norm());
    CHECK((v23 - v13).norm() < 1e-6 * t.velocity.norm());   // settled: the same velocity over both spans

    // The design's own runs are judged past the start-up: each from its midpoint, within 2 % of the
    // travel over the second half (the transient lags about 0.1 s).
    for (const DesignStartRun& r : s.runs) {
        CHECK(std::abs(r.from - 0.5 * r.seconds) <= 0.5 * s.scene.plate.T);
        CHECK(std::abs(std::remainder(r.seconds - r.from, s.scene.plate.T)) < 1e-9);
        CHECK(r.end_distance <= 0.02 * t.velocity.norm() * (r.seconds - r.from));
    }
    // Faster, where the start-up's lag alone (9.6 mm at 0.08 m/s, an outside audit measured) exceeded
    // the 5 mm a check from the start allowed, and the field is as close as ever: verified.
    DesignTarget quick = t;
    quick.velocity = Vec2(0.08, 0);
    DesignOptions oq = o;
    oq.lin_limit = 20;
    const DesignSummary sq = design(part, quick, oq);
    INFO(sq.failure);
    CHECK(sq.verified);
    CHECK((sq.transport_mean - quick.velocity).norm() <= 0.02 * quick.velocity.norm());

    // 2 m/s is far beyond what 15 m/s^2 at 20 Hz can drive through friction: reported, not done.
    t.velocity = Vec2(2.0, 0);
    const DesignSummary fast = design(part, t, o);
    CHECK_FALSE(fast.verified);
    CHECK(fast.failure.find("out of reach within the limits") != std::string::npos);
}

TEST_CASE("transport of a rigid part with one friction coefficient: the point part's design, verified on the part",
          "[design][rigid]") {
    const Scene part = scene("fig4");
    const DesignTarget t = transport(Vec2(0.02, 0.01));
    const DesignSummary s = verified_transport(part, t.velocity, searched(4, 150, 6));
    CHECK(!s.scene.part.point);
    for (const Harmonic& h : s.scene.plate.harmonics) CHECK(static_cast<int>(h.axis) < 3);   // it only translates
    // Independently of the design's own grid: the part's cycles at three configurations, tight, each
    // at the target within 2 % and not turning (the torque vanishes exactly: theta' is the cycles'
    // noise, measured 1e-16); and a point part with fig4's friction under the same plate moves alike.
    LimitCycleOptions tight;
    tight.integration.rtol = 1e-10;
    tight.tol = 1e-9;
    Scene point = s.scene;
    point.part.point = true;
    const LimitCycleSummary lp = limit_cycle(point, Vec3::Zero(), tight);
    REQUIRE(lp.converged);
    for (const Vec3& q : {Vec3(0, 0, 0), Vec3(0.03, -0.02, 1.0), Vec3(-0.04, 0.04, -2.5)}) {
        INFO("q = " << q.transpose());
        const LimitCycleSummary lc = limit_cycle(s.scene, q, tight);
        REQUIRE(lc.converged);
        CHECK((lc.twist.head<2>() - t.velocity).norm() <= 0.02 * t.velocity.norm());
        CHECK(std::abs(lc.twist[2]) < 1e-9);
        CHECK((lc.twist.head<2>() - lp.twist.head<2>()).norm() < 1e-8 * s.scene.v_ref());
    }
    CHECK(s.transport_turn < 1e-9);
    for (const DesignStartRun& r : s.runs) CHECK(std::abs(r.end[2] - r.theta) < 1e-6);   // never turned
}

TEST_CASE("the allowed axes and harmonics narrow the search: the designed motion uses nothing else, and an empty family fails cleanly",
          "[design]") {
    const Scene part = scene("fig1_point");
    DesignTarget t = transport(Vec2(0.02, 0));
    DesignOptions o = searched(8, 200, 6);
    o.lin_limit = 15;
    // Along x alone, with its first two harmonics (a shake whose second harmonic skews it: the part
    // drifts along the shake), or with x and z at n = 1 only (the heave in phase with the shake).
    for (const auto& [axes, n_max] : {std::pair<std::vector<Axis>, int>{{Axis::x}, 0}, {{Axis::x, Axis::z}, 1}}) {
        DesignOptions on = o;
        on.axes = axes;
        on.max_harmonic = n_max;
        const DesignSummary s = design(part, t, on);
        INFO(s.failure);
        CHECK(s.verified);
        CHECK((s.transport_mean - t.velocity).norm() <= 0.02 * t.velocity.norm());
        REQUIRE(!s.scene.plate.harmonics.empty());
        for (const Harmonic& h : s.scene.plate.harmonics) {
            CHECK(std::find(axes.begin(), axes.end(), h.axis) != axes.end());
            if (n_max > 0) CHECK(h.n <= n_max);
        }
    }
    // A point sink's family is x, y, rx, ry at n = 1, 3: on z alone nothing of it is left.
    DesignOptions oz = o;
    oz.axes = {Axis::z};
    CHECK_THROWS_WITH(design(part, DesignTarget{}, oz), Catch::Contains("x, y, rx, ry at n = 1, 3"));
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

TEST_CASE("a translating plate: the same twist everywhere, full = U dynamics, no turn with one friction "
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
    DesignTarget t;
    t.kind = DesignTargetKind::Orient;
    t.theta = 2.0;
    DesignOptions o = searched(2, 80, 8, 2);
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
    // Within the limits, translating only, no flight; every run ends turned to THETA.
    for (const Harmonic& h : s.scene.plate.harmonics) {
        CHECK(static_cast<int>(h.axis) < 3);
        CHECK(std::abs(h.amp) <= o.lin_limit * (1 + 1e-9));
    }
    CHECK(s.min_vertical_margin >= o.flight_margin - 1e-9);
    for (const DesignStartRun& r : s.runs) CHECK(std::abs(wrap_angle(r.end[2] - t.theta)) <= 0.05);
    // Reproducible by seed.
    const DesignSummary again = design(foot, t, o);
    CHECK(scene_to_json(again.scene).dump() == scene_to_json(s.scene).dump());
}

TEST_CASE("line sink: every start ends on the line asked and stays where it arrives", "[design][line]") {
    const Scene part = scene("fig1_point");
    DesignTarget t;
    t.kind = DesignTargetKind::LineSink;
    t.at = Vec2(0.01, -0.02);
    t.theta = 0.6;
    DesignOptions o = searched(2, 60, 6, 2);
    o.lin_limit = 15;
    o.ang_limit = 100;
    const DesignSummary s = design(part, t, o);
    INFO(s.failure);
    REQUIRE(s.verified);
    CHECK(s.rate > 0.2);
    for (const Harmonic& h : s.scene.plate.harmonics)
        CHECK(std::abs(h.amp) <= (static_cast<int>(h.axis) < 3 ? o.lin_limit : o.ang_limit) * (1 + 1e-9));
    // Independently, at tight tolerances: on the line the velocity vanishes (anywhere along it, not only
    // at the point given); off it, it points back across it, and along it there is none.
    const Vec2 dir(std::cos(t.theta), std::sin(t.theta)), nrm(-dir.y(), dir.x());
    const double v = s.scene.v_ref();
    for (double a : {-0.03, 0.0, 0.025}) {
        INFO("along " << a);
        const Vec2 on = t.at + a * dir;
        CHECK(xi(s.scene, Vec3(on.x(), on.y(), 0)).head<2>().norm() < 1e-8 * v);
        for (double d : {-0.02, 0.01}) {
            const Vec2 off = on + d * nrm;
            const Vec2 w = xi(s.scene, Vec3(off.x(), off.y(), 0)).head<2>();
            CHECK(w.dot(nrm) * d < 0);
            CHECK(std::abs(w.dot(dir)) < 1e-8 * v);
        }
    }
    // Full dynamics from two corners: on the line (within 5 mm) after 8 / rate.
    for (const Vec2& c : {Vec2(-0.045, 0.045), Vec2(0.045, -0.045)}) {
        const double secs = 8 / s.rate;
        const Trajectory tr = simulate(s.scene, Dynamics::Full, Vec3(c.x(), c.y(), 0), Vec3::Zero(), secs, secs);
        REQUIRE(tr.stop.reason == StopReason::None);
        CHECK(std::abs((tr.samples.back().q.head<2>() - t.at).dot(nrm)) < 0.005);
    }
    // A rigid part is not served.
    CHECK_THROWS_WITH(design(scene("fig4"), t, o), Catch::Contains("point parts only"));
}

TEST_CASE("orientation harmonics: what a plate can give a rigid part's orientation, from the exact symmetries",
          "[design][orient]") {
    // theta' at a position, as M + sum_k B_k sin(k theta + phi_k) from 12 orientations. Each check below
    // follows from a symmetry (design.hpp), and each has a case where the symmetry is broken and the
    // harmonic it forbids is there. The cycles at tight() are within ~60 rtol v_ref of the limit: the
    // harmonics' noise is about that times v_ref / rho (~5e-9 rad/s for fig4's part); 1e-6 rad/s is
    // the bound, far below the harmonics that are allowed (1e-3 and up).
    const Scene fig4 = scene("fig4"), foot = scene("foot");
    const LimitCycleOptions o = tight();
    const double noise = 1e-6;
    auto harmonics = [&](const Scene& sc, const Vec2& s) {
        const OrientationHarmonics h = orientation_harmonics(sc, s, o);
        REQUIRE(h.defined);
        REQUIRE(h.amplitude.size() == 7);
        return h;
    };
    // (0) The transform itself, on known series: M + B_1 sin(theta + 0.3) + B_2 sin(2 theta - 1) +
    // B_6 cos(6 theta) on 12 points (k = 6 = n/2: only a cosine part is seen there).
    {
        std::vector<double> w(12);
        for (int k = 0; k < 12; ++k) {
            const double th = 2 * kPi * k / 12;
            w[k] = -0.02 + 0.3 * std::sin(th + 0.3) + 0.1 * std::sin(2 * th - 1) + 0.05 * std::cos(6 * th);
        }
        const OrientationHarmonics h = harmonics_of(w);
        CHECK(h.mean == Approx(-0.02).margin(1e-15));
        const double expected[7] = {0.02, 0.3, 0.1, 0, 0, 0, 0.05};
        for (int k = 0; k <= 6; ++k) CHECK(h.amplitude[k] == Approx(expected[k]).margin(1e-14));
        CHECK(h.rest() == Approx(0.17));
        CHECK(h.slope_bound() == Approx(2 * 0.1 + 6 * 0.05));
        CHECK_FALSE(h.one_stable());   // 0.09 < 0.17^2 + 0.5^2
        // Either side of the threshold B_1^2 = rest^2 + slope^2: 0.02 + B_1 sin(theta) + 0.05 sin(2 theta)
        // has rest 0.07 and slope bound 0.1, so B_1^2 against 0.0149: one stable orientation at B_1 =
        // 0.13 (0.0169) -- theta' = 0.02 + 0.13 sin + 0.05 sin 2 has exactly one zero with negative slope,
        // counted here on a fine ring -- and not claimed at B_1 = 0.12 (0.0144).
        for (const double b1 : {0.13, 0.12}) {
            INFO("B_1 = " << b1);
            const auto series = [&](double th) { return 0.02 + b1 * std::sin(th) + 0.05 * std::sin(2 * th); };
            for (int k = 0; k < 12; ++k) w[k] = series(2 * kPi * k / 12);
            const OrientationHarmonics hb = harmonics_of(w);
            CHECK(hb.rest() == Approx(0.07));
            CHECK(hb.slope_bound() == Approx(0.1));
            CHECK(hb.one_stable() == (b1 > 0.1221));
            int stable = 0;
            for (int k = 0; k < 100000; ++k)
                stable += series(2 * kPi * k / 100000) > 0 && series(2 * kPi * (k + 1) / 100000) <= 0;
            if (hb.one_stable()) CHECK(stable == 1);
        }
    }
    // (1) One friction coefficient on a plate that only translates: theta' = 0 is invariant, nothing
    // turns the part. With the rubber foot (foot.json's own plate, the same motion) friction's torque
    // -(sum_i (mu_i - mu) N_i r_i) x u turns it, and the same way everywhere (no position in the
    // dynamics): a weathervane, its first harmonic above the rest (B_1 0.37 against 0.16 rad/s) -- but not
    // enough for one stable orientation by one_stable(), and indeed there are three at a finer scale
    // (design.hpp).
    Scene plain = fig4;
    plain.plate = foot.plate;
    const OrientationHarmonics none = harmonics(plain, Vec2::Zero());
    CHECK(none.first() + none.rest() < noise);
    const OrientationHarmonics vane = harmonics(foot, Vec2::Zero()), there = harmonics(foot, Vec2(0.03, -0.02));
    CHECK(vane.first() > 0.1);
    CHECK(vane.first() > vane.rest());
    CHECK_FALSE(vane.one_stable());
    for (int k = 0; k <= 6; ++k) CHECK(std::abs(there.amplitude[k] - vane.amplitude[k]) < noise);
    // (2) Odd harmonics without z or rz (fig4's own plate): turning the motion by pi is shifting it by
    // half a period, so at the centre theta'(theta + pi) = theta'(theta): no odd harmonic. (The foot's
    // plate has a heave: B_1 above.)
    const OrientationHarmonics odd = harmonics(fig4, Vec2::Zero());
    CHECK(odd.amplitude[1] < noise);
    CHECK(odd.amplitude[3] < noise);
    CHECK(odd.amplitude[5] < noise);
    CHECK(odd.amplitude[2] > 0.05);   // the half-turn pairing's own term
    // Away from the centre the pairing maps s to -s: nothing forbids B_1 there (the plate's tilt and
    // alpha x s make the position matter).
    CHECK(harmonics(fig4, Vec2(0.03, -0.02)).amplitude[1] > 1e-4);
    // (3) A quarter-turn-symmetric motion: x, y, rx, ry turning in circles one way at n = 1 and the
    // other way at n = 3. Turning it by pi/2 is shifting it by T/4 (e^{i pi/2} at n = 1, e^{i 3 pi/2}
    // = e^{-i pi/2} at n = 3), so theta' at the centre has period pi/2: only B_4 (and M) remain. With
    // the third harmonic's angular-acceleration amplitude sqrt(27) times the first's (its tilt angle
    // 1/sqrt(3) times) the two harmonics' coning cancels exactly (coning_rate: Im(A_rx conj A_ry) /
    // (2 (n w)^3) per harmonic). With n = 3 reversed, turning the same way as n = 1, the symmetry is
    // broken (the motion is still odd): B_2 returns.
    auto quarter_turn = [&](int sense3) {
        const double a1 = 20, c = 9.5, a3 = 7.3, d = std::sqrt(27.0) * c, q = kPi / 2, flip = sense3 < 0 ? kPi : 0;
        PlateMotion u;
        u.T = fig4.plate.T;
        u.harmonics = {{Axis::x, 1, a1, q},         {Axis::y, 1, a1, 0},          {Axis::rx, 1, c, q + 6.30},
                       {Axis::ry, 1, c, 6.30},      {Axis::x, 3, a3, q + 3.06},   {Axis::y, 3, a3, 3.06 + flip},
                       {Axis::rx, 3, d, q + 6.33},  {Axis::ry, 3, d, 6.33 + flip}};
        return u;
    };
    Scene sym = fig4;
    sym.plate = quarter_turn(-1);
    CHECK(std::abs(coning_rate(sym.plate)) < 1e-12);
    const OrientationHarmonics quarter = harmonics(sym, Vec2::Zero());
    for (int k : {1, 2, 3, 5}) CHECK(quarter.amplitude[k] < noise);
    CHECK(quarter.amplitude[4] > 1e-3);
    sym.plate = quarter_turn(+1);
    CHECK(std::abs(coning_rate(sym.plate)) > 1e-5);
    const OrientationHarmonics broken = harmonics(sym, Vec2::Zero());
    CHECK(broken.amplitude[2] > 1e-3);
    CHECK(broken.amplitude[1] < noise);   // (still odd)
}

TEST_CASE("a rigid fixed point out of reach as a unique one: the half-turn pair, verified and reported as not unique",
          "[design][rigid]") {
    // fig4's part at (0.02, -0.01, 0.5): no motion found gives it one orientation together with the
    // position's pull (README), so after the unique search fails the design falls back on the sink's odd
    // harmonics with THETA a stable zero of theta'. Turning such a motion by pi is shifting it by half a
    // period, so the twin (s, theta) -> (-s, theta + pi) about the design's centre is a stable fixed
    // point too, with the same eigenvalues; the runs end at one or the other, and the report says so.
    const Scene part = scene("fig4");
    const DesignTarget t = fig4_fixed_point();
    DesignOptions o = searched(2, 150, 10);
    o.break_pair = false;   // (the pair itself; broken: the next test)
    const DesignSummary s = design(part, t, o);
    INFO(s.failure << "; rate " << s.rate << " 1/s");
    REQUIRE(s.verified);
    CHECK_FALSE(s.unique);
    CHECK((s.fixed_point.head<2>() - t.at).norm() <= o.fixed_point_tolerance);
    CHECK(std::abs(wrap_angle(s.fixed_point[2] - t.theta)) <= 0.02);
    for (int k = 0; k < 3; ++k) CHECK(s.fixed_point_eigenvalues[k].real() < 0);
    REQUIRE(s.competitors.size() == 1u);
    const FixedPoint& twin = s.competitors[0].point;
    CHECK((twin.q.head<2>() - t.at).norm() <= o.fixed_point_tolerance);
    CHECK(std::abs(wrap_angle(twin.q[2] - t.theta - kPi)) <= 0.02);
    // The pairing is exact: the same eigenvalues, to the accuracy they are computed with. At the summary's
    // refinement (ftol 1e-6 v_ref) the fixed points sit up to 3e-5 rad from where the field vanishes, and
    // the Jacobians taken there differ by that (7.6e-7 1/s measured), so both are refined again at
    // ftol 1e-7 and 1e-8 (find_fixed_points: cycles at rtol 1e-3 ftol): the change from 1e-7 to 1e-8
    // bounds each one's remaining error (measured 7.6e-9), and the two must agree within four times the
    // sum, plus the differences' rounding (1e-9 relative). Measured at 1e-8: equal to 1e-10. Pairing
    // breaks fail it: 2 m/s^2 of x at n = 2 (a half turn flips x, half a period does not) by 6.7e-4, and
    // 8 rad/s^2 of rz at n = 2 about the plate's origin by 8e-5 -- rz about the origin is rz about the
    // design's centre D plus a translation alpha e_z x D at n = 2, which breaks it like x does; the
    // same rz about D keeps it (2e-8 apart at ftol 1e-6).
    {
        const Field vf = compute_field(s.scene, GridSpec{});
        auto refined = [&](double ftol, const Vec3& near) {
            FixedPointOptions fo;
            fo.ftol = ftol;
            const FixedPoints fp = find_fixed_points(s.scene, vf, fo);
            const FixedPoint* best = nullptr;
            for (const FixedPoint& p : fp.points)
                if (p.stability == Stability::Stable &&
                    (!best || std::hypot((p.q - near).head<2>().norm(), wrap_angle(p.q[2] - near[2])) <
                                  std::hypot((best->q - near).head<2>().norm(), wrap_angle(best->q[2] - near[2]))))
                    best = &p;
            REQUIRE(best);
            return best->eigenvalues;
        };
        auto gap = [](const Eigen::Vector3cd& a, const Eigen::Vector3cd& b) {   // eigenvalues matched nearest
            double worst = 0;
            for (int k = 0; k < 3; ++k) {
                double nearest = HUGE_VAL;
                for (int j = 0; j < 3; ++j) nearest = std::min(nearest, std::abs(a[j] - b[k]));
                worst = std::max(worst, nearest);
            }
            return worst;
        };
        const Vec3 at_target(t.at.x(), t.at.y(), t.theta);
        const Eigen::Vector3cd t7 = refined(1e-7, at_target), t8 = refined(1e-8, at_target);
        const Eigen::Vector3cd w7 = refined(1e-7, twin.q), w8 = refined(1e-8, twin.q);
        const double bound = 4 * (gap(t7, t8) + gap(w7, w8)) + 1e-9 * t8.cwiseAbs().maxCoeff();
        INFO("target against twin " << gap(t8, w8) << " 1/s; allowed " << bound);
        CHECK(gap(t8, w8) <= bound);
    }
    // The shares, recounted from where the runs ended: each at the target or at the twin.
    REQUIRE(s.runs.size() == 10u);
    int at_target = 0, at_twin = 0;
    for (const DesignStartRun& r : s.runs) {
        CHECK(r.stop.empty());
        const bool a = (r.end.head<2>() - t.at).norm() <= o.verify_distance && std::abs(wrap_angle(r.end[2] - t.theta)) <= 0.05;
        const bool b = (r.end.head<2>() - twin.q.head<2>()).norm() <= o.verify_distance &&
                       std::abs(wrap_angle(r.end[2] - twin.q[2])) <= 0.05;
        CHECK(a != b);
        at_target += a;
        at_twin += b;
    }
    CHECK(s.basin_share == Approx(at_target / 10.0));
    CHECK(s.competitors[0].basin_share == Approx(at_twin / 10.0));
    // The pairing's cap on the share, about the centre halfway between the target and its twin:
    // (0.1 - 0.04)(0.1 - 0.02) of the 0.01 m^2 square is its own image, so at most 1 - 0.48 / 2.
    CHECK(s.basin_share_bound == Approx(pair_basin_bound(0.5 * (t.at + twin.q.head<2>()), o.region)).margin(1e-3));
    CHECK(s.basin_share_bound == Approx(0.76).margin(1e-3));
    CHECK(at_target > 0);
    CHECK(at_twin > 0);   // (each basin half the starts in expectation; 10 runs)
    CHECK(std::abs(s.coning) <= 1e-4);
    CHECK(s.held.seconds == o.hold);   // released at the target, held
    CHECK(s.held.stop.empty());
    CHECK(s.held.end_distance <= o.verify_distance);
    CHECK(s.starts == 2);   // the pair's search alone (the general search runs only where the pair fails)
    CHECK(s.notes.front().find("a half-turn pair") == 0);
}

TEST_CASE("the half-turn pair broken by rz about its centre: fig4's fixed point unique, every run at the target",
          "[design][rigid]") {
    // docs/inverse-design.md (2026-11-28): at the pair's fixed point theta' has no first harmonic; rz at
    // n = 2 about the design's centre brings its two minima near a saddle-node and rz at n = 1 lifts one
    // of them, so the part turns into one orientation from everywhere (through a slow passage where the
    // twin was). The field's fixed points lie on the curve s*(theta) where the position's twist
    // vanishes; along it the twin's well must stay above zero too (lift_wells). The README's target:
    // unique on the 7^3 grid, every run at the target.
    const Scene part = scene("fig4");
    const DesignTarget t = fig4_fixed_point();
    DesignOptions o;
    const DesignSummary s = design(part, t, o);
    INFO(s.failure << "; rate " << s.rate << " 1/s, share " << s.basin_share << ", unique " << s.unique);
    REQUIRE(s.verified);
    CHECK(s.unique);
    CHECK(s.competitors.empty());
    CHECK(s.basin_share == 1.0);
    CHECK(s.worst_end_distance <= o.verify_distance);
    CHECK((s.fixed_point.head<2>() - t.at).norm() <= o.fixed_point_tolerance);
    CHECK(std::abs(wrap_angle(s.fixed_point[2] - t.theta)) <= 0.02);
    for (int k = 0; k < 3; ++k) CHECK(s.fixed_point_eigenvalues[k].real() < 0);
    // Uniqueness checked apart from the library's grid search and its linearised ring: on 96 orientations
    // (between lift_wells's 48), s*(theta) by Newton on the position's twist alone (central differences,
    // 0.5 mm), and theta' there. Every fixed point of the field is a zero of that theta' on the branch of
    // s* followed; the position is a stable node there (its 2x2 Jacobian: positive determinant, negative
    // trace), so one branch. A stable fixed point is a zero theta' falls through: exactly one, within a
    // ring step of THETA, and every other well of theta' above zero by half lift_wells's 0.003 rad/s
    // margin (its linearisation was measured 3e-4 off: -0.0016 against -0.0013). Without lift_wells:
    // two falls, the second near -2.49, THETA + pi + 0.15 wrapped.
    {
        const int n = 96;
        std::vector<double> w(n);
        Vec2 p = t.at;
        for (int k = 0; k < n; ++k) {
            const double th = -kPi + 2 * kPi * (k + 0.5) / n;
            auto pos_twist = [&](const Vec2& at) { return limit_cycle(s.scene, Vec3(at.x(), at.y(), th)).twist; };
            Eigen::Matrix2d J;
            for (int it = 0; it < 20; ++it) {
                const double h = 5e-4;
                const Vec3 f = pos_twist(p);
                J.col(0) = (pos_twist(p + Vec2(h, 0)) - pos_twist(p - Vec2(h, 0))).head<2>() / (2 * h);
                J.col(1) = (pos_twist(p + Vec2(0, h)) - pos_twist(p - Vec2(0, h))).head<2>() / (2 * h);
                const Vec2 step = J.fullPivLu().solve(Vec2(f.head<2>()));
                p -= step;
                if (step.norm() < 1e-9) break;
            }
            REQUIRE(pos_twist(p).head<2>().norm() < 1e-7);
            CHECK((p - t.at).norm() < o.region);
            CHECK(J.determinant() > 0);
            CHECK(J.trace() < 0);
            w[k] = pos_twist(p)[2];
        }
        std::vector<int> falls;
        for (int k = 0; k < n; ++k)
            if (w[k] > 0 && w[(k + 1) % n] <= 0) falls.push_back(k);
        INFO("theta' falls through zero along s* " << falls.size() << " time(s)");
        REQUIRE(falls.size() == 1);
        CHECK(std::abs(wrap_angle(-kPi + 2 * kPi * (falls[0] + 1.0) / n - t.theta)) <= 2 * kPi / n);
        // the target's well: from the fall to where theta' turns positive again; every other local
        // minimum clears the margin
        std::vector<bool> target_well(n, false);
        for (int k = (falls[0] + 1) % n; w[k] <= 0 && !target_well[k]; k = (k + 1) % n) target_well[k] = true;
        double lowest_other = HUGE_VAL;
        for (int k = 0; k < n; ++k)
            if (!target_well[k] && w[k] <= w[(k + n - 1) % n] && w[k] < w[(k + 1) % n]) lowest_other = std::min(lowest_other, w[k]);
        INFO("the shallowest other well " << lowest_other << " rad/s");
        CHECK(lowest_other >= 0.0015);
    }
    // The pairing is broken: the motion has rz at n = 1 (a half turn keeps rz, half a period reverses it)
    // and no tilt drift (rz at n = 1 along the tilts, which were made parallel): without that the plate's
    // tilt grows and the runs leave the plate.
    bool rz1 = false;
    for (const Harmonic& h : s.scene.plate.harmonics) rz1 |= h.axis == Axis::rz && h.n == 1 && h.amp > 1;
    CHECK(rz1);
    CHECK(tilt_drift_rate(s.scene.plate).norm() <= 1e-12);   // (zero but for rounding: rz along the parallel tilts)
    CHECK(std::abs(s.coning) <= 1e-4);
    CHECK(s.held.stop.empty());
    CHECK(s.held.end_distance <= o.verify_distance);
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
    CHECK(end.head<2>().norm() > 0.01);   // it slid off downhill:
    CHECK(std::abs(end.y()) < 0.1 * std::abs(end.x()));   // along x (the tilt is about y)
    // the sign, as coning_rate's, is the world's axes' turn seen from the plate: the plate itself turns
    // about y at -d_y, and a turn about +y lowers its +x side, so with d_y < 0 the part slides to +x
    CHECK(end.x() * tilt_drift_rate(sc.plate).y() < 0);
    sc.plate.harmonics[1].phase = 0;   // in line: no drift, no slide beyond the shaking's own motion
    const Trajectory flat = simulate(sc, Dynamics::Full, Vec3::Zero(), Vec3::Zero(), 20, 20);
    REQUIRE_FALSE(flat.samples.empty());
    CHECK(flat.samples.back().q.head<2>().norm() < 0.1 * tr.samples.back().q.head<2>().norm());
}

TEST_CASE("a half-turn pair's basin cap: of the region's part that is its own image, at most half",
          "[design][rigid]") {
    // Closed forms for |s_x|, |s_y| <= a: about the region's centre the whole region is its own image
    // (1/2); about a point on its edge nothing is (1); in between (2a - 2|D_x|)(2a - 2|D_y|) / (4 a^2)
    // of it is, half of which may go to the target.
    const double a = 0.05;
    CHECK(pair_basin_bound(Vec2(0, 0), a) == Approx(0.5));
    CHECK(pair_basin_bound(Vec2(a, 0), a) == Approx(1.0));
    CHECK(pair_basin_bound(Vec2(0, -2 * a), a) == Approx(1.0));
    CHECK(pair_basin_bound(Vec2(0.02, -0.01), a) == Approx(1 - 0.06 * 0.08 / (2 * 0.01)));
    CHECK(pair_basin_bound(Vec2(-0.02, 0.01), a) == Approx(pair_basin_bound(Vec2(0.02, -0.01), a)));
}
