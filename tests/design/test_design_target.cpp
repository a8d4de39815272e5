// Design targets are parsed and judged once, in the library (design_target.hpp): the command line,
// campaigns and the library refuse a target with the same message; a kind of target registered from
// outside the library (here, in the test only) is parsed, dispatched, verified and reported like a
// built-in one -- the worked example of docs/architecture.md's "Adding a design target".
#include "plate/design.hpp"
#include "plate/scene_io.hpp"
#include "plate/simulate.hpp"
#include "plate/sweep.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace plate;
namespace fs = std::filesystem;

namespace {

const std::string kScenes = PLATE_SOURCE_DIR "/scenes/";

struct Words {
    std::string kind;
    std::vector<double> values;
    std::string text() const {
        std::ostringstream s;
        s << kind;
        for (double v : values) s << ' ' << v;
        return s.str();
    }
};

// The library's message for a target it refuses (empty if it takes it).
std::string library_refusal(const Words& w, const Scene& part) {
    try {
        const DesignTarget t = parse_design_target(w.kind, w.values, part.part.point);
        validate_design_target(t, part, DesignOptions{});
    } catch (const std::invalid_argument& e) {
        return e.what();
    }
    return "";
}

struct Run {
    int code;
    std::string err;
};
Run cli_design(const std::string& scene, const Words& w) {
    const fs::path dir = fs::temp_directory_path() / ("plate_target_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const std::string cmd = std::string(PLATE_EXE) + " design " + kScenes + scene + ".json --target " + w.text() + " --out " +
                            (dir / "x.json").string() + " > /dev/null 2> " + (dir / "err").string();
    const int st = std::system(cmd.c_str());
    std::ifstream in(dir / "err");
    std::stringstream e;
    e << in.rdbuf();
    const bool wrote = fs::exists(dir / "x.json");
    fs::remove_all(dir);
    return {WIFEXITED(st) && !wrote ? WEXITSTATUS(st) : -1, e.str()};
}

// A campaign over `scene` whose one computation is a design for the target `w`: the message its
// reader refuses it with (empty if it takes it).
std::string campaign_refusal(const std::string& scene, const Words& w) {
    nlohmann::json target = nlohmann::json::array({w.kind});
    for (double v : w.values) target.push_back(v);
    const nlohmann::json file = {
        {"name", "t"},
        {"scene", kScenes + scene + ".json"},
        {"sampling", "grid"},
        {"parameters", nlohmann::json::array({{{"name", "g"}, {"pointer", "/gravity"}, {"values", {9.81}}}})},
        {"compute", {{"design", {{"target", target}}}}}};
    try {
        (void)sweep::campaign_from_json(file, "t.json");
    } catch (const std::exception& e) {
        return e.what();
    }
    return "";
}

}   // namespace

TEST_CASE("A target the command line refuses, campaigns and the library refuse with the same message", "[design][target]") {
    // Wrong words (kind, count) and targets this part cannot have (outside the region, a line sink
    // for a rigid part, an orientation for a point part, a transport without velocity or with a turn).
    const std::vector<std::pair<std::string, Words>> bad = {
        {"fig1_point", {"wobble", {0, 0}}},
        {"fig1_point", {"sink", {0.02}}},
        {"fig4", {"fixed-point", {0.02, -0.01}}},
        {"fig1_point", {"line-sink", {0, 0}}},
        {"fig1_point", {"transport", {1, 2, 3, 4}}},
        {"fig1_point", {"sink", {0.2, 0}}},
        {"fig4", {"line-sink", {0, 0, 0.5}}},
        {"fig1_point", {"orient", {1.0}}},
        {"fig1_point", {"transport", {0, 0}}},
        {"fig1_point", {"transport", {0.01, 0, 0.5}}},
        {"fig4", {"orient", {}}},
        {"fig1_point", {"line-sink", {0, 0, 0.5, 1, 2, 3}}},
    };
    for (const auto& [scene, w] : bad) {
        INFO(scene << ": --target " << w.text());
        const std::string message = library_refusal(w, load_scene(kScenes + scene + ".json"));
        REQUIRE_FALSE(message.empty());
        const Run cli = cli_design(scene, w);
        CHECK(cli.code == 2);
        CHECK(cli.err.find(message) != std::string::npos);
        CHECK(campaign_refusal(scene, w).find(message) != std::string::npos);
    }
    // ... and good targets of every kind are taken by the library and campaigns alike (the CLI's and
    // Python's acceptance: their design tests).
    const std::vector<std::pair<std::string, Words>> good = {
        {"fig1_point", {"sink", {0.02, -0.01}}},
        {"fig4", {"fixed-point", {0.02, -0.01, 0.5}}},
        {"fig1_point", {"fixed-point", {0.02, -0.01}}},
        {"fig1_point", {"line-sink", {0, 0, 0.5}}},
        {"fig1_point", {"transport", {0.02, 0}}},
        {"foot", {"orient", {1.0}}},
        {"fig4", {"sink", {0.01, 0.01}}},
    };
    for (const auto& [scene, w] : good) {
        INFO(scene << ": --target " << w.text());
        CHECK(library_refusal(w, load_scene(kScenes + scene + ".json")).empty());
        CHECK(campaign_refusal(scene, w).empty());
    }
}

TEST_CASE("A target's words round-trip through the parser, every kind", "[design][target]") {
    for (const bool point : {true, false})
        for (const Words& w :
             std::vector<Words>{{"sink", {0.01, -0.02}},
                                {"fixed-point", point ? std::vector<double>{0.01, 0.02} : std::vector<double>{0.01, 0.02, 0.3}},
                                {"orient", {-1.25}},
                                {"line-sink", {0.01, 0, 0.6}},
                                {"transport", {0.02, -0.01}}}) {
            const DesignTarget t = parse_design_target(w.kind, w.values, point);
            CHECK(design_target_kind(t) == w.kind);
            CHECK(design_target_values(t, point) == w.values);
        }
}

TEST_CASE("A kind of target registered outside the library is parsed, dispatched, verified and reported", "[design][target]") {
    // "still X Y": keep a part resting at (X, Y). The design: a plate that does not move. Its
    // verification, a physical truth: on a level plate at rest a part released at rest stays where it
    // is (gravity is balanced by the normal forces, friction has nothing to hold), in full dynamics.
    const Scene part = load_scene(kScenes + "fig1_point.json");
    const Words still{"still", {0.01, -0.02}};
    CHECK_THROWS_WITH(parse_design_target(still.kind, still.values, true), Catch::Contains("still: expected sink X Y"));
    DesignTargetType type;
    type.name = "still";
    type.numbers = "X Y";
    type.count = 2;
    type.rigid = false;
    type.default_starts = 1;
    type.design = [](const Scene& p, const DesignTarget& t, const DesignOptions& opt, double T) {
        DesignSummary s;
        s.scene = p;
        s.scene.plate = PlateMotion{};
        s.scene.plate.T = T;
        const Vec3 q0(t.values[0], t.values[1], 0);
        const Trajectory tr = simulate(s.scene, Dynamics::Full, q0, Vec3::Zero(), opt.hold, opt.hold);
        s.held.x = q0[0];
        s.held.y = q0[1];
        s.held.seconds = opt.hold;
        s.held.end = tr.samples.back().q;
        s.held.end_distance = (s.held.end - q0).head<2>().norm();
        s.verified = s.held.end_distance <= opt.verify_distance;
        s.fixed_point = q0;
        return s;
    };
    register_design_target(type);
    CHECK_THROWS_WITH(register_design_target(type), Catch::Contains("exists"));
    CHECK(design_target_usage().find("still X Y") != std::string::npos);
    CHECK_THROWS_WITH(parse_design_target("still", {0.01}, true), Catch::Contains("still: expected still X Y"));
    const DesignTarget t = parse_design_target(still.kind, still.values, true);
    CHECK(t.kind == DesignTargetKind::Registered);
    CHECK_THROWS_WITH(validate_design_target(t, load_scene(kScenes + "fig4.json"), DesignOptions{}),
                      Catch::Contains("point parts only"));
    CHECK_THROWS_WITH(design(load_scene(kScenes + "fig4.json"), t, DesignOptions{}),   // (design() judges it too)
                      Catch::Contains("point parts only"));
    DesignOptions o;
    o.hold = 2;
    const DesignSummary d = design(part, t, o);
    CHECK(d.verified);
    CHECK(d.starts == 1);   // (the kind's own default)
    CHECK(d.held.end_distance < 1e-12);
    const nlohmann::json j = design_summary_json(d, part, t, o, "still.json");
    CHECK(j["target"]["kind"] == "still");
    CHECK(j["target"]["values"] == nlohmann::json({0.01, -0.02}));
    CHECK_FALSE(j["target"].contains("at"));
    CHECK(j["hold"]["end_distance"].get<double>() < 1e-12);
}
