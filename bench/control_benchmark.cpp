// Benchmark: closed-loop control (issue 53's targets). Not a test: nothing here passes or fails.
// STARTS seeded starts at rest, uniform over the 0.1 m square [-0.05, 0.05]^2 (a rigid part: theta
// uniform over a turn), to the goal within 1 mm (and 0.02 rad), by the `library` policy (--mpc: `mpc`) over LIBRARY
// against a truth with friction 20 % below the model's and 3 % amplitude / 0.03 rad phase tracking
// errors drawn every period (draw = the start's index), filmed by a stroboscopic world-frame camera at
// phase 0 with 0.1 mm (and 5 mrad) noise and one period of latency (seed = the start's index). Each run
// lasts DURATION s: the time to goal is when the part came within tolerance and stayed there to the end.
// Per start: time to goal, final errors, worst overshoot, switches, decision times (mean, p99, max);
// then how many met the target time, and the machine.
//   bench_control [--rigid] [--starts N] [--first SEED] [--duration S] [--scene SCENE] [--library LIB]
//                 [--goal X Y [THETA]] [--horizon H] [--transitions 0|1] [--grid-transitions 0|1]
//                 [--friction-scale F] [--spread S] [--contact-spread S] [--single-phase] [--open-loop SCENE]
//                 [--open-loop-time S]
//                 [--open-loop-tol MM RAD] [--mpc [--mpc-horizon H] [--mpc-no-correction]]
// Defaults: the point-part target (scenes/fig1_point.json, scenes/control/fig1_point/library.json,
// goal (0.02, -0.01), 15 s runs, target 10 s). --rigid: the rigid-part target (scenes/fig4.json,
// scenes/control/fig4/library.json, goal (0.02, -0.01, 0.5), 40 s runs, target 30 s) and, beside each
// start, the open-loop fixed-point design scenes/designs/fig4_fixed_point.json run on the same truth
// from the same start (its time to goal, cap --open-loop-time, default 300 s; judged within --open-loop-tol,
// default the goal's 1 mm and 0.02 rad). --single-phase: a rigid
// part's one weighted distance (LibraryPolicyOptions::two_phase false, theta weighted by rho).
// --spread: the tracking errors' (amplitude relative, phase rad; default 0.03); --contact-spread S: each
// contact's true friction also off by its own uniform relative error in [-S, S] (drawn once per run, so a
// rigid part's contacts differ); --grid-transitions 1: the rigid part's transition table also for the
// turning motions (on the 3-D grid). --open-loop "": no open-loop run beside the closed loop.
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

