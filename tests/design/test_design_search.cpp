// What every search shares (design/src/search.cpp): reproducible by seed whatever the threads, the same
// design from tasks computed elsewhere, the family of axes and harmonics searched.
#include "design_test_helpers.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <functional>
#include <string>
#include <vector>

using namespace plate;
using namespace design_tests;

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

TEST_CASE(
    "the allowed axes and harmonics narrow the search: the designed motion uses nothing else, and an empty family fails cleanly",
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
