// The `mpc` policy (control.hpp, issue 53): its online correction recovers a gain and a drift the model
// does not have, exactly on exact data (a rigid part's angle too); on the test plate it brings the
// point part in as the target asks; options it cannot meet are refused by name.
#include "plate/control.hpp"
#include "plate/scene_io.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

using namespace plate;
using Catch::Matchers::Contains;
using Catch::Matchers::WithinAbs;

namespace {

const std::string kScenes = PLATE_SOURCE_DIR "/scenes/";

// A model whose motions are uniform fields given by hand: the still plate and transports at 0.02 m/s
// east, north and west (the plates themselves are not read by the policy).
ControlModel hand_model() {
    ControlModel m;
    m.nominal = load_scene(kScenes + "fig1_point.json");
    m.library.names = {"still", "east", "north", "west"};
    m.library.motions.assign(4, m.nominal.plate);
    m.library.still = 0;
    for (const Vec3& xi : {Vec3(0, 0, 0), Vec3(0.02, 0, 0), Vec3(0, 0.02, 0), Vec3(-0.02, 0, 0)}) {
        MotionField f;
        f.uniform = true;
        f.twist = {xi};
        m.fields.push_back(f);
    }
    return m;
}

// fig4's part with hand-given uniform fields: the still plate, (with_east) a transport east at 0.02 m/s,
// and a turn at 0.5 rad/s; and its goal (0.01, 0.006, 0.4), theta weighted by rho.
ControlModel rigid_hand_model(bool with_east) {
    ControlModel m = hand_model();
    m.nominal = load_scene(kScenes + "fig4.json");
    m.library.names = with_east ? std::vector<std::string>{"still", "east", "turn"} : std::vector<std::string>{"still", "turn"};
    const std::size_t n = m.library.names.size();
    m.library.motions.resize(n);
    m.fields.resize(n);
    m.fields[n - 1].twist = {Vec3(0, 0, 0.5)};
    return m;
}
Goal rigid_goal(const ControlModel& m) {
    Goal goal;
    goal.q = Vec3(0.01, 0.006, 0.4);
    goal.point = false;
    goal.theta_weight = m.nominal.part.rho();
    return goal;
}

}   // namespace

TEST_CASE("mpc: the online fit recovers the true gain and drift from exact frames", "[control][mpc]") {
    // A synthetic plate: each period the part moves by gain * xi T + drift, seen without noise or latency.
    // With priors far below the data (1e-9 m of travel, 1e-9 frames) the forgotten least squares solve an
    // exact, consistent system once two motions have been seen: the estimate is the truth to rounding
    // (measured: gain to 9e-13, drift to 3e-15 m). Seen failing: with the regressor taken from the
    // corrected model (the gain fitted onto itself) the synthetic part is not in within 40 periods.
    const ControlModel m = hand_model();
    MpcPolicyOptions o;
    o.prior_travel = 1e-9;
    o.prior_frames = 1e-9;
    auto p = make_mpc_policy(o);
    Goal goal;
    goal.q = Vec3(0.01, 0.006, 0);
    p->reset(m, goal);
    const double T = m.T(), gain = 0.8;
    const Vec2 drift(1.5e-5, -2.5e-5);   // [m per period]
    Vec3 q = Vec3::Zero();
    bool used[4] = {false, false, false, false};
    long k = 0;
    for (; k < 40 && !goal.within(q); ++k) {
        Observation obs;
        obs.t = obs.stamp = obs.state_time = k * T;
        obs.seen = true;
        obs.q = q;
        const Decision d = p->decide(obs, k);
        REQUIRE((d.motion >= 0 && d.motion < 4));
        used[d.motion] = true;
        q += gain * m.fields[d.motion].twist[0] * T;
        q.x() += drift.x();
        q.y() += drift.y();
    }
    REQUIRE(goal.within(q));   // (the corrected model steers the synthetic part in)
    REQUIRE((used[1] && used[2]));
    const MpcEstimate e = mpc_estimate(*p);
    CHECK(e.frames == k - 1);
    CHECK_THAT(e.gain, WithinAbs(gain, 1e-9));
    CHECK_THAT(e.drift.x(), WithinAbs(drift.x(), 1e-12));
    CHECK_THAT(e.drift.y(), WithinAbs(drift.y(), 1e-12));
    // Without the correction the estimate stays the nominal model's.
    o.correct = false;
    auto nominal = make_mpc_policy(o);
    nominal->reset(m, goal);
    Observation obs;
    obs.seen = true;
    for (long j = 0; j < 5; ++j) {
        obs.stamp = obs.state_time = obs.t = j * T;
        obs.q = Vec3(0.001 * j, 0, 0);
        nominal->decide(obs, j);
    }
    CHECK(mpc_estimate(*nominal).frames == 0);
    CHECK(mpc_estimate(*nominal).gain == 1);
}

