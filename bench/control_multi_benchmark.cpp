// Benchmark: two point parts on one plate to two goals (issue 53, point 3). Not a test: nothing here
// passes or fails. PAIRS seeded start pairs at rest (pair i: square_start(2 i) and square_start(2 i + 1),
// uniform over the 0.1 m square [-0.05, 0.05]^2), part 1 to GOAL1 and part 2 to GOAL2 within 1 mm, by
// the multi-part `library` policy over LIBRARY, against the point target's truth (friction 20 % below the
// model's, 3 % amplitude / 0.03 rad phase tracking errors drawn every period, draw = i) and camera
// (stroboscopic, world frame, phase 0, 0.1 mm noise, one period of latency, seed i; part j's stream seed
// i + j). Each run lasts DURATION s. Per pair: each part's time to goal and final error, switches, decision
// times (mean, p99, max); then how many pairs had both parts in, and the machine.
//   bench_control_multi [--pairs N] [--first I] [--duration S] [--library LIB] [--goals X1 Y1 X2 Y2]
//                       [--horizon H] [--max] [--one-phase] [--friction-scale F] [--spread S]
// --max: the policy's cost the largest weighted distance instead of the sum (Aggregate::max); --one-phase:
// one choice over every motion by that cost (LibraryPolicyOptions::two_phase false).
// Defaults: scenes/fig1_point.json, scenes/control/fig1_point/multi.json, goals (0.02, -0.01) and
// (-0.02, 0.01), 20 pairs, 30 s runs.
#include "machine.hpp"
#include "plate/control_multi.hpp"
#include "plate/random_scene.hpp"
#include "plate/scene_io.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <thread>

using namespace plate;

namespace {

struct Args {
    int pairs = 20, first = 0;
    double duration = 30, friction_scale = 0.8, spread = 0.03;
    std::string scene = PLATE_SOURCE_DIR "/scenes/fig1_point.json";
    std::string library = PLATE_SOURCE_DIR "/scenes/control/fig1_point/multi.json";
    Vec3 goal1 = Vec3(0.02, -0.01, 0), goal2 = Vec3(-0.02, 0.01, 0);
    LibraryPolicyOptions policy;
    Aggregate aggregate = Aggregate::sum;
};

Args parse(int argc, char** argv) {
    Args a;
    for (int i = 1; i < argc; ++i) {
        const std::string o = argv[i];
        if (o == "--max" || o == "--one-phase") {
            if (o == "--max") a.aggregate = Aggregate::max;
            if (o == "--one-phase") a.policy.two_phase = false;
            continue;
        }
        auto next = [&]() -> double {
            if (i + 1 >= argc) throw std::invalid_argument(o + ": expected a value");
            return std::stod(argv[++i]);
        };
        if (o == "--pairs")
            a.pairs = static_cast<int>(next());
        else if (o == "--first")
            a.first = static_cast<int>(next());
        else if (o == "--duration")
            a.duration = next();
        else if (o == "--library") {
            if (i + 1 >= argc) throw std::invalid_argument(o + ": expected a value");
            a.library = argv[++i];
        } else if (o == "--goals") {
            a.goal1.x() = next();
            a.goal1.y() = next();
            a.goal2.x() = next();
            a.goal2.y() = next();
        } else if (o == "--horizon")
            a.policy.horizon = static_cast<int>(next());
        else if (o == "--friction-scale")
            a.friction_scale = next();
        else if (o == "--spread")
            a.spread = next();
        else
            throw std::invalid_argument("unknown option " + o);
    }
    return a;
}

}   // namespace

int main(int argc, char** argv) try {
    const Args a = parse(argc, argv);
    const Scene sc = load_scene(a.scene);
    const auto t_model = std::chrono::steady_clock::now();
    ControlModelOptions mo;
    mo.field.threads = 1;
    mo.grid.x0 = mo.grid.y0 = -0.06;   // the square and a margin, 13 x 13 (the non-uniform fields)
    mo.grid.x1 = mo.grid.y1 = 0.06;
    mo.grid.nx = mo.grid.ny = 13;
    const ControlModel model = build_control_model(sc, load_motion_library(a.library, sc), mo);
    const double model_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_model).count();
    std::printf(
        "bench_control_multi: %s, %d start pairs over [-0.05, 0.05]^2 to (%g, %g) and (%g, %g) within 1 mm, %g s runs, "
        "%d motions of %s (model built in %.3g s)\n",
        sc.name.c_str(), a.pairs, a.goal1.x(), a.goal1.y(), a.goal2.x(), a.goal2.y(), a.duration, model.motions(),
        a.library.c_str(), model_s);
    std::printf(
        "truth: friction x %g, amplitude %g %%, phase %g rad per period; camera: world, noise 0.1 mm, latency one "
        "period (%g s)\n",
        a.friction_scale, 100 * a.spread, a.spread, sc.plate.T);
    std::printf("%4s %8s %8s %8s %8s %9s %9s %9s %9s %5s %8s %8s %8s %7s\n", "pair", "x1 [m]", "y1 [m]", "x2 [m]", "y2 [m]",
                "goal1 [s]", "goal2 [s]", "err1 [mm]", "err2 [mm]", "sw", "dec mean", "dec p99", "dec max", "run [s]");
    int both = 0, one = 0;
    double slowest = 0, worst_decision = 0;
    for (int i = a.first; i < a.first + a.pairs; ++i) {
        MultiParts parts;
        parts.parts = {{a.goal1, square_start(2 * static_cast<std::uint64_t>(i), false), 1},
                       {a.goal2, square_start(2 * static_cast<std::uint64_t>(i) + 1, false), 1}};
        const Truth truth = spread_truth(a.friction_scale, a.spread, static_cast<std::uint64_t>(i));
        const Camera cam = issue_camera(sc.plate.T, static_cast<std::uint64_t>(i), false);
        ControlOptions opt;
        opt.duration = a.duration;
        auto policy = make_multi_library_policy(a.policy, a.aggregate);
        const auto t0 = std::chrono::steady_clock::now();
        const MultiControlSummary s = run_multi_control(model, *policy, truth, cam, parts, opt);
        const double run_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        both += s.reached;
        one += s.parts[0].reached != s.parts[1].reached;
        if (s.reached) slowest = std::max(slowest, s.time_to_goal);
        worst_decision = std::max(worst_decision, s.decision_max);
        const Vec3 &p1 = parts.parts[0].start, &p2 = parts.parts[1].start;
        std::printf("%4d %8.4f %8.4f %8.4f %8.4f %9.3g %9.3g %9.3g %9.3g %5d %6.2gus %6.2gus %6.2gus %7.3g", i, p1.x(), p1.y(),
                    p2.x(), p2.y(), s.parts[0].time_to_goal, s.parts[1].time_to_goal, s.parts[0].final_error * 1e3,
                    s.parts[1].final_error * 1e3, s.switches, s.decision_mean * 1e6, s.decision_p99 * 1e6, s.decision_max * 1e6,
                    run_s);
        if (s.stop.reason != StopReason::None) std::printf(" stopped: %s", s.stop.describe().c_str());
        std::printf("\n");
        std::fflush(stdout);
    }
    std::printf("both parts reached and held: %d/%d (one of the two: %d); slowest pair %.3g s; largest decision %.3g ms\n", both,
                a.pairs, one, slowest, worst_decision * 1e3);
    std::printf("machine: %s, %u hardware threads (one used)\n", bench::machine().c_str(), std::thread::hardware_concurrency());
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "bench_control_multi: %s\n", e.what());
    return 2;
}
