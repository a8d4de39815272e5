// Profile likelihood (profile.hpp): where chi-square is nearly quadratic in a parameter the profile's
// interval is the linearised one; where a part never sticks its static coefficient's profile is flat
// from bound to bound (not identifiable); where the tracks see a static coefficient only as a threshold
// the profile interval runs to the bound (or covers the truth) where the linearised one is narrow.
#include "identify_fixtures.hpp"
#include "plate/identify.hpp"
#include "plate/observe.hpp"
#include "plate/profile.hpp"
#include "plate/scene_io.hpp"

#include "cli_run.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>

using namespace plate;
using namespace plate::test;

namespace {

// The fit of `names` to one track and every parameter's profile; the JSON shown on failure.
struct Profiled {
    IdentifySummary s;
    ProfileSummary p;
    nlohmann::json json;
};

Profiled fit_and_profile(const Scene& nominal, const Track& tr, const std::vector<std::string>& names) {
    const IdentifyOptions o = options(names);
    Profiled r;
    r.s = identify(nominal, {tr}, o);
    r.p = profile_likelihood(nominal, {tr}, o, r.s, ProfileOptions{});
    r.json = identify_json(r.s, o, r.p, ProfileOptions{});
    return r;
}

}   // namespace

// fig1_point's part sliding throughout (as test_identify.cpp's first case): chi-square is nearly quadratic
// in mu_k (measured: the profile at -+1 linearised sd is 1.012 and 0.992, 1 for a parabola), and the
// profile's ends, interpolated on sqrt(chi2 - chi2_min) (exact for a parabola) and refined, lie 0.012 of
// the linearised half-width from the linearised ends; 0.04 allowed. Not re-minimising over the track's
// start puts them 0.49 of the half-width inside.
TEST_CASE("a point part's kinetic friction: the profile interval is the linearised one", "[identify][profile]") {
    const Scene nominal = scene("fig1_point");
    const Track tr = filmed(nominal, {"mu_k"}, {0.27}, strobe(0.1, 0, 3), Vec3(0.01, -0.02, 0), 5.0);
    const auto [s, p, json] = fit_and_profile(nominal, tr, {"mu_k"});
    INFO(json.dump(2));
    REQUIRE(p.profiles.size() == 1u);
    const ParameterProfile& m = p.profiles[0];
    CHECK(m.lo_end == ProfileEnd::Crossed);
    CHECK(m.hi_end == ProfileEnd::Crossed);
    const double half = 0.5 * (s.params[0].hi - s.params[0].lo);
    CHECK(std::abs(m.lo - s.params[0].lo) < 0.04 * half);
    CHECK(std::abs(m.hi - s.params[0].hi) < 0.04 * half);
    CHECK_FALSE(m.interval_is_profile);
}

// The same fit's interval checked at its ends: the chi-square along the quadratic model's profile path (the
// track's start moved by its regression on mu_k) at estimate -+ 1.96 sd rises by 3.84 for a parabola; the
// profile at -+1 sd above (1.012, 0.992) says it is one within about 1 %, so 3.84 within 0.2 (5 %).
// Measured 3.94 and 3.76. Seen failing: the start left where the fit put it (the path then climbs as the
// fixed-start slice does: 15.0 and 14.4, "unconfirmed"), and the ends taken at -+1 sd (1.01 and 0.99,
// "too narrow").
TEST_CASE("a point part's kinetic friction: its interval's ends lie 3.84 above the minimum, the check holds",
          "[identify][profile]") {
    const Scene nominal = scene("fig1_point");
    const Track tr = filmed(nominal, {"mu_k"}, {0.27}, strobe(0.1, 0, 3), Vec3(0.01, -0.02, 0), 5.0);
    const IdentifySummary s = identify(nominal, {tr}, options({"mu_k"}));
    const nlohmann::json j = identify_json(s, options({"mu_k"}));
    INFO(j.dump(2));
    const FittedParameter& p = s.params[0];
    CHECK(std::abs(p.dchi2_lo - 3.84) < 0.2);
    CHECK(std::abs(p.dchi2_hi - 3.84) < 0.2);
    CHECK(p.linearity == Linearity::Holds);
    CHECK(j["parameters"][0]["interval95_check"]["verdict"] == "holds");
    CHECK(j["parameters"][0]["interval95_check"]["dchi2_at_ends"][0] == p.dchi2_lo);
}