namespace {

struct Args {
    int starts = 20, first = 0;
    double duration = 15, target = 10, friction_scale = 0.8, open_loop_time = 300, spread = 0.03, contact_spread = 0;
    double open_loop_tol = 1e-3, open_loop_tol_theta = 0.02;
    std::string scene, library, open_loop;
    Vec3 goal = Vec3(0.02, -0.01, 0);
    bool rigid = false;
    LibraryPolicyOptions policy;
    bool mpc = false;
    MpcPolicyOptions mpc_options;
    bool transitions = true, grid_transitions = false;
};

Args parse(int argc, char** argv) {
    const std::string root = PLATE_SOURCE_DIR;
    Args a;
    for (int i = 1; i < argc; ++i)
        if (std::string(argv[i]) == "--rigid") {
            a.rigid = true;
            a.duration = 40;
            a.target = 30;
            a.goal = Vec3(0.02, -0.01, 0.5);
            a.open_loop = root + "/scenes/designs/fig4_fixed_point.json";
        }
    a.scene = root + (a.rigid ? "/scenes/fig4.json" : "/scenes/fig1_point.json");
    a.library = root + (a.rigid ? "/scenes/control/fig4/library.json" : "/scenes/control/fig1_point/library.json");
    for (int i = 1; i < argc; ++i) {
        const std::string o = argv[i];
        auto next = [&]() -> std::string {
            if (i + 1 >= argc) throw std::invalid_argument(o + ": expected a value");
            return argv[++i];
        };
        if (o == "--rigid") continue;
        if (o == "--mpc") {
            a.mpc = true;
            continue;
        }
        if (o == "--mpc-horizon") {
            a.mpc_options.horizon = std::stoi(next());
            continue;
        }
        if (o == "--mpc-no-correction") {
            a.mpc_options.correct = false;
            continue;
        }
        if (o == "--starts")
            a.starts = std::stoi(next());
        else if (o == "--first")
            a.first = std::stoi(next());
        else if (o == "--duration")
            a.duration = std::stod(next());
        else if (o == "--scene")
            a.scene = next();
        else if (o == "--library")
            a.library = next();
        else if (o == "--goal") {
            a.goal.x() = std::stod(next());
            a.goal.y() = std::stod(next());
            if (a.rigid) a.goal.z() = std::stod(next());
        } else if (o == "--horizon")
            a.policy.horizon = std::stoi(next());
        else if (o == "--transitions")
            a.transitions = std::stoi(next()) != 0;
        else if (o == "--grid-transitions")
            a.grid_transitions = std::stoi(next()) != 0;
        else if (o == "--friction-scale")
            a.friction_scale = std::stod(next());
        else if (o == "--spread")
            a.spread = std::stod(next());
        else if (o == "--contact-spread")
            a.contact_spread = std::stod(next());
        else if (o == "--single-phase")
            a.policy.two_phase = false;
        else if (o == "--open-loop")
            a.open_loop = next();
        else if (o == "--open-loop-time")
            a.open_loop_time = std::stod(next());
        else if (o == "--open-loop-tol") {
            a.open_loop_tol = std::stod(next()) * 1e-3;
            a.open_loop_tol_theta = std::stod(next());
        } else
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
    mo.transitions = a.transitions;
    if (a.rigid) {   // the turning motions' fields on a 3-D grid over the square and a margin; no grid transitions
        mo.grid.x0 = mo.grid.y0 = -0.07;
        mo.grid.x1 = mo.grid.y1 = 0.07;
        mo.grid.nx = mo.grid.ny = 8;
        mo.grid.nth = 8;
        mo.grid_transitions = a.grid_transitions;
    }
    const ControlModel model = build_control_model(sc, load_motion_library(a.library, sc), mo);
    const double model_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_model).count();
    Goal goal;
    goal.q = a.goal;
    goal.point = sc.part.point;
    goal.theta_weight = sc.part.point ? goal.theta_weight : sc.part.rho();
    std::printf(
        "bench_control: %s, %d starts over [-0.05, 0.05]^2 to (%g, %g%s) within 1 mm%s, %g s runs, %d motions "
        "(model built in %.3g s)\n",
        sc.name.c_str(), a.starts, a.goal.x(), a.goal.y(), a.rigid ? (", " + std::to_string(a.goal.z())).c_str() : "",
        a.rigid ? " and 0.02 rad" : "", a.duration, model.motions(), model_s);
    std::printf(
        "truth: friction x %g, each contact's also x (1 + e), e uniform in +-%g %%; amplitude %g %%, phase %g rad per "
        "period; camera: world, noise 0.1 mm%s, latency one period (%g s)\n",
        a.friction_scale, 100 * a.contact_spread, 100 * a.spread, a.spread, a.rigid ? " / 5 mrad" : "", sc.plate.T);
    std::printf("%5s %8s %8s %7s %9s %9s %9s %9s %5s %8s %8s %8s %7s%s\n", "start", "x0 [m]", "y0 [m]", "th0", "goal [s]",
                "err [mm]", "err [rad]", "overshoot", "sw", "dec mean", "dec p99", "dec max", "run [s]",
                a.open_loop.empty() ? "" : "  open-loop goal [s], err [mm], err [rad], run [s]");
    int met = 0, reached = 0, ol_reached = 0;
    double worst_time = 0, worst_decision = 0, ol_worst = 0;
    for (int i = a.first; i < a.first + a.starts; ++i) {
        const Vec3 q0 = square_start(static_cast<std::uint64_t>(i), a.rigid);
        Truth truth = spread_truth(a.friction_scale, a.spread, static_cast<std::uint64_t>(i));
        truth.uncertainty->friction = Spread{a.contact_spread, Distribution::uniform};
        truth.validate();
        const Camera cam = issue_camera(sc.plate.T, static_cast<std::uint64_t>(i), a.rigid);
        ControlOptions opt;
        opt.duration = a.duration;
        auto policy = a.mpc ? make_mpc_policy(a.mpc_options) : make_library_policy(a.policy);
        const auto t0 = std::chrono::steady_clock::now();
        const ControlSummary s = run_control(model, *policy, truth, cam, goal, q0, opt);
        const double run_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        reached += s.reached;
        met += s.reached && s.time_to_goal <= a.target;
        worst_time = std::max(worst_time, s.reached ? s.time_to_goal : 1e300);
        worst_decision = std::max(worst_decision, s.decision_max);
        std::printf("%5d %8.4f %8.4f %7.3f %9.3g %9.3g %9.3g %9.3g %5d %6.2gus %6.2gus %6.2gus %7.3g", i, q0.x(), q0.y(), q0.z(),
                    s.time_to_goal, s.final_error * 1e3, s.final_theta_error, s.worst_overshoot * 1e3, s.switches,
                    s.decision_mean * 1e6, s.decision_p99 * 1e6, s.decision_max * 1e6, run_s);
        if (s.stop.reason != StopReason::None) std::printf(" stopped: %s", s.stop.describe().c_str());
        if (a.mpc) {
            const MpcEstimate e = mpc_estimate(*policy);
            std::printf("  mpc gain %.3f drift (%.3g, %.3g) mm/period over %d frames", e.gain, 1e3 * e.drift.x(),
                        1e3 * e.drift.y(), e.frames);
        }
        if (!a.open_loop.empty()) {
            const ControlModel ol = open_loop_model(sc, a.open_loop);
            const std::unique_ptr<Policy> always = make_open_loop_policy();
            ControlOptions olo;
            olo.duration = a.open_loop_time;
            const auto t1 = std::chrono::steady_clock::now();
            Goal ol_goal = goal;
            ol_goal.tolerance = a.open_loop_tol;
            ol_goal.tolerance_theta = a.open_loop_tol_theta;
            const ControlSummary o = run_control(ol, *always, truth, std::nullopt, ol_goal, q0, olo);
            const double ol_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
            ol_reached += o.reached;
            ol_worst = std::max(ol_worst, o.reached ? o.time_to_goal : 1e300);
            std::printf("  %9.3g %9.3g %9.3g %7.3g", o.time_to_goal, o.final_error * 1e3, o.final_theta_error, ol_s);
            if (o.stop.reason != StopReason::None) std::printf(" stopped: %s", o.stop.describe().c_str());
        }
        std::printf("\n");
        std::fflush(stdout);
    }
    std::printf("reached and held: %d/%d; within %g s: %d/%d; slowest %.3g s; largest decision %.3g ms (target %d ms)\n", reached,
                a.starts, a.target, met, a.starts, worst_time, worst_decision * 1e3, a.mpc ? 10 : 1);
    if (!a.open_loop.empty())
        std::printf("open loop (%s): within %g mm and %g rad and held %d/%d within %g s; slowest %.3g s\n", a.open_loop.c_str(),
                    a.open_loop_tol * 1e3, a.open_loop_tol_theta, ol_reached, a.starts, a.open_loop_time, ol_worst);
    std::printf("machine: %s, %u hardware threads (one used)\n", bench::machine().c_str(), std::thread::hardware_concurrency());
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "bench_control: %s\n", e.what());
    return 2;
}
