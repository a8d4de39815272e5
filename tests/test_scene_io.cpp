// Scene files: the shipped scenes read as the paper states them; bad input is refused with a
// message that names the file and the field.
#include "plate/scene_io.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

using namespace plate;

namespace {

const std::string kGood = R"({
  "name": "t", "gravity": 9.81,
  "part": {"mass": 0.0216, "inertia": [[1.084e-5, 0, 0], [0, 1.23e-6, 0], [0, 0, 1.20e-5]],
           "contacts": [[0.01, -0.03, -0.002], [0, 0.03, -0.002], [-0.01, -0.03, -0.002]],
           "friction": [0.3, 0.3, 0.3]},
  "plate": {"period": 0.05, "harmonics": [{"axis": "x", "n": 1, "amp": 20, "phase": 0}]}
})";

std::string replace(std::string s, const std::string& from, const std::string& to) {
    const auto p = s.find(from);
    REQUIRE(p != std::string::npos);
    return s.replace(p, from.size(), to);
}

// Scenes the reader must refuse: the message starts with the file and contains `expect`.
struct Refused {
    std::string text, expect;
};
template <std::size_t N>
void check_refused(const Refused (&cases)[N]) {
    for (const auto& c : cases) {
        INFO(c.text);
        try {
            parse_scene(c.text, "bad.json");
            FAIL("accepted a bad scene");
        } catch (const InputError& e) {
            const std::string msg = e.what();
            INFO(msg);
            CHECK(msg.rfind("bad.json", 0) == 0);
            CHECK(msg.find(c.expect) != std::string::npos);
        }
    }
}

}   // namespace

TEST_CASE("shipped scenes state the paper's parts and plate motions", "[scene]") {
    const std::string dir = PLATE_SOURCE_DIR "/scenes/";
    const Scene f4 = load_scene(dir + "fig4.json");
    CHECK(f4.part.m == 0.0216);
    CHECK(f4.part.J(1, 1) == 0.123e-5);
    CHECK(f4.part.mu == Vec3::Constant(0.3));
    CHECK(f4.part.s_z() == 0.002);
    REQUIRE(f4.plate.harmonics.size() == 4);
    CHECK(f4.plate.harmonics[2].phase == Approx(549 * kPi / 512).epsilon(1e-15));   // u4, Section IV-C
    CHECK(f4.plate.harmonics[3].phase == Approx(805 * kPi / 512).epsilon(1e-15));
    const Scene f5 = load_scene(dir + "fig5.json");
    CHECK(f5.part.m == 0.0539);
    CHECK(f5.part.c[0] == Vec3(0, 0.052, -0.006));
    CHECK(f5.part.mu[2] == 0.17);
    const Scene f6 = load_scene(dir + "fig6.json");
    CHECK(f6.plate.harmonics.back().axis == Axis::rz);
    CHECK(f6.plate.harmonics.back().amp == 150);
    const Scene p = load_scene(dir + "fig1_point.json");
    CHECK(p.part.point);
    for (const char* n : {"fig1", "fig3_random"}) CHECK_NOTHROW(load_scene(dir + n + ".json"));
}

TEST_CASE("scene_to_json writes what parse_scene reads back", "[scene]") {
    const Scene a = parse_scene(kGood, "good.json");
    const Scene b = parse_scene(scene_to_json(a).dump(), "again.json");
    CHECK(b.part.J == a.part.J);
    CHECK(b.part.c[1] == a.part.c[1]);
    CHECK(b.plate.harmonics[0].amp == a.plate.harmonics[0].amp);
}

TEST_CASE("friction may be one number, a point part has mass and friction only", "[scene]") {
    const Scene s = parse_scene(replace(kGood, "[0.3, 0.3, 0.3]", "0.25"), "f.json");
    CHECK(s.part.mu == Vec3::Constant(0.25));
    const Scene p = parse_scene(R"({"name": "p", "gravity": 9.81, "part": {"mass": 1, "friction": 0.2},
        "plate": {"period": 0.05, "harmonics": []}})",
                                "p.json");
    CHECK(p.part.point);
    CHECK(p.part.contacts() == 1);
}

