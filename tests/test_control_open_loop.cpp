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

// The section's open loop (open_loop_model, the policy that always keeps it, no camera) on a plate whose
// friction is 20 % below the model's, against the design file's own scene with its friction x 0.8
// simulated over the whole run at once and sampled at the period starts (world pose at phase 0).
Compared compare(const std::string& design, const Vec3& q0, double duration) {
    const Scene nominal = load_scene(kScenes + "fig1_point.json");
    Truth truth;
    truth.friction_scale = 0.8;
    Goal goal;
    goal.q = Vec3(0.02, -0.01, 0);   // (point_sink's sink)
    goal.point = true;
    ControlOptions o;
    o.duration = duration;
    Compared c;
    c.loop = run_control(open_loop_model(nominal, design), *make_open_loop_policy(), truth, std::nullopt, goal, q0, o);
    Scene ref = load_scene(design);
    ref.part.mu *= 0.8;
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

}   // namespace

TEST_CASE("The control section's open loop is the designed sink's scene simulated without a break", "[control][open-loop]") {
    // point_sink without its tilts (rx, ry): a plate that does not rotate does not cone, so restarting the
    // full dynamics at every period's phase 0 (as the loop does) changes nothing but the integrator's
    // steps. Measured: 3.5e-10 m at worst over 8 s (160 restarts at rtol 1e-9) from both starts.
    const std::string design = kScenes + "designs/point_sink.json";
    Scene flat = load_scene(design);
    flat.plate.harmonics.erase(std::remove_if(flat.plate.harmonics.begin(), flat.plate.harmonics.end(),
                                              [](const Harmonic& h) { return h.axis == Axis::rx || h.axis == Axis::ry; }),
                               flat.plate.harmonics.end());
    const std::filesystem::path flat_file = std::filesystem::temp_directory_path() / "plate-open-loop-flat.json";
    std::ofstream(flat_file) << scene_to_json(flat).dump();
    for (std::uint64_t start : {3u, 11u}) {
        const Compared c = compare(flat_file.string(), square_start(start, false), 8);
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
        const Compared c = compare(design, square_start(start, false), 8);
        std::printf("open loop from start %llu: %.3g m from the unbroken simulation at worst (bound %.3g m)\n",
                    static_cast<unsigned long long>(start), c.worst, drift);
        CHECK(c.worst < drift);
        CHECK(c.worst > 1e-3 * drift);   // (coning there, and seen: not an exact match by chance)
        CHECK(c.loop.reached);
        CHECK(c.held < 7);
    }
}
