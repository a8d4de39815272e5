// Robust designs (DesignOptions::robust, design/src/robust.cpp): a point sink searched for a small
// spread under the PPOD spec has it on draws the search never saw; a design that cannot hold the asked
// spread fails verification and says by how much; robust design is refused where it has no meaning.
#include "design_test_helpers.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

using namespace plate;
using namespace design_tests;

namespace {

UncertaintySpec ppod() { return load_uncertainty(PLATE_SOURCE_DIR "/scenes/uncertainty/ppod.json"); }

// A lean verification: 40 draws, 6 starts, full dynamics on 2 drawn plates (the command line's default
// is 200, 20 and 10).
DesignOptions robust_options(double radius) {
    DesignOptions o;
    o.robust = ppod();
    o.robust_radius = radius;
    o.robust_draws = 40;
    o.verify_starts = 6;
    o.robust_full_draws = 2;
    return o;
}

// The first-order 95 % radius of a design's fixed point under the spec, computed here from the library's
// sensitivities at the fixed point the design's own grid found (refined: tight cycles).
double first_order_radius(const DesignSummary& d) {
    RobustnessSummary s;
    fixed_point_sensitivities(d.scene, ppod(), d.fixed_point, LimitCycleOptions{}, s);
    return s.predicted_radius95;
}

// A lean search (2 starts, 150 local evaluations) for a point sink at (0.02, -0.01) of fig1's point
// part, verified robustly under `o` (the two designs below that must fail verification).
DesignSummary lean_point_sink(DesignOptions o) {
    DesignTarget t;
    t.at = Vec2(0.02, -0.01);
    o.starts = 2;
    o.local_evaluations = 150;
    return design(scene("fig1_point"), t, o);
}

}   // namespace

TEST_CASE("a robust point sink holds its fixed point within the asked radius on draws the search never saw", "[design][robust]") {
    const Scene part = scene("fig1_point");
    DesignTarget t;
    t.at = Vec2(0.02, -0.01);
    // The plain design: fastest sink, spread unasked. Under PPOD its fixed point's first-order 95 % radius
    // is 2.5 mm (measured; under the per-harmonic limits of scenes/designs/point_sink.json it was 3.26 mm).
    DesignOptions plain;
    plain.verify_starts = 6;
    const DesignSummary p = design(part, t, plain);
    REQUIRE(p.verified);
    const double plain_radius = first_order_radius(p);
    // Robust: 2 mm asked; the search aims at 0.85 of it to first order (a penalty, so a little over is
    // possible: 1.706 mm measured against 1.700).
    const DesignSummary r = design(part, t, robust_options(0.002));
    INFO(r.failure << "; plain radius " << plain_radius << " m, robust search " << r.predicted_radius95 << " m");
    REQUIRE(r.verified);
    REQUIRE(r.robustness);
    CHECK(r.predicted_radius95 <= 0.002);
    CHECK(r.predicted_radius95 < 0.8 * plain_radius);   // (the spread is what the search changed: 0.69 measured)
    // Recomputed here at tight tolerances about the design's own fixed point: the same first-order radius.
    CHECK(first_order_radius(r) == Approx(r.predicted_radius95).epsilon(0.05));
    // The verification's draws: all unique and arrived, their 95 % radius within the asked 2 mm.
    const RobustnessSummary& mc = *r.robustness;
    CHECK(mc.draws.size() == 40u);
    CHECK(mc.counts[static_cast<int>(Outcome::unique)] == 40);
    CHECK(mc.radius95 <= 0.002);
    CHECK(mc.draws[0].arrival_full.size() == 6u);   // full dynamics on the first two drawn plates
    CHECK(mc.draws[2].arrival_full.empty());
}

TEST_CASE("a robust design that cannot hold the asked spread fails verification, naming the spread", "[design][robust]") {
    // 0.3 mm: under PPOD's 3 % amplitude and 0.03 rad phase no sink of these limits is that tight (the search's
    // best first order is ~2 mm at the rates a verification needs): the Monte Carlo must refuse it.
    const DesignSummary r = lean_point_sink(robust_options(0.0003));
    INFO(r.failure);
    CHECK_FALSE(r.verified);
    CHECK(r.failure.rfind("robust: ", 0) == 0);
    CHECK(r.failure.find("0.3 mm asked") != std::string::npos);
    REQUIRE(r.robustness);
    CHECK(r.robustness->radius95 > 0.0003);
}

TEST_CASE("robust design is refused where it has no fixed point to follow", "[design][robust]") {
    DesignOptions o;
    o.robust = ppod();
    DesignTarget sink;
    sink.at = Vec2(0.02, -0.01);
    CHECK_THROWS_WITH(design(scene("fig4"), sink, o), Catch::Contains("rigid part's sink leaves its orientation free"));
    DesignTarget transport;
    transport.kind = DesignTargetKind::Transport;
    transport.velocity = Vec2(0.05, 0);
    CHECK_THROWS_WITH(design(scene("fig1_point"), transport, o), Catch::Contains("sinks and fixed points only"));
    o.robust_share = 1.5;
    CHECK_THROWS_WITH(design(scene("fig1_point"), sink, o), Catch::Contains("robust_share"));
}

TEST_CASE("a robust design whose starts cannot arrive in time fails on the share", "[design][robust][audit]") {
    DesignOptions o = robust_options(0.01);
    o.arrive = 2;
    const DesignSummary r = lean_point_sink(o);
    INFO(r.failure);
    CHECK_FALSE(r.verified);
    CHECK(r.failure.find("reached from every start within 2 s") != std::string::npos);
}