TEST_CASE("bad scenes name the file and the field", "[scene][input]") {
    const Refused cases[] = {
        {"{ \"name\": ", "bad.json:1:"},                                  // malformed
        {replace(kGood, "\"gravity\": 9.81,", ""), "gravity: missing"},   // missing
        {replace(kGood, "\"name\": \"t\",", "\"name\": \"t\", \"colour\": 1,"), "colour: unknown field"},
        // a control character in a field name is escaped: the message stays on one line (found by the fuzzer)
        {replace(kGood, "\"name\": \"t\",", "\"name\": \"t\", \"col\\nour\": 1,"), "col\\nour: unknown field"},
        {replace(kGood, "\"mass\": 0.0216", "\"mass\": -1"), "part.mass: expected a positive number"},
        {replace(kGood, "\"mass\": 0.0216", "\"mass\": 0"), "part.mass: expected a positive number"},
        {replace(kGood, "[0, 0, 1.20e-5]]", "[0, 0, 1.20e-5], [1, 2, 3]]"), "part.inertia: expected a 3x3"},
        {replace(kGood, "[0, 1.23e-6, 0]", "[1e-6, 1.23e-6, 0]"), "part.inertia: expected a symmetric"},
        {replace(kGood, "[[1.084e-5, 0, 0]", "[[-1.084e-5, 0, 0]"), "part.inertia: expected a symmetric positive definite"},
        {replace(kGood, "[0.3, 0.3, 0.3]", "[0.3, -0.1, 0.3]"), "part.friction: expected friction coefficients >= 0"},
        {replace(kGood, "[0.3, 0.3, 0.3]", "[0.3, 0.3]"), "part.friction: expected one number or an array of 3"},
        {replace(kGood, "[0, 0.03, -0.002]", "[0, -0.03, -0.002]"), "part.contacts: nearly collinear"},
        {replace(kGood, "[0, 0.03, -0.002]", "[0, 0.03, -0.004]"), "part.contacts: expected coplanar"},
        {replace(kGood, "[0, 0.03, -0.002]", "[0, 0.03]"), "part.contacts[1]: expected an array of 3 numbers"},
        {replace(kGood, "\"period\": 0.05", "\"period\": 0"), "plate.period: expected a positive number"},
        {replace(kGood, "\"axis\": \"x\"", "\"axis\": \"q\""), "plate.harmonics[0].axis: expected one of"},
        {replace(kGood, "\"n\": 1", "\"n\": 1.5"), "plate.harmonics[0].n: expected a whole number"},
        {replace(kGood, "\"amp\": 20", "\"amp\": NaN"), "bad.json:"},   // NaN is not JSON
        {replace(kGood, "\"amp\": 20", "\"amp\": 1e999"), "number overflow parsing '1e999'"},
        {replace(kGood, "\"amp\": 20", "\"amp\": \"20\""), "plate.harmonics[0].amp: expected a number"},
    };
    check_refused(cases);
}

