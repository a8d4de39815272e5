// plate robustness end to end: its JSON (units in the keys, shares that add up, the same result on
// one thread or two), and bad input refused with exit code 2, the file or option named, no output.
#include "cli_run.hpp"

#include "plate/scene_io.hpp"

#include <nlohmann/json.hpp>

#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

TEST_CASE("plate robustness writes outcome shares, the spread and the sensitivities as JSON", "[cli][robustness]") {
    const std::string scene = kScenes + "designs/fig4_fixed_point.json", spec = kScenes + "uncertainty/ppod.json";
    const fs::path out1 = tmpdir() / "rob1.json", out2 = tmpdir() / "rob2.json";
    const std::string args =
        "robustness " + scene + " --uncertainty " + spec + " --draws 6 --starts 2 --full-draws 1 --horizon 20";
    const Run r1 = run(args + " --threads 1 --out " + out1.string());
    const Run r2 = run(args + " --threads 2 --out " + out2.string());
    INFO(r1.err);
    REQUIRE(r1.code == 0);
    REQUIRE(r2.code == 0);
    CHECK(r1.err.find("unique in") != std::string::npos);
    auto j1 = nlohmann::json::parse(slurp(out1)), j2 = nlohmann::json::parse(slurp(out2));
    int total = 0;
    double share = 0;
    for (const auto& [name, o] : j1["outcomes"].items()) {
        total += o["count"].get<int>();
        share += o["probability"].get<double>();
        CHECK(o["interval95"][0].get<double>() <= o["probability"].get<double>());
        CHECK(o["probability"].get<double>() <= o["interval95"][1].get<double>());
    }
    CHECK(total == 6);
    CHECK(share == Approx(1).epsilon(1e-12));
    CHECK(j1["per_draw"].size() == 6);
    CHECK(j1["per_draw"][0]["arrival_full_s"].size() == 2);   // the first draw, in full dynamics
    CHECK_FALSE(j1["per_draw"][1].contains("arrival_full_s"));
    CHECK(j1["spread"].contains("radius95_mm"));
    CHECK(j1["sensitivity"]["parameters"].size() > 10);
    CHECK(j1["target_m_m_rad"].size() == 3);
    // One thread or two: the same draws, the same numbers (the run's seconds aside).
    j1.erase("seconds");
    j2.erase("seconds");
    j1["sensitivity"].erase("seconds");
    j2["sensitivity"].erase("seconds");
    CHECK(j1 == j2);
}

TEST_CASE("plate robustness: bad input exits 2 naming the file or option, and writes nothing", "[cli][robustness][input]") {
    const std::string scene = kScenes + "designs/fig4_fixed_point.json", spec = kScenes + "uncertainty/ppod.json";
    const fs::path bad = tmpdir() / "bad_spec.json", out = tmpdir() / "never.json";
    std::ofstream(bad) << R"({"seed": 1, "friction": {"spread": -0.1}})";
    const std::pair<std::string, std::string> cases[] = {
        {"robustness " + scene, "missing --uncertainty"},
        {"robustness " + scene + " --uncertainty " + bad.string(), bad.string() + ": friction.spread: expected a number from 0"},
        {"robustness " + scene + " --uncertainty /nonexistent.json", "/nonexistent.json: cannot open"},
        {"robustness " + scene + " --uncertainty " + spec + " --draws 0", "--draws"},
        {"robustness " + scene + " --uncertainty " + spec + " --horizon -1", "--horizon"},
        {"robustness " + scene + " --uncertainty " + spec + " --measured x.csv", "--measured FILE and --harmonics N go together"},
        {"robustness " + kScenes + "fig4.json --uncertainty " + spec + " --draws 1", "name the fixed point to follow"},
    };
    for (const auto& [args, expect] : cases) {
        fs::remove(out);
        const Run r = run(args + " --out " + out.string());
        INFO(args << "\n" << r.err);
        CHECK(r.code == 2);
        CHECK(r.err.find(expect) != std::string::npos);
        CHECK_FALSE(fs::exists(out));
    }
}

namespace {

// One period of `sc`'s plate acceleration sampled at M points, in the measured-cycle CSV form
// (columns permuted by `order`: the identity writes x y z rx ry rz in place).
std::string measured_csv(const plate::Scene& sc, int M, const std::array<int, 6>& order = {0, 1, 2, 3, 4, 5}) {
    std::ostringstream o;
    o.precision(17);
    o << "t [s],x [m/s^2],y [m/s^2],z [m/s^2],rx [rad/s^2],ry [rad/s^2],rz [rad/s^2]\n";
    for (int k = 0; k < M; ++k) {
        const double t = sc.plate.T * k / M;
        plate::Vec3 a, w;
        sc.plate.acceleration(t, a, w);
        const double u[6] = {a[0], a[1], a[2], w[0], w[1], w[2]};
        o << t;
        for (int c : order) o << ',' << u[c];
        o << '\n';
    }
    return o.str();
}

}   // namespace

