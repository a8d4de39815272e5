// The open-loop half of the report's control section (reports/report_sections_control.cpp) checked
// against an independent run: the designed sink's scene simulated in one go, not period by period.
#include "plate/control.hpp"
#include "plate/design.hpp"
#include "plate/scene_io.hpp"
#include "plate/simulate.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

using namespace plate;

namespace {

const std::string kScenes = PLATE_SOURCE_DIR "/scenes/";

struct Compared {
    double worst = 0;    // [m] the loop's true world position against the unbroken simulation's, at worst
    double held = NAN;   // [s] from the unbroken simulation: first period start from which it stays within 1 mm
    ControlSummary loop;
};

// The section's open loop (open_loop_model of `design`, the policy that always keeps it, no camera) on
// `truth`, against `ref` simulated over the whole run at once and sampled at the period starts (world pose
// at phase 0).
Compared compare(const std::string& design, const Truth& truth, const Scene& ref, const Vec3& q0, double duration) {
    const Scene nominal = load_scene(kScenes + "fig1_point.json");
    Goal goal;
    goal.q = Vec3(0.02, -0.01, 0);   // (point_sink's sink)
    goal.point = true;
    ControlOptions o;
    o.duration = duration;
    Compared c;
    c.loop = run_control(open_loop_model(nominal, design), *make_open_loop_policy(), truth, std::nullopt, goal, q0, o);
    const long periods = std::lround(duration / ref.plate.T);
    std::vector<double> times;
    for (long k = 1; k <= periods; ++k) times.push_back(k * ref.plate.T);
    const Trajectory tr = simulate_at(ref, Dynamics::Full, q0, Vec3::Zero(), times);
    REQUIRE(c.loop.stop.reason == StopReason::None);
    REQUIRE(tr.samples.size() == times.size());
    REQUIRE(static_cast<long>(c.loop.rows.size()) == periods + 1);
    long held_from = periods + 1;
    for (long k = periods; k >= 0; --k) {
        const Vec3 w = world_pose_at_phase0(ref, k == 0 ? q0 : tr.samples[k - 1].q);
        c.worst = std::max(c.worst, (w - c.loop.rows[k].truth).head<2>().norm());
        CHECK(c.loop.rows[k].motion == (k < periods ? 0 : -1));
        if ((w - goal.q).head<2>().norm() <= goal.tolerance && held_from == k + 1) held_from = k;
    }
    if (held_from <= periods) c.held = held_from * ref.plate.T;
    return c;
}

// The section's truth: friction 20 % below the model's; and the design file's scene on it.
Truth low_friction() {
    Truth t;
    t.friction_scale = 0.8;
    return t;
}
Scene on_low_friction(const std::string& design) {
    Scene s = load_scene(design);
    s.part.mu *= 0.8;
    return s;
}

// point_sink without its tilts (rx, ry): a plate that does not rotate, so it does not cone.
Scene flat_sink() {
    Scene flat = load_scene(kScenes + "designs/point_sink.json");
    flat.plate.harmonics.erase(std::remove_if(flat.plate.harmonics.begin(), flat.plate.harmonics.end(),
                                              [](const Harmonic& h) { return h.axis == Axis::rx || h.axis == Axis::ry; }),
                               flat.plate.harmonics.end());
    return flat;
}

}   // namespace

TEST_CASE("The control section's open loop is the designed sink's scene simulated without a break", "[control][open-loop]") {
    // point_sink without its tilts (rx, ry): a plate that does not rotate does not cone, so restarting the
    // full dynamics at every period's phase 0 (as the loop does) changes nothing but the integrator's
    // steps. Measured: 3.5e-10 m at worst over 8 s (160 restarts at rtol 1e-9) from both starts.
    const std::filesystem::path flat_file = std::filesystem::temp_directory_path() / "plate-open-loop-flat.json";
    std::ofstream(flat_file) << scene_to_json(flat_sink()).dump();
    for (std::uint64_t start : {3u, 11u}) {
        const Compared c =
            compare(flat_file.string(), low_friction(), on_low_friction(flat_file.string()), square_start(start, false), 8);
        std::printf("open loop without tilts from start %llu: %.3g m from the unbroken simulation at worst; %s\n",
                    static_cast<unsigned long long>(start), c.worst, c.loop.reached ? "reached" : "not reached");
        CHECK(c.worst < 1e-9);
        CHECK(c.loop.switches == 0);
        CHECK(c.loop.reached == !std::isnan(c.held));
        if (c.loop.reached) CHECK_THAT(c.loop.time_to_goal, Catch::Matchers::WithinAbs(c.held, 1e-12));
    }
    std::filesystem::remove(flat_file);
}

TEST_CASE("The control loop does not carry the plate's coning: the shipped sink's drift from it is bounded by psi' t r",
          "[control][open-loop]") {
    // The shipped point_sink tilts about x and y out of phase, so the unbroken simulation's plate yaws at
    // its coning rate psi' (coning_rate, a closed form) while the loop restarts it at phase 0 every period
    // (docs/decisions/control.md). Over 8 s the difference is then at most about |psi'| t times the part's
    // distance from the plate's origin (<= 0.05 m over the square): measured 1.26e-4 m against the bound
    // 3.7e-4 m. The part is brought in all the same: the unbroken run is within 1 mm from 6 s and 5.75 s.
    const std::string design = kScenes + "designs/point_sink.json";
    const double drift = std::abs(coning_rate(load_scene(design).plate)) * 8 * 0.05;
    for (std::uint64_t start : {3u, 11u}) {
        const Compared c = compare(design, low_friction(), on_low_friction(design), square_start(start, false), 8);
        std::printf("open loop from start %llu: %.3g m from the unbroken simulation at worst (bound %.3g m)\n",
                    static_cast<unsigned long long>(start), c.worst, drift);
        CHECK(c.worst < drift);
        CHECK(c.worst > 0.1 * drift);   // (the coning's size, not a match by chance or a drift far smaller)
        CHECK(c.loop.reached);
        CHECK(c.held < 7);
    }
}

