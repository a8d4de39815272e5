// Profile likelihood (profile.hpp): where chi-square is nearly quadratic in a parameter the profile's
// interval is the linearised one; where a part never sticks its static coefficient's profile is flat
// from bound to bound (not identifiable); where the tracks see a static coefficient only as a threshold
// the profile interval runs to the bound (or covers the truth) where the linearised one is narrow.
#include "plate/identify.hpp"
#include "plate/observe.hpp"
#include "plate/profile.hpp"
#include "plate/scene_io.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace plate;

namespace {

Scene scene(const std::string& name) { return load_scene(PLATE_SOURCE_DIR "/scenes/" + name + ".json"); }

Camera strobe(double xy_mm, double theta_mrad, std::uint64_t seed) {
    Camera c;
    c.per_period = 1;
    c.phase = 0.25;
    c.noise_xy_mm = xy_mm;
    c.noise_theta_mrad = theta_mrad;
    c.seed = seed;
    return c;
}

Track filmed(const Scene& nominal, const std::vector<std::string>& names, const std::vector<double>& truth, const Camera& cam,
             const Vec3& q0, double duration) {
    Track tr = observe(apply_parameters(nominal, names, truth), cam, Dynamics::Full, q0, Vec3::Zero(), duration);
    tr.source = "track.csv";
    return tr;
}

IdentifyOptions options(const std::vector<std::string>& params) {
    IdentifyOptions o;
    o.params = params;
    o.starts = 2;
    o.threads = 1;
    return o;
}

}   // namespace

TEST_CASE("a point part's kinetic friction: the profile interval is the linearised one", "[identify][profile]") {
    const Scene nominal = scene("fig1_point");
    const Track tr = filmed(nominal, {"mu_k"}, {0.27}, strobe(0.1, 0, 3), Vec3(0.01, -0.02, 0), 5.0);
    const IdentifyOptions o = options({"mu_k"});
    const IdentifySummary s = identify(nominal, {tr}, o);
    const ProfileSummary p = profile_likelihood(nominal, {tr}, o, s, ProfileOptions{});
    INFO(identify_json(s, o, p, ProfileOptions{}).dump(2));
    REQUIRE(p.profiles.size() == 1u);
    const ParameterProfile& m = p.profiles[0];
    CHECK(m.lo_end == ProfileEnd::Crossed);
    CHECK(m.hi_end == ProfileEnd::Crossed);
    const double half = 0.5 * (s.params[0].hi - s.params[0].lo);
    CHECK(std::abs(m.lo - s.params[0].lo) < 0.04 * half);
    CHECK(std::abs(m.hi - s.params[0].hi) < 0.04 * half);
    CHECK_FALSE(m.interval_is_profile);
}

TEST_CASE("a part that never sticks: its static coefficient's profile is flat from bound to bound", "[identify][profile]") {
    Scene nominal = scene("fig1_point");
    nominal.plate.harmonics[0].phase = kPi / 2;
    const Track tr = filmed(nominal, {"mu_k", "mu_s"}, {0.27, 0.33}, strobe(0.1, 0, 5), Vec3(0.005, -0.02, 0), 3.0);
    const IdentifyOptions o = options({"mu_k", "mu_s"});
    const IdentifySummary s = identify(nominal, {tr}, o);
    const ProfileSummary p = profile_likelihood(nominal, {tr}, o, s, ProfileOptions{});
    INFO(identify_json(s, o, p, ProfileOptions{}).dump(2));
    REQUIRE(p.profiles.size() == 2u);
    const ParameterProfile& m = p.profiles[1];
    CHECK(m.lo_end == ProfileEnd::AtBound);
    CHECK(m.hi_end == ProfileEnd::AtBound);
    CHECK_FALSE(m.identifiable);
    for (const ProfilePoint& q : m.points) CHECK(std::abs(q.dchi2) < 0.01);
    CHECK(identify_json(s, o, p, ProfileOptions{})["parameters"][1]["interval95"].is_null());
    CHECK(p.profiles[0].lo_end == ProfileEnd::Crossed);
    CHECK(p.profiles[0].hi_end == ProfileEnd::Crossed);
}

TEST_CASE("a static coefficient seen only through a brief stick: the profile interval runs to the bound and covers the truth",
          "[identify][profile]") {
    Scene nominal = scene("fig1_point");
    nominal.part.mu_static = Vec3::Constant(0.36);
    const Track tr = filmed(nominal, {"mu_k", "mu_s"}, {0.27, 0.33}, strobe(0.1, 0, 4), Vec3(-0.03, 0.01, 0), 5.0);
    const IdentifyOptions o = options({"mu_k", "mu_s"});
    const IdentifySummary s = identify(nominal, {tr}, o);
    const ProfileSummary p = profile_likelihood(nominal, {tr}, o, s, ProfileOptions{});
    INFO(identify_json(s, o, p, ProfileOptions{}).dump(2));
    REQUIRE(p.profiles.size() == 2u);
    const ParameterProfile& m = p.profiles[1];
    REQUIRE(s.params[1].identifiable);
    CHECK(s.params[1].lo < m.bound_lo);   // the linearised interval runs below static = kinetic
    CHECK(m.lo_end == ProfileEnd::AtBound);
    CHECK(m.hi_end == ProfileEnd::Crossed);
    CHECK(m.lo < 0.33);
    CHECK(0.33 < m.hi);
}
