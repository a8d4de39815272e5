// Benchmark: closed-loop control of fig1_point's part (issue 53, the point-part target). Not a test:
// nothing here passes or fails. STARTS seeded starts at rest, uniform over the 0.1 m square
// [-0.05, 0.05]^2, to the goal (0.02, -0.01) within 1 mm, by the `library` policy over LIBRARY
// (default scenes/control/fig1_point/library.json) against a truth with friction 20 % below the
// model's and 3 % amplitude / 0.03 rad phase tracking errors drawn every period (draw = the start's
// index), filmed by a stroboscopic world-frame camera at phase 0 with 0.1 mm noise and one period of
// latency (seed = the start's index). Each run lasts DURATION s (default 15): the time to goal is when
// the part came within 1 mm and stayed there to the end. Per start: time to goal, final error, worst
// overshoot, switches, mean and largest decision time; then how many met <= 10 s, and the machine.
// HORIZON: the policy's (LibraryPolicyOptions::horizon, default 4); TRANSITIONS 0: the model without the
// switches' first periods (ControlModel::transitions).
// LIBRARY "-": the default.
// FRICTION_SCALE: the truth's (default 0.8).
//   bench_control [STARTS [DURATION [LIBRARY [FIRST_SEED [HORIZON [TRANSITIONS [FRICTION_SCALE]]]]]]]
#include "machine.hpp"
#include "plate/control.hpp"
#include "plate/random_scene.hpp"
#include "plate/scene_io.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <thread>

using namespace plate;

int main(int argc, char** argv) try {
    const int starts = argc > 1 ? std::stoi(argv[1]) : 20;
    const double duration = argc > 2 ? std::stod(argv[2]) : 15;
    const std::string root = PLATE_SOURCE_DIR;
    const std::string lib = argc > 3 && std::string(argv[3]) != "-" ? argv[3] : root + "/scenes/control/fig1_point/library.json";
    const int first = argc > 4 ? std::stoi(argv[4]) : 0;
    const double friction_scale = argc > 7 ? std::stod(argv[7]) : 0.8;
    LibraryPolicyOptions po;
    po.horizon = argc > 5 ? std::stoi(argv[5]) : po.horizon;
    const Scene sc = load_scene(root + "/scenes/fig1_point.json");
    const auto t_model = std::chrono::steady_clock::now();
    ControlModelOptions mo;
    mo.field.threads = 1;
    mo.transitions = argc > 6 ? std::stoi(argv[6]) != 0 : true;
    const ControlModel model = build_control_model(sc, load_motion_library(lib, sc), mo);
    const double model_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_model).count();
    Goal goal;
    goal.q = Vec3(0.02, -0.01, 0);
    goal.tolerance = 1e-3;
    std::printf(
        "bench_control: %d starts over [-0.05, 0.05]^2 to (0.02, -0.01) within 1 mm, %g s runs, %d motions "
        "(model built in %.3g s)\n",
        starts, duration, model.motions(), model_s);
    std::printf(
        "truth: friction x 0.8, amplitude 3 %%, phase 0.03 rad per period; camera: world, noise 0.1 mm, latency "
        "one period (0.05 s)\n");
    std::printf("%5s %9s %9s %11s %11s %11s %8s %10s %10s %10s %7s\n", "start", "x0 [m]", "y0 [m]", "to goal [s]", "final [mm]",
                "overshoot", "switches", "dec mean", "dec p99", "dec max", "run [s]");
    int met = 0, reached = 0;
    double worst_time = 0, worst_decision = 0;
    for (int i = first; i < first + starts; ++i) {
        Rng rng(1000 + static_cast<std::uint64_t>(i));
        const Vec3 q0(rng.uniform(-0.05, 0.05), rng.uniform(-0.05, 0.05), 0);
        Truth truth;
        truth.friction_scale = friction_scale;
        UncertaintySpec spec;
        spec.seed = 53;
        spec.amplitude.spread = 0.03;
        spec.phase.spread = 0.03;
        truth.uncertainty = spec;
        truth.draw = static_cast<std::uint64_t>(i);
        Camera cam;
        cam.per_period = 1;
        cam.noise_xy_mm = 0.1;
        cam.latency = sc.plate.T;
        cam.seed = static_cast<std::uint64_t>(i);
        cam.frame = CameraFrame::world;
        ControlOptions opt;
        opt.duration = duration;
        auto policy = make_library_policy(po);
        const auto t0 = std::chrono::steady_clock::now();
        const ControlSummary s = run_control(model, *policy, truth, cam, goal, q0, opt);
        const double run_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        reached += s.reached;
        met += s.reached && s.time_to_goal <= 10;
        worst_time = std::max(worst_time, s.reached ? s.time_to_goal : 1e300);
        worst_decision = std::max(worst_decision, s.decision_max);
        std::printf("%5d %9.4f %9.4f %11.3g %11.3g %11.3g %8d %8.2gus %8.2gus %8.2gus %7.3g%s\n", i, q0.x(), q0.y(),
                    s.time_to_goal, s.final_error * 1e3, s.worst_overshoot * 1e3, s.switches, s.decision_mean * 1e6,
                    s.decision_p99 * 1e6, s.decision_max * 1e6, run_s,
                    s.stop.reason == StopReason::None ? "" : (" stopped: " + s.stop.describe()).c_str());
    }
    std::printf("reached and held: %d/%d; within 10 s: %d/%d; slowest %.3g s; largest decision %.3g ms (target 1 ms)\n", reached,
                starts, met, starts, worst_time, worst_decision * 1e3);
    std::printf("machine: %s, %u hardware threads (one used)\n", bench::machine().c_str(), std::thread::hardware_concurrency());
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "bench_control: %s\n", e.what());
    return 2;
}