TEST_CASE(
    "physical pre-checks: a part that tips, a unit error, an impossible inertia, collinear contacts, "
    "friction out of range",
    "[scene][input][precheck]") {
    // kGood's contacts (0.01, -0.03), (0, 0.03), (-0.01, -0.03): at rest N_i / (m g) are the
    // barycentric coordinates of the origin, 1/4, 1/2, 1/4. Moving contact 1 to x = 0.03 (and 3 to
    // x = 0.02) puts the origin outside the triangle: the line through contacts 2 and 3 passes
    // x = 0.01 at y = 0, so the origin lies beyond it, and contact 1 would pull.
    const Refused cases[] = {
        {replace(replace(kGood, "[0.01, -0.03, -0.002]", "[0.03, -0.03, -0.002]"), "[-0.01, -0.03, -0.002]",
                 "[0.02, -0.03, -0.002]"),
         "part.contacts: the part tips over"},
        // Contact 3 at x = +1e-4: N_1 / (m g) = -0.03 x3 / (0.06 (0.01 - x3)) = -0.5%: just outside.
        {replace(kGood, "[-0.01, -0.03, -0.002]", "[0.0001, -0.03, -0.002]"), "part.contacts: the part tips over"},
        // mass in grams: rho = sqrt(1.2e-5 / 21.6) = 7.5e-4 m against a reach of 0.0316 m (ratio 1/42,
        // inside the range); a tonne: rho = 1.1e-4 m, ratio 1/290, outside.
        {replace(kGood, "\"mass\": 0.0216", "\"mass\": 1000"), "part.inertia: radius of gyration"},
        // 1.2e-5 about z with 1e-6 and 1e-6 about x and y: 1e-6 + 1e-6 < 1.2e-5.
        {replace(replace(kGood, "[[1.084e-5, 0, 0]", "[[1e-6, 0, 0]"), "[0, 1.23e-6, 0]", "[0, 1e-6, 0]"),
         "part.inertia: principal moments"},
        // a sliver around the centre of mass, (-0.03, -e), (0.03, -e), (0, 2e): cond = 8.5e5 at e = 5e-8
        // (refused), 4.2e5 at e = 1e-7 (accepted, below)
        {replace(replace(replace(kGood, "[0.01, -0.03, -0.002]", "[-0.03, -5e-8, -0.002]"), "[0, 0.03, -0.002]",
                         "[0.03, -5e-8, -0.002]"),
                 "[-0.01, -0.03, -0.002]", "[0, 1e-7, -0.002]"),
         "part.contacts: nearly collinear"},
        // principal moments 1e-6 + 1.09e-5 < 1.2e-5, 0.8% past the triangle's edge (1.1e-5 is accepted, below)
        {replace(replace(kGood, "[[1.084e-5, 0, 0]", "[[1e-6, 0, 0]"), "[0, 1.23e-6, 0]", "[0, 1.09e-5, 0]"),
         "part.inertia: principal moments"},
        // the other side of the gyration range: 1e-5 kg with fig4's inertia, rho = 1.1 m against 0.0316 m
        // (ratio 35: inside) -- 1e-6 kg: rho = 3.5 m, ratio 110, outside
        {replace(kGood, "\"mass\": 0.0216", "\"mass\": 1e-6"), "part.inertia: radius of gyration"},
        // the model's ranges
        {replace(kGood, "\"mass\": 0.0216", "\"mass\": 2e6"), "part.mass: 2e+06 kg is outside"},
        {replace(kGood, "\"period\": 0.05", "\"period\": 5e-6"), "plate.period: 5e-06 s is outside"},
        {replace(kGood, "\"gravity\": 9.81", "\"gravity\": 2000"), "gravity: 2000 m/s^2 is above"},
        {replace(kGood, "\"amp\": 20", "\"amp\": -2e6"), "plate.harmonics[0].amp: -2e+06 is above"},
        {replace(kGood, "[0.3, 0.3, 0.3]", "[0.3, 11, 0.3]"), "part.friction: friction coefficient 11 above 10"},
    };
    check_refused(cases);
    // Inside each bound the scene is accepted: 21.6 kg with the same inertia (ratio 1/42); friction 10;
    // principal moments 1e-6, 1.1e-5, 1.2e-5 (1e-6 + 1.1e-5 = 1.2e-5, the triangle's edge).
    CHECK_NOTHROW(parse_scene(replace(kGood, "\"mass\": 0.0216", "\"mass\": 21.6"), "ok.json"));
    // Contact 3 at x = -1e-4: N_1 / (m g) = +0.5%, inside (and warned about: close to tipping).
    const Scene edge = parse_scene(replace(kGood, "[-0.01, -0.03, -0.002]", "[-0.0001, -0.03, -0.002]"), "ok.json");
    CHECK_FALSE(scene_warnings(edge).empty());
    CHECK_NOTHROW(parse_scene(replace(kGood, "[0.3, 0.3, 0.3]", "[0.3, 10, 0.3]"), "ok.json"));
    CHECK_NOTHROW(parse_scene(replace(replace(replace(kGood, "[0.01, -0.03, -0.002]", "[-0.03, -1e-7, -0.002]"),
                                              "[0, 0.03, -0.002]", "[0.03, -1e-7, -0.002]"),
                                      "[-0.01, -0.03, -0.002]", "[0, 2e-7, -0.002]"),
                              "ok.json"));
    CHECK_NOTHROW(parse_scene(replace(kGood, "\"mass\": 0.0216", "\"mass\": 1e-5"), "ok.json"));
    // The mass range on a point part (no inertia to compare with): 1e6 kg accepted, 2e6 refused.
    const std::string point = R"({"name": "p", "gravity": 9.81, "part": {"mass": 1e6, "friction": 0.2},
        "plate": {"period": 0.05, "harmonics": []}})";
    CHECK_NOTHROW(parse_scene(point, "ok.json"));
    CHECK_THROWS_WITH(parse_scene(replace(point, "1e6", "2e6"), "bad.json"), Catch::Contains("part.mass: 2e+06 kg is outside"));
    CHECK_NOTHROW(parse_scene(replace(kGood, "\"period\": 0.05", "\"period\": 1e-5"), "ok.json"));
    CHECK_NOTHROW(parse_scene(replace(replace(kGood, "[[1.084e-5, 0, 0]", "[[1e-6, 0, 0]"), "[0, 1.23e-6, 0]", "[0, 1.1e-5, 0]"),
                              "ok.json"));
}

