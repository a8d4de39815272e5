// plate control's command line (issue 53): bad inputs exit 2 naming the file and the field, nothing
// written; a good run writes its rows and its summary.
#include <catch2/catch.hpp>

#include "cli_run.hpp"

using Catch::Matchers::Contains;

namespace {

std::string write(const std::string& name, const std::string& text) {
    const fs::path p = tmpdir() / name;
    std::ofstream(p) << text;
    return p.string();
}

// A one-motion library of the shipped e_fast.json with `from` replaced by `to` in its scene.
std::string library_changing(const std::string& from, const std::string& to) {
    std::string scene = slurp(kScenes + "control/fig1_point/e_fast.json");
    scene.replace(scene.find(from), from.size(), to);
    write("e_changed.json", scene);
    return write("lib.json", R"({"motions": [{"name": "e", "scene": "e_changed.json"}]})");
}

const std::string kBase = "control " + kScenes + "fig1_point.json --goal 0.02 -0.01 --policy library --time 0.5 ";
const std::string kLibrary = "--library " + kScenes + "control/fig1_point/library.json ";

}   // namespace

TEST_CASE("plate control: bad input files exit 2 naming the file and the field, and write nothing", "[control][cli]") {
    const std::string out = (tmpdir() / "run.csv").string();
    fs::remove(out);
    SECTION("a truth with an unknown field") {
        const std::string t = write("truth.json", R"({"friction_scale": 0.8, "tracking_error": 0.03})");
        const Run r = run(kBase + kLibrary + "--truth " + t + " --out " + out);
        CHECK(r.code == 2);
        CHECK_THAT(r.err, Contains(t + ": tracking_error: unknown field"));
    }
    SECTION("a truth's recorded cycles: a missing file, another period, a motion named twice, no harmonics") {
        const std::string cycle = write("rec.csv",
                                        "t [s],x [m/s^2],y [m/s^2],z [m/s^2],rx [rad/s^2],ry [rad/s^2],rz [rad/s^2]\n"
                                        "0,1,0,0,0,0,0\n0.01,0,0,0,0,0,0\n0.02,-1,0,0,0,0,0\n0.03,0,0,0,0,0,0\n");
        const std::string e_fast = kScenes + "control/fig1_point/e_fast.json";
        const auto entry = [&](const std::string& cyc, const std::string& harmonics) {
            return R"({"commanded": ")" + e_fast + R"(", "cycle": ")" + cyc + R"(", "harmonics": )" + harmonics + "}";
        };
        const std::pair<std::string, std::string> cases[] = {
            {R"({"measured": [)" + entry(cycle + ".gone", "1") + "]}", ": measured[0].cycle: " + cycle + ".gone: cannot open"},
            {R"({"measured": [)" + entry(cycle, "1") + "]}",
             ": measured[0].cycle: " + cycle + ": period 0.04 s, not the commanded 0.05 s"},
            {R"({"measured": [)" + entry(cycle, "0") + "]}", ": measured[0].harmonics: expected a whole number from 1 to 1000"},
            {R"({"measured": [{"commanded": "e.json"}]})", ": measured[0].cycle: missing required field"},
        };
        for (const auto& [text, message] : cases) {
            const std::string t = write("truth.json", text);
            const Run r = run(kBase + kLibrary + "--truth " + t + " --out " + out);
            CHECK(r.code == 2);
            CHECK_THAT(r.err, Contains(t + message));
            CHECK_FALSE(fs::exists(out));
        }
        // (the same commanded motion twice -- the second a copy under another name: matched by its
        // harmonics, not its file -- each with a good cycle of its period)
        std::string good = "t [s],x [m/s^2],y [m/s^2],z [m/s^2],rx [rad/s^2],ry [rad/s^2],rz [rad/s^2]\n";
        for (int i = 0; i < 5; ++i) good += std::to_string(0.01 * i) + ",1,0,0,0,0,0\n";
        const std::string g = write("good.csv", good);
        const std::string copy = write("e_fast_copy.json", slurp(e_fast));
        std::string twice = entry(g, "1");
        twice.replace(twice.find(e_fast), e_fast.size(), copy);
        const std::string t = write("truth.json", R"({"measured": [)" + entry(g, "1") + "," + twice + "]}");
        const Run r = run(kBase + kLibrary + "--truth " + t + " --out " + out);
        CHECK(r.code == 2);
        CHECK_THAT(r.err, Contains(t + ": measured[1].commanded: " + copy + ": the same motion as " + e_fast));
    }
    SECTION("a truth's uncertainty spec with a bad spread") {
        const std::string t = write("truth.json", R"({"uncertainty": {"seed": 1, "amplitude": {"spread": -1}}})");
        const Run r = run(kBase + kLibrary + "--truth " + t + " --out " + out);
        CHECK(r.code == 2);
        CHECK_THAT(r.err, Contains(t + ": uncertainty: amplitude"));
    }
    SECTION("a library motion of another period") {
        const std::string lib = library_changing("\"period\": 0.05", "\"period\": 0.04");
        const Run r = run(kBase + "--library " + lib + " --out " + out);
        CHECK(r.code == 2);
        CHECK_THAT(r.err, Contains(lib + ": motions[0].scene: "));
        CHECK_THAT(r.err, Contains("every motion must share the period"));
    }
    SECTION("a library motion with another part") {
        const std::string lib = library_changing("\"friction\": 0.3", "\"friction\": 0.4");
        const Run r = run(kBase + "--library " + lib + " --out " + out);
        CHECK(r.code == 2);
        CHECK_THAT(r.err, Contains(lib + ": motions[0].scene: "));
        CHECK_THAT(r.err, Contains("its part differs"));
    }
    SECTION("a camera that films more than once a period") {
        const std::string c = write("cam.json", R"({"rate_hz": 200, "noise": {"xy_mm": 0.1}, "frame": "world"})");
        const Run r = run(kBase + kLibrary + "--camera " + c + " --out " + out);
        CHECK(r.code == 2);
        CHECK_THAT(r.err, Contains(c + ": stroboscopic.per_period"));
    }
    SECTION(
        "the mpc policy over more sequences than it searches, a policy not known, the mpc's options on the library "
        "policy") {
        Run r = run("control " PLATE_SOURCE_DIR
                    "/scenes/fig4.json --goal 0.02 -0.01 0.5 --policy mpc --horizon 5 --time 1 --library " PLATE_SOURCE_DIR
                    "/scenes/control/fig4/library.json --out " +
                    out);
        CHECK(r.code == 2);   // (fig4's 31 motions over 5 periods: 28629151 sequences)
        CHECK_THAT(r.err, Contains("31 motions over a horizon of 5 periods are more than 1000000 sequences"));
        CHECK_FALSE(fs::exists(out));
        std::string base = kBase;
        base.replace(base.find("--policy library"), 16, "--policy greedy");
        r = run(base + kLibrary + "--out " + out);
        CHECK(r.code == 2);
        CHECK_THAT(r.err, Contains("--policy: expected library or mpc"));
        r = run(kBase + kLibrary + "--switch-cost 0.001 --out " + out);
        CHECK(r.code == 2);
        CHECK_THAT(r.err, Contains("--switch-cost and --no-correction are the mpc policy's"));
    }
    CHECK_FALSE(fs::exists(out));
}

