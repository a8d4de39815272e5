// plate robustness end to end: its JSON (units in the keys, shares that add up, the same result on
// one thread or two), and bad input refused with exit code 2, the file or option named, no output.
#include "cli_run.hpp"

#include <nlohmann/json.hpp>

#include <catch2/catch.hpp>

#include <string>

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