TEST_CASE("scene warnings: admissible scenes outside the intended regime", "[scene][precheck]") {
    // The shipped scenes are in the regime: no warning.
    for (const char* n : {"fig1", "fig1_point", "fig3_random", "fig4", "fig5", "fig6", "heave_yaw"})
        CHECK(scene_warnings(load_scene(std::string(PLATE_SOURCE_DIR "/scenes/") + n + ".json")).empty());
    auto has = [](const std::vector<std::string>& w, const std::string& s) {
        for (const auto& x : w)
            if (x.find(s) != std::string::npos) return true;
        return false;
    };
    CHECK(has(scene_warnings(parse_scene(replace(kGood, "[0.3, 0.3, 0.3]", "[0.3, 2.5, 0.3]"), "w.json")),
              "part.friction: 2.5 is above 2"));
    // Contact 2 moved to (0, 0.000303): the origin lies 0.03 above the base y = -0.03 of a triangle
    // 0.030303 high, so contact 2 carries 0.03 / 0.030303 = 99% of the weight and contacts 1 and 3
    // 0.5% each: close to tipping (below 2%).
    CHECK(has(scene_warnings(parse_scene(replace(kGood, "[0, 0.03, -0.002]", "[0, 0.000303, -0.002]"), "w.json")),
              "close to tipping over"));
    // 9.81 m/s^2 of heave: the downward acceleration reaches g.
    CHECK(
        has(scene_warnings(parse_scene(
                replace(kGood, "\"axis\": \"x\", \"n\": 1, \"amp\": 20", "\"axis\": \"z\", \"n\": 1, \"amp\": 9.81"), "w.json")),
            "at least g"));
    // v_ref = max(mu g, 20) / omega = 20 / (2 pi / 0.05) = 0.159 m/s; with a 5 s period, v_ref T is
    // 20 * 5^2 / (2 pi) = 79.6 m against a reach of 0.0316 m.
    CHECK(has(scene_warnings(parse_scene(replace(kGood, "\"period\": 0.05", "\"period\": 5"), "w.json")), "times its size"));
    CHECK(scene_warnings(parse_scene(kGood, "ok.json")).empty());
    // Grams typed as kilograms: 21.6 kg with fig4's inertia, ratio 1/42: accepted, but warned about.
    CHECK(has(scene_warnings(parse_scene(replace(kGood, "\"mass\": 0.0216", "\"mass\": 21.6"), "w.json")), "check the units"));
    // A sliver 2e-7 m wide around the centre of mass: accepted, and friction (mu h = 6e-4 m) can tip it.
    CHECK(has(scene_warnings(parse_scene(replace(replace(replace(kGood, "[0.01, -0.03, -0.002]", "[-0.03, -1e-7, -0.002]"),
                                                         "[0, 0.03, -0.002]", "[0.03, -1e-7, -0.002]"),
                                                 "[-0.01, -0.03, -0.002]", "[0, 2e-7, -0.002]"),
                                         "w.json")),
              "sliding friction can tip the part"));
    // The tilt counts too: rx of 400 rad/s^2 at contacts 0.03 m off the axis gives 12 m/s^2 downward.
    CHECK(
        has(scene_warnings(parse_scene(
                replace(kGood, "\"axis\": \"x\", \"n\": 1, \"amp\": 20", "\"axis\": \"rx\", \"n\": 1, \"amp\": 400"), "w.json")),
            "at least g"));
}