TEST_CASE("plate --measured: a recorded cycle of a scene's own plate gives its twist, a mislabelled one does not",
          "[cli][measured]") {
    const std::string fig4 = kScenes + "fig4.json";
    const plate::Scene sc = plate::load_scene(fig4);
    const fs::path good = tmpdir() / "fig4_cycle.csv", swapped = tmpdir() / "fig4_xy_swapped.csv";
    std::ofstream(good) << measured_csv(sc, 64);
    std::ofstream(swapped) << measured_csv(sc, 64, {1, 0, 2, 3, 4, 5});
    auto twist = [](const Run& r) {
        INFO(r.err);
        REQUIRE(r.code == 0);
        const auto j = nlohmann::json::parse(r.out)["twist"];
        return std::vector<double>{j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
    };
    const std::string at = " --at 0.01 -0.02 0.5";
    const auto nominal = twist(run("twist " + fig4 + at));
    // fig4 commands n = 1 only; harmonics 1..3 from 64 samples recover it to rounding (the DFT's
    // test: 1e-15), and the cycle converges to the same twist within its tolerance (1e-7 v_ref).
    const auto measured = twist(run("twist " + fig4 + at + " --measured " + good.string() + " --harmonics 3"));
    for (int c = 0; c < 3; ++c) CHECK(measured[c] == Approx(nominal[c]).margin(1e-6));
    const auto wrong = twist(run("twist " + fig4 + at + " --measured " + swapped.string() + " --harmonics 3"));
    CHECK(std::abs(wrong[0] - nominal[0]) + std::abs(wrong[1] - nominal[1]) > 1e-3);
    // Every command that takes a scene takes the cycle, and refuses it alone or broken, exit 2.
    const fs::path broken = tmpdir() / "broken_cycle.csv";
    std::string text = measured_csv(sc, 64);
    const std::size_t row2 = text.find('\n', text.find('\n') + 1) + 1;   // the second sample's row: line 3
    text.replace(row2, 1, "x");
    std::ofstream(broken) << text;
    const std::pair<std::string, std::string> cases[] = {
        {"twist " + fig4 + at + " --measured " + good.string(), "--measured FILE and --harmonics N go together"},
        {"field " + fig4 + " --grid 2 --harmonics 3", "--measured FILE and --harmonics N go together"},
        {"fixed-points " + fig4 + " --grid 2 --measured /nonexistent.csv --harmonics 3", "/nonexistent.csv: cannot open"},
        {"simulate " + fig4 + " --dynamics u --start 0 0 0 --time 0.1 --measured " + broken.string() + " --harmonics 3",
         broken.string() + ":3:1"},
        {"twist " + fig4 + at + " --measured " + good.string() + " --harmonics 32", "64 samples resolve harmonics up to n = 31"},
    };
    for (const auto& [args, expect] : cases) {
        const Run r = run(args);
        INFO(args << "\n" << r.err);
        CHECK(r.code == 2);
        CHECK(r.err.find(expect) != std::string::npos);
    }
}

TEST_CASE(
    "plate robustness --write-draws: each drawn scene, run through plate fixed-points, has the fixed point the "
    "robustness run reported",
    "[cli][robustness]") {
    const std::string scene = kScenes + "designs/fig4_fixed_point.json", spec = kScenes + "uncertainty/ppod.json";
    const fs::path dir = tmpdir() / "draws", out = tmpdir() / "rob_draws.json";
    fs::remove_all(dir);
    const std::string args = "robustness " + scene + " --uncertainty " + spec + " --draws 3 --starts 0 --full-draws 0 --out ";
    const Run r = run(args + out.string() + " --write-draws " + dir.string());
    INFO(r.err);
    REQUIRE(r.code == 0);
    const auto j = nlohmann::json::parse(slurp(out));
    for (int i = 0; i < 3; ++i) {
        const fs::path f = dir / ("draw_" + std::to_string(i) + ".json");
        REQUIRE(fs::exists(f));
        const Run fp = run("fixed-points " + f.string() + " --threads 2");
        REQUIRE(fp.code == 0);
        const auto points = nlohmann::json::parse(fp.out)["points"];
        const auto& d = j["per_draw"][i];
        INFO("draw " << i << ": " << d.dump());
        if (!d.contains("fixed_point_m_m_rad")) continue;   // (no stable point at the target in this draw)
        // The same field and refinement (the same cycle options, any threads): the same point, every digit.
        bool found = false;
        for (const auto& p : points) found = found || (p["stability"] == "stable" && p["at"] == d["fixed_point_m_m_rad"]);
        CHECK(found);
    }
    // A folder that exists is not overwritten: exit 2 before any work.
    const Run again = run(args + out.string() + " --write-draws " + dir.string());
    CHECK(again.code == 2);
    CHECK(again.err.find("exists") != std::string::npos);
}