TEST_CASE("A truth with a recorded cycle runs the commanded motion on the plate the recording shows", "[control][open-loop]") {
    // The commanded motion: the tilt-free point_sink. The "recording": the plate's acceleration over one
    // period, sampled at 240 points from that motion with every amplitude x 0.95 and every phase + 0.03 rad
    // (a plate that tracks its signal 5 % low and late), written as a measured cycle. The truth names the
    // two; the loop must then run the recorded plate. Expected, independently: the perturbed harmonics put
    // into the scene by hand and simulated unbroken. Measured: 2.1e-10 m at worst over 8 s (the restarts,
    // as above; the cycle's harmonics equal the perturbed ones to about 1e-15 relative); the commanded
    // plate itself is 23 mm away by then.
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / "plate-measured-truth";
    fs::create_directories(dir);
    const Scene flat = flat_sink();
    std::ofstream(dir / "commanded.json") << scene_to_json(flat).dump();
    Scene recorded = flat;
    for (Harmonic& h : recorded.plate.harmonics) {
        h.amp *= 0.95;
        h.phase += 0.03;
    }
    {
        std::ofstream csv(dir / "recorded.csv");
        csv << "t [s],x [m/s^2],y [m/s^2],z [m/s^2],rx [rad/s^2],ry [rad/s^2],rz [rad/s^2]\n";
        csv.precision(17);
        const int M = 240;
        const double T = flat.plate.T;
        for (int i = 0; i < M; ++i) {
            const double t = i * T / M;
            double u[6] = {0, 0, 0, 0, 0, 0};
            for (const Harmonic& h : recorded.plate.harmonics)
                u[static_cast<int>(h.axis)] += h.amp * std::sin(h.n * 2 * M_PI * t / T + h.phase);
            csv << t;
            for (double v : u) csv << ',' << v;
            csv << '\n';
        }
    }
    std::ofstream(dir / "truth.json")
        << R"({"measured": [{"commanded": "commanded.json", "cycle": "recorded.csv", "harmonics": 5}]})";
    const Truth truth = load_truth((dir / "truth.json").string());
    REQUIRE(truth.measured.size() == 1);
    const Vec3 q0 = square_start(3, false);
    const Compared c = compare((dir / "commanded.json").string(), truth, recorded, q0, 8);
    const Compared as_commanded = compare((dir / "commanded.json").string(), Truth{}, recorded, q0, 8);
    std::printf("a recorded cycle's truth: %.3g m from the recorded plate unbroken; the commanded plate %.3g m\n", c.worst,
                as_commanded.worst);
    CHECK(c.worst < 1e-9);
    CHECK(as_commanded.worst > 1e-3);   // (the recording matters: without it the run is the commanded plate's)
    // Only the recorded motion is replaced: another motion runs as commanded (the loop's other library
    // motions), and the truth's friction scale applies on the recorded plate too.
    Scene other = flat;
    other.plate.harmonics[0].amp *= 1.1;
    const Scene other_true = true_scene(truth, other, 1, 7);
    REQUIRE(other_true.plate.harmonics.size() == other.plate.harmonics.size());
    for (std::size_t k = 0; k < other.plate.harmonics.size(); ++k) {
        CHECK(other_true.plate.harmonics[k].amp == other.plate.harmonics[k].amp);
        CHECK(other_true.plate.harmonics[k].phase == other.plate.harmonics[k].phase);
    }
    Truth scaled = truth;
    scaled.friction_scale = 0.8;
    const Scene recorded_true = true_scene(scaled, flat, 0, 7);
    CHECK(recorded_true.part.mu.x() == flat.part.mu.x() * 0.8);
    Scene holding = flat;   // (static above kinetic: both scaled)
    holding.part.mu_static = holding.part.mu * 1.2;
    const Scene holding_true = true_scene(scaled, holding, 0, 7);
    REQUIRE(holding_true.part.mu_static);
    CHECK(holding_true.part.mu_static->x() == holding.part.mu_static->x() * 0.8);
    REQUIRE(recorded_true.plate.harmonics.size() == recorded.plate.harmonics.size());
    for (const Harmonic& h : recorded.plate.harmonics) {
        const auto same = [&](const Harmonic& g) { return g.axis == h.axis && g.n == h.n; };
        const auto it = std::find_if(recorded_true.plate.harmonics.begin(), recorded_true.plate.harmonics.end(), same);
        REQUIRE(it != recorded_true.plate.harmonics.end());
        CHECK(std::abs(it->amp - h.amp) <= 1e-12 * h.amp);
        CHECK(std::abs(wrap_angle(it->phase - h.phase)) <= 1e-12);
    }
    fs::remove_all(dir);
}
