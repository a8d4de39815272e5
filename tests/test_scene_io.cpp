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

}  // namespace

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
        "plate": {"period": 0.05, "harmonics": []}})", "p.json");
    CHECK(p.part.point);
    CHECK(p.part.contacts() == 1);
}

TEST_CASE("bad scenes name the file and the field", "[scene][input]") {
    struct Case {
        std::string text, expect;
    };
    const Case cases[] = {
        {"{ \"name\": ", "bad.json:1:"},                                                      // malformed
        {replace(kGood, "\"gravity\": 9.81,", ""), "gravity: missing"},                        // missing
        {replace(kGood, "\"name\": \"t\",", "\"name\": \"t\", \"colour\": 1,"), "colour: unknown field"},
        {replace(kGood, "\"mass\": 0.0216", "\"mass\": -1"), "part.mass: expected a positive number"},
        {replace(kGood, "\"mass\": 0.0216", "\"mass\": 0"), "part.mass: expected a positive number"},
        {replace(kGood, "[0, 0, 1.20e-5]]", "[0, 0, 1.20e-5], [1, 2, 3]]"), "part.inertia: expected a 3x3"},
        {replace(kGood, "[0, 1.23e-6, 0]", "[1e-6, 1.23e-6, 0]"), "part.inertia: expected a symmetric"},
        {replace(kGood, "[[1.084e-5, 0, 0]", "[[-1.084e-5, 0, 0]"), "part.inertia: expected a symmetric positive definite"},
        {replace(kGood, "[0.3, 0.3, 0.3]", "[0.3, -0.1, 0.3]"), "part.friction: expected friction coefficients >= 0"},
        {replace(kGood, "[0.3, 0.3, 0.3]", "[0.3, 0.3]"), "part.friction: expected one number or an array of 3"},
        {replace(kGood, "[0, 0.03, -0.002]", "[0, -0.03, -0.002]"), "part.contacts: expected non-collinear"},
        {replace(kGood, "[0, 0.03, -0.002]", "[0, 0.03, -0.004]"), "part.contacts: expected coplanar"},
        {replace(kGood, "[0, 0.03, -0.002]", "[0, 0.03]"), "part.contacts[1]: expected an array of 3 numbers"},
        {replace(kGood, "\"period\": 0.05", "\"period\": 0"), "plate.period: expected a positive number"},
        {replace(kGood, "\"axis\": \"x\"", "\"axis\": \"q\""), "plate.harmonics[0].axis: expected one of"},
        {replace(kGood, "\"n\": 1", "\"n\": 1.5"), "plate.harmonics[0].n: expected a whole number"},
        {replace(kGood, "\"amp\": 20", "\"amp\": NaN"), "bad.json:"},                       // NaN is not JSON
        {replace(kGood, "\"amp\": 20", "\"amp\": 1e999"), "number overflow parsing '1e999'"},
        {replace(kGood, "\"amp\": 20", "\"amp\": \"20\""), "plate.harmonics[0].amp: expected a number"},
    };
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