// Hops (IdentifyOptions::hops): a search cut short (one Levenberg-Marquardt iteration from 0.30 for the truth
// 0.27) leaves the minimum 1.96 sd or more away, so an end of mu_k's path fits better; the search goes on
// from there until no end does, and reaches the chi-square of the search left to converge. Measured: cut
// short 415.2 (mu_k 0.2895), after 5 hops 185.87 (0.2675), converged 185.79 (0.2677). Seen failing with
// the hops never taken (0 hops, 415.2). The wide steps (IdentifyOptions::wide_iterations) are left out
// for this: they (and the one fine iteration after them) take the search cut short on to the converged
// chi-square themselves, their drop the difference from the search without them (seen failing with their
// steps never kept).
TEST_CASE("a search cut short goes on from the better end of its interval's check", "[identify][profile]") {
    const Scene nominal = scene("fig1_point");
    const Track tr = filmed(nominal, {"mu_k"}, {0.27}, strobe(0.1, 0, 3), Vec3(0.01, -0.02, 0), 5.0);
    IdentifyOptions o = options({"mu_k"});
    o.starts = 1;
    o.segment_seconds = 0;
    const IdentifySummary full = identify(nominal, {tr}, o);
    o.max_iterations = 1;
    o.fit_starts_first = false;
    o.hops = 0;
    const IdentifySummary widened = identify(nominal, {tr}, o);
    CHECK(widened.wide_iterations >= 1);
    CHECK(widened.chi2 < full.chi2 + 1);
    o.wide_iterations = 0;
    const IdentifySummary cut = identify(nominal, {tr}, o);
    CHECK(widened.wide_chi2_drop == Approx(cut.chi2 - widened.chi2).epsilon(1e-9));
    o.hops = 20;
    const IdentifySummary hopped = identify(nominal, {tr}, o);
    INFO("chi2: full " << full.chi2 << ", cut " << cut.chi2 << ", hopped " << hopped.chi2 << " after " << hopped.hops << " hops");
    INFO("mu_k: full " << full.params[0].estimate << ", cut " << cut.params[0].estimate << ", hopped "
                       << hopped.params[0].estimate);
    CHECK(full.hops == 0);
    CHECK(cut.hops == 0);
    CHECK(cut.chi2 > full.chi2 + 10);
    CHECK(hopped.hops >= 1);
    CHECK(hopped.chi2 < full.chi2 + 1);
}

// fig1_point's plate started at its peak, 20 m/s^2 against mu_s g <= 14.7 m/s^2: the part at rest breaks away
// at once and never sticks (test_identify.cpp), so no value of mu_s from its kinetic base to 1.5 changes a
// frame: the profile is flat (chi-square unchanged to 0.01) and runs to both bounds, while mu_k's crosses.
TEST_CASE("a part that never sticks: its static coefficient's profile is flat from bound to bound", "[identify][profile]") {
    Scene nominal = scene("fig1_point");
    nominal.plate.harmonics[0].phase = kPi / 2;
    const Track tr = filmed(nominal, {"mu_k", "mu_s"}, {0.27, 0.33}, strobe(0.1, 0, 5), Vec3(0.005, -0.02, 0), 3.0);
    const auto [s, p, json] = fit_and_profile(nominal, tr, {"mu_k", "mu_s"});
    INFO(json.dump(2));
    REQUIRE(p.profiles.size() == 2u);
    const ParameterProfile& m = p.profiles[1];
    CHECK(m.lo_end == ProfileEnd::AtBound);
    CHECK(m.hi_end == ProfileEnd::AtBound);
    CHECK_FALSE(m.identifiable);
    for (const ProfilePoint& q : m.points) CHECK(std::abs(q.dchi2) < 0.01);
    CHECK(json["parameters"][1]["interval95"].is_null());
    CHECK(p.profiles[0].lo_end == ProfileEnd::Crossed);
    CHECK(p.profiles[0].hi_end == ProfileEnd::Crossed);
}