TEST_CASE("mpc: frames one period late are carried forward along the motions chosen since", "[control][mpc]") {
    // The hand model's east transport moves 1 mm a period (0.02 m/s x 0.05 s); the synthetic part moves
    // exactly so, and each frame shows it one period late. Goal at 5.25 mm: the policy must see that the
    // part is at 5 mm at the decision (the late frame's 4 mm advanced by the period on east) and stop
    // there -- 5 mm is within the 0.5 mm stop radius, 6 mm would not be. Seen failing: deciding from the
    // frame as it is (no advance), the part went on to 6 mm.
    const ControlModel m = hand_model();
    MpcPolicyOptions o;
    o.correct = false;
    auto p = make_mpc_policy(o);
    Goal goal;
    goal.q = Vec3(0.00525, 0, 0);
    p->reset(m, goal);
    const double T = m.T();
    std::vector<Vec3> truth = {Vec3::Zero()};
    for (long k = 0; k < 12; ++k) {
        Observation obs;
        obs.t = k * T;
        obs.seen = k >= 1;
        obs.stamp = k * T;
        obs.state_time = (k - 1) * T;
        obs.q = obs.seen ? truth[static_cast<std::size_t>(k - 1)] : Vec3::Zero();
        const Decision d = p->decide(obs, k);
        truth.push_back(truth.back() + m.fields[static_cast<std::size_t>(d.motion)].twist[0] * T);
    }
    double furthest = 0;
    for (const Vec3& q : truth) furthest = std::max(furthest, q.x());
    CHECK_THAT(furthest, WithinAbs(0.005, 1e-12));   // (never beyond: it stopped at 5 mm)
    CHECK_THAT(truth.back().x(), WithinAbs(0.005, 1e-12));
    CHECK_THAT(truth.back().y(), WithinAbs(0.0, 1e-12));
}

TEST_CASE("mpc: on the issue's test plate the point part comes within 1 mm in 10 s and stays", "[control][mpc]") {
    // fig1_point's library, the truth (friction x0.8, 3 % / 0.03 rad per period), a world camera
    // with 0.1 mm noise one period late; bench_control's first 3 starts (bench_control --mpc: 20 of 20,
    // the slowest after 2.35 s).
    const Scene sc = load_scene(kScenes + "fig1_point.json");
    ControlModelOptions mo;
    mo.field.threads = 1;
    const ControlModel model = build_control_model(sc, load_motion_library(kScenes + "control/fig1_point/library.json", sc), mo);
    Goal goal;
    goal.q = Vec3(0.02, -0.01, 0);
    for (std::uint64_t i = 0; i < 3; ++i) {
        Camera cam;
        cam.per_period = 1;
        cam.noise_xy_mm = 0.1;
        cam.latency = sc.plate.T;
        cam.seed = i;
        cam.frame = CameraFrame::world;
        ControlOptions opt;
        opt.duration = 10;
        auto p = make_mpc_policy();
        const ControlSummary s = run_control(model, *p, spread_truth(0.8, 0.03, i), cam, goal, square_start(i, false), opt);
        INFO("start " << i);
        CHECK(s.reached);
        CHECK(s.final_error < 1e-3);
        CHECK(s.policy == "mpc");
    }
}

TEST_CASE("mpc: a rigid part's turn enters the fit: turning alone, the gain is recovered from the angle", "[control][mpc]") {
    // fig4's part at its goal's position, 0.4 rad off; the motions: the still plate and a uniform turn of
    // 0.5 rad/s. The synthetic plate turns it at gain 0.8, exactly, so only the angle's frames carry the
    // gain (the positions never move): the estimate is 0.8 to rounding (measured 7e-14) once frames have
    // come. Seen failing with the angle's row left out of the fit (the gain stays at its prior, 1).
    const ControlModel m = rigid_hand_model(false);
    MpcPolicyOptions o;
    o.prior_travel = 1e-9;
    o.prior_frames = 1e-9;
    auto p = make_mpc_policy(o);
    const Goal goal = rigid_goal(m);
    p->reset(m, goal);
    const double T = m.T(), gain = 0.8;
    Vec3 q(0.01, 0.006, 0);
    long k = 0, turns = 0;
    for (; k < 60 && !goal.within(q); ++k) {
        Observation obs;
        obs.t = obs.stamp = obs.state_time = k * T;
        obs.seen = true;
        obs.q = q;
        const Decision d = p->decide(obs, k);
        REQUIRE((d.motion == 0 || d.motion == 1));
        turns += d.motion == 1;
        q += gain * m.fields[d.motion].twist[0] * T;
    }
    REQUIRE(goal.within(q));
    REQUIRE(turns >= 3);
    CHECK_THAT(mpc_estimate(*p).gain, WithinAbs(gain, 1e-9));
    // The same across theta = pi: the camera gives angles in (-pi, pi], so a turn from 2.9 rad to the goal
    // at -3.0 (3.28 unwrapped) shows a jump of -2 pi between two frames; the fit takes the wrapped change.
    // Seen failing with the change taken unwrapped (the gain pulled far from 0.8).
    Goal across = goal;
    across.q.z() = -3.0;
    p->reset(m, across);
    q = Vec3(0.01, 0.006, 2.9);
    for (k = 0; k < 60 && !across.within(q); ++k) {
        Observation obs;
        obs.t = obs.stamp = obs.state_time = k * T;
        obs.seen = true;
        obs.q = Vec3(q.x(), q.y(), wrap_angle(q.z()));
        const Decision d = p->decide(obs, k);
        q += gain * m.fields[d.motion].twist[0] * T;
    }
    CHECK(k < 60);
    CHECK_THAT(mpc_estimate(*p).gain, WithinAbs(gain, 1e-9));
}