TEST_CASE("plate control: a run writes a row per period with units and its summary", "[control][cli]") {
    const std::string out = (tmpdir() / "run.csv").string();
    const Run r = run(kBase + kLibrary + "--start 0.019 -0.01 --out " + out);
    CHECK(r.code == 0);
    CHECK_THAT(r.out, Contains("\"reached\": true"));
    const std::string csv = slurp(out);
    CHECK(csv.rfind("t [s],obs_s_x [m],obs_s_y [m],x [m],y [m],motion,decision [s]\n", 0) == 0);
    CHECK(std::count(csv.begin(), csv.end(), '\n') == 1 + 10 + 1);   // header, 10 periods, the end
}

TEST_CASE("plate control --parts: bad parts exit 2 naming the file and the field, and a run writes each part's columns",
          "[control][cli][multi]") {
    const std::string out = (tmpdir() / "multi.csv").string();
    fs::remove(out);
    const std::string base = "control " + kScenes + "fig1_point.json --time 0.5 " + kLibrary;
    const std::string bad = write("parts_bad.json", R"({"parts": [{"goal": [0.02, -0.01]}, {"goal": [0, 0], "weight": 0}]})");
    Run r = run(base + "--policy library --parts " + bad + " --out " + out);
    CHECK(r.code == 2);
    CHECK_THAT(r.err, Contains("parts_bad.json: parts[1].weight"));
    const std::string parts =
        write("parts.json", R"({"parts": [{"goal": [0.02, -0.01], "start": [0.019, -0.01]}, {"goal": [0, 0.0005]}]})");
    r = run(base + "--policy library --parts " + parts + " --goal 0 0 --out " + out);
    CHECK(r.code == 2);
    CHECK_THAT(r.err, Contains("--parts"));
    r = run(base + "--parts " + parts + " --policy mpc --out " + out);
    CHECK(r.code == 2);
    CHECK_THAT(r.err, Contains("--parts: the library policy"));
    CHECK_FALSE(fs::exists(out));
    r = run(base + "--policy library --parts " + parts + " --out " + out);
    CHECK(r.code == 0);   // both start within 1 mm of their goals, on a still plate
    CHECK_THAT(r.out, Contains("\"parts\": ["));
    const std::string csv = slurp(out);
    CHECK(csv.rfind("t [s],obs_s_x_1 [m],obs_s_y_1 [m],x_1 [m],y_1 [m],obs_s_x_2 [m],obs_s_y_2 [m],x_2 [m],y_2 [m],motion,"
                    "decision [s]\n",
                    0) == 0);
    CHECK(std::count(csv.begin(), csv.end(), '\n') == 1 + 10 + 1);
}