// The same part under fig1's own plate (which starts at rest: the part sticks briefly before it breaks away),
// filmed at kinetic 0.27 and static 0.33 (seed 4, from (-30, 10) mm): mu_s is seen only through the moment
// of break-away, a threshold. Measured: estimate 0.445, linearised interval -+0.86 (running below its kinetic
// base 0.2695, where no static coefficient can be); the profile stays within 0.13 of its minimum down to
// that base and crosses 3.84 near 0.83 -- one-sided, covering the truth.
TEST_CASE("a static coefficient seen only through a brief stick: the profile interval runs to the bound and covers the truth",
          "[identify][profile]") {
    Scene nominal = scene("fig1_point");
    nominal.part.mu_static = Vec3::Constant(0.36);
    const Track tr = filmed(nominal, {"mu_k", "mu_s"}, {0.27, 0.33}, strobe(0.1, 0, 4), Vec3(-0.03, 0.01, 0), 5.0);
    const auto [s, p, json] = fit_and_profile(nominal, tr, {"mu_k", "mu_s"});
    INFO(json.dump(2));
    REQUIRE(p.profiles.size() == 2u);
    const ParameterProfile& m = p.profiles[1];
    REQUIRE(s.params[1].identifiable);
    CHECK(s.params[1].lo < m.bound_lo);   // the linearised interval runs below static = kinetic
    CHECK(m.lo_end == ProfileEnd::AtBound);
    CHECK(m.hi_end == ProfileEnd::Crossed);
    CHECK(m.lo < 0.33);
    CHECK(0.33 < m.hi);
}

// plate identify --profile writes each profile with its units into the JSON, and the reported interval
// beside the linearised one; a name not fitted, or a profile option without --profile, exits 2 naming it.
TEST_CASE("plate identify --profile writes the profiles, and a name not fitted exits 2", "[identify][profile][cli]") {
    const fs::path cam = tmpdir() / "camera.json", track = tmpdir() / "track.csv", out = tmpdir() / "est.json";
    std::ofstream(cam) << R"({"stroboscopic": {"phase": 0.25}, "noise": {"xy_mm": 0.1}, "seed": 1, "frame": "plate"})";
    REQUIRE(run("simulate " + kScenes + "fig1_point.json --dynamics full --from 0.01 -0.02 --time 2 --observe " + cam.string() +
                " --out " + track.string())
                .code == 0);
    const std::string head = "identify " + kScenes + "fig1_point.json --tracks " + track.string() + " --params mu_k";
    const Run ok = run(head + " --profile all --out " + out.string());
    REQUIRE(ok.code == 0);
    std::ifstream in(out);
    const nlohmann::json j = nlohmann::json::parse(in);
    REQUIRE(j["profiles"].size() == 1u);
    CHECK(j["profiles"][0]["points_columns"][0] == "value [1]");
    CHECK(j["profiles"][0]["interval95"]["lo_end"] == "crossed");
    CHECK(j["profiles"][0]["points"].size() >= 5u);
    CHECK(j["parameters"][0]["interval_method"] == "linearised");
    CHECK(j["parameters"][0]["interval95"] == j["parameters"][0]["interval95_linearised"]);
    const Run bad = run(head + " --profile mu_s --out " + out.string());
    CHECK(bad.code == 2);
    CHECK(bad.err.find("--profile: mu_s is not among --params") != std::string::npos);
    const Run lone = run(head + " --profile-steps 3 --out " + out.string());
    CHECK(lone.code == 2);
    CHECK(lone.err.find("--profile-steps: only with --profile") != std::string::npos);
}