TEST_CASE("mpc: a rigid part's angle enters the fit weighted by the goal's theta_weight", "[control][mpc]") {
    // Positions and angle disagree: the synthetic plate moves the part east at the model's speed (gain 1)
    // and turns it at 0.8 of the model's rate. With no forgetting and negligible priors the fit is the
    // least-squares solution over the frame pairs, worked out by hand: with N pairs, N_e of them east (a =
    // 0.02 T per period), N_t turning (b = 0.5 T), the x rows give the drift d_x = N_e a (1 - g) / N and then
    //     g = (E + 0.8 R) / (E + R),   E = N_e a^2 (1 - N_e / N),   R = N_t (w b)^2,
    // w the goal's theta_weight (the y rows see nothing: d_y = 0). Measured: 0.90140845071 against
    // 0.90140845070 (the priors' 1e-9), 28 pairs, 10 east, 18 turning. Seen failing with the angle's row
    // weighted by 1 instead of w: 0.8001.
    const ControlModel m = rigid_hand_model(true);
    MpcPolicyOptions o;
    o.prior_travel = 1e-9;
    o.prior_frames = 1e-9;
    o.forgetting = 1;
    auto p = make_mpc_policy(o);
    const Goal goal = rigid_goal(m);
    p->reset(m, goal);
    const double T = m.T();
    Vec3 q(0, 0.006, 0);
    std::vector<int> chosen;
    for (long k = 0; k < 80 && !goal.within(q); ++k) {
        Observation obs;
        obs.t = obs.stamp = obs.state_time = k * T;
        obs.seen = true;
        obs.q = q;
        const int d = p->decide(obs, k).motion;
        chosen.push_back(d);
        const Vec3 xi = m.fields[d].twist[0];
        q += Vec3(xi.x(), xi.y(), 0.8 * xi.z()) * T;
    }
    REQUIRE(goal.within(q));
    chosen.pop_back();   // (the last decision's period was not filmed)
    const double N = static_cast<double>(chosen.size());
    const double Ne = static_cast<double>(std::count(chosen.begin(), chosen.end(), 1));
    const double Nt = static_cast<double>(std::count(chosen.begin(), chosen.end(), 2));
    REQUIRE((Ne >= 2 && Nt >= 2));
    const double a = 0.02 * T, b = 0.5 * T, w = goal.theta_weight;
    const double E = Ne * a * a * (1 - Ne / N), R = Nt * (w * b) * (w * b);
    const MpcEstimate e = mpc_estimate(*p);
    CHECK(e.frames == static_cast<int>(N));
    CHECK_THAT(e.gain, WithinAbs((E + 0.8 * R) / (E + R), 1e-9));
    CHECK(std::abs(e.gain - 0.8) > 1e-3);   // (both kinds of rows count: not the angle's gain alone)
}

TEST_CASE("mpc: too many sequences and bad options are refused by name", "[control][mpc]") {
    ControlModel m = hand_model();
    MpcPolicyOptions o;
    o.horizon = 8;   // 4^8 = 65536 sequences: allowed
    CHECK_NOTHROW(make_mpc_policy(o)->reset(m, Goal{}));
    m.fields.resize(6, m.fields[0]);
    m.library.names.resize(6, "more");
    m.library.motions.resize(6, m.nominal.plate);   // 6^8 = 1679616 sequences
    CHECK_THROWS_WITH(make_mpc_policy(o)->reset(m, Goal{}), Contains("shorten the horizon"));
    // The limit exactly: 1000 motions over 2 periods are 10^6 sequences (allowed), 1001 are not.
    o.horizon = 2;
    m.fields.resize(1000, m.fields[0]);
    m.library.names.resize(1000, "more");
    m.library.motions.resize(1000, m.nominal.plate);
    CHECK_NOTHROW(make_mpc_policy(o)->reset(m, Goal{}));
    m.fields.push_back(m.fields[0]);
    m.library.names.push_back("more");
    m.library.motions.push_back(m.nominal.plate);
    CHECK_THROWS_WITH(make_mpc_policy(o)->reset(m, Goal{}), Contains("more than 1000000 sequences"));
    o.horizon = 0;
    CHECK_THROWS_WITH(make_mpc_policy(o), Contains("horizon: expected 1 to 8"));
    o = {};
    o.forgetting = 1.5;
    CHECK_THROWS_WITH(make_mpc_policy(o), Contains("forgetting"));
    CHECK_THROWS_WITH(mpc_estimate(*make_library_policy()), Contains("not an mpc policy"));
}
