// plate control: closed-loop control of a part from camera frames (control.hpp), against a true plate.
#include "commands.hpp"

#include "plate/control.hpp"
#include "plate/control_multi.hpp"
#include "plate/output.hpp"

#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

namespace plate::cli {
namespace {

struct ControlArgs : Options {
    std::string scene, policy, library, camera, truth, out, parts;
    std::vector<double> goal, start;
    double time = 0, tol = Goal{}.tolerance, tol_theta = Goal{}.tolerance_theta, theta_weight = Goal{}.theta_weight;
    double stop_radius = LibraryPolicyOptions{}.stop_radius, hysteresis = LibraryPolicyOptions{}.hysteresis;
    int horizon = 0;   // (0: the policy's default)
    double switch_cost = MpcPolicyOptions{}.switch_cost;
    bool no_correction = false;
    GridArgs grid = [] {
        GridArgs g;
        g.n = 13;
        return g;
    }();
    explicit ControlArgs(CLI::App& app)
        : Options(app, "control", "closed-loop control: a policy steers the part from camera frames, CSV",
                  "Steers the part of SCENE from --start (default: the origin) to --goal, choosing each plate period's\n"
                  "motion from what a camera sees (--camera CAM.json: one stroboscopic frame per period, with noise,\n"
                  "latency and drops; default: a perfect camera), against a true plate and part (--truth TRUTH.json:\n"
                  "the scene perturbed by an uncertainty spec, tracking errors drawn per period, friction scaled;\n"
                  "default: the scene itself) run through the full dynamics, stick-slip included. The motion changes\n"
                  "only at period boundaries; the part's world position and in-plane velocity are continuous there.\n"
                  "--policy library --library LIB.json: each period the library motion that, kept for --horizon\n"
                  "periods (default 2), stays nearest the goal on average -- the first period's step from the switch\n"
                  "(tabulated: the part arrives with the old motion's velocity), then q + xi(q) T (fields tabulated\n"
                  "once: a plate that only translates gives a point part one velocity everywhere; other motions on\n"
                  "the --grid over --x, --y); the observation predicted forward over the camera's latency; inside\n"
                  "--stop-radius the still plate (its frames averaged), and a motion kept unless another does better\n"
                  "by --hysteresis. The library file: docs/guide.md, control.\n"
                  "--policy mpc --library LIB.json: each period the sequence of --horizon motions (default 3;\n"
                  "every one of motions^horizon searched, a switch allowed each period) whose predicted path costs\n"
                  "least: the mean over the periods of the distance to the goal (a rigid part's weighted, theta\n"
                  "by rho), plus --switch-cost in a period that switches; its first motion is applied.\n"
                  "The prediction is corrected online: a gain on the model's steps and a drift per period, fitted to\n"
                  "the frames by forgetting least squares (--no-correction: the nominal model). Stop radius and\n"
                  "hysteresis as for library.\n"
                  "--parts PARTS.json (point parts, --policy library): several parts on one plate, each to its own goal\n"
                  "({\"parts\": [{\"goal\": [X, Y], \"start\": [X, Y], \"weight\": W}, ...]}, start and weight optional;\n"
                  "instead of --goal and --start): each period the one motion whose predicted paths have the least sum\n"
                  "of the parts' weighted distances to their goals; the camera films every part (part i's seed: the\n"
                  "camera's + i); the parts do not interact. --out's columns per part (obs_s_x_1, ..., x_1, y_1, ...),\n"
                  "the summary's per part under \"parts\"; exit 0 only when every part holds its goal at the end.\n"
                  "--out gets one row per period: t [s], the observed and the true configuration, the motion chosen\n"
                  "and the decision's time [s] (17 significant digits); the summary (time to goal: from when the part\n"
                  "stays within --tol to the end; final error, switches, worst overshoot, decision times) to stdout\n"
                  "as JSON. Exit 1 if the goal is not reached and held at the end, 3 if the true part loses contact.\n") {
        scene_file(scene);
        numbers("--goal", goal, 2, 3, "X Y [THETA]", "the goal (point parts: X Y); required unless --parts");
        text("--parts", parts, "PARTS.json", "several point parts and their goals (instead of --goal, --start)");
        numbers("--start", start, 2, 3, "SX SY [THETA]", "the start, at rest on the plate");
        text("--policy", policy, "library|mpc", "the policy; required");
        text("--library", library, "LIB.json", "the motions (library and mpc)");
        text("--camera", camera, "CAMERA.json", "the camera (stroboscopic, one frame per period)");
        text("--truth", truth, "TRUTH.json", "the true plate and part");
        number("--time", time, "the run's duration [s]; required", "");
        text("--out", out, "RUN.csv", "the run's rows; required");
        number("--tol", tol, "the goal's tolerance on the position [m]");
        number("--tol-theta", tol_theta, "the goal's tolerance on theta [rad] (rigid parts)");
        number("--theta-weight", theta_weight, "metres per radian in the distance to the goal");
        number("--stop-radius", stop_radius, "hold the still plate within this distance [m]");
        number("--hysteresis", hysteresis,
               "library: switch only for a step nearer by this; both: leave the still plate beyond "
               "the stop radius plus this [m]");
        whole("--horizon", horizon, 1, kMaxHorizon,
              "periods: library, a motion judged kept for; mpc, the sequences' length (at most 8)", "2 for library, 3 for mpc");
        number("--switch-cost", switch_cost, "mpc: the cost of a switch, in metres of distance");
        flag("--no-correction", no_correction, "mpc: no online gain and drift (the nominal model)");
        add_grid_options(*this, grid);
    }
};

// Several parts (--parts): the multi-part loop, its CSV and its summary; exit 0 when every part holds its goal.
int run_multi(const ControlArgs& a, const ControlModel& model, const LibraryPolicyOptions& lo, const Truth& truth,
              const std::optional<Camera>& camera, const MultiParts& parts, const ControlOptions& opt, Io& cio) {
    auto policy = make_multi_library_policy(lo);
    const MultiControlSummary s = run_multi_control(model, *policy, truth, camera, parts, opt);
    write_file_atomic(a.out, [&](std::ostream& out) { write_multi_control_csv(out, s, model); });
    cio.out << multi_control_summary_json(s, model, parts).dump(2) << "\n";
    if (s.stop.reason != StopReason::None) {
        cio.err << "plate control: " << a.scene << ": a true part stopped: " << s.stop.describe() << std::endl;
        return s.stop.reason == StopReason::ContactLost ? 3 : 1;
    }
    return s.reached ? 0 : 1;
}

int cmd_control(const ControlArgs& a, Io& cio) {
    const Scene sc = scene_arg(a.scene, cio);
    if (!(a.tol > 0) || !(a.tol_theta > 0) || !(a.theta_weight >= 0))
        throw UsageError("--tol and --tol-theta must be > 0, --theta-weight >= 0");
    const bool multi = a.has("--parts");
    Goal goal;
    Vec3 q0 = Vec3::Zero();
    MultiParts parts;
    if (multi) {
        if (a.has("--goal") || a.has("--start"))
            throw UsageError("--parts gives the parts' goals and starts: not with --goal or --start");
        parts = load_parts(a.parts);
        if (a.has("--tol")) parts.tolerance = a.tol;
        parts.validate(sc);   // (an InputError naming the file and the field: exit 2)
    } else {
        goal.q = config_arg(a, "--goal", a.goal, sc, true);
        goal.point = sc.part.point;
        goal.tolerance = a.tol;
        goal.tolerance_theta = a.tol_theta;
        goal.theta_weight = a.theta_weight;
        q0 = config_arg(a, "--start", a.start, sc, false);
    }
    if (!a.has("--policy")) throw UsageError("missing --policy library|mpc");
    if (multi && a.policy != "library") throw UsageError("--parts: the library policy steers several parts (--policy library)");
    if (a.policy != "library" && a.policy != "mpc")
        throw UsageError("--policy: expected library or mpc (a Python callable: plate.control in Python), got '" + a.policy +
                         "'");
    if (!a.has("--library")) throw UsageError("--policy " + a.policy + " needs --library LIB.json");
    if (a.policy == "library" && (a.has("--switch-cost") || a.has("--no-correction")))
        throw UsageError("--switch-cost and --no-correction are the mpc policy's");
    if (!a.has("--time")) throw UsageError("missing --time T");
    if (!a.has("--out")) throw UsageError("missing --out RUN.csv");
    ControlOptions opt;
    opt.duration = a.time;
    LibraryPolicyOptions lo;
    lo.stop_radius = a.stop_radius;
    lo.hysteresis = a.hysteresis;
    if (a.horizon > 0) lo.horizon = a.horizon;
    MpcPolicyOptions mpo;
    mpo.stop_radius = a.stop_radius;
    mpo.hysteresis = a.hysteresis;
    mpo.switch_cost = a.switch_cost;
    mpo.correct = !a.no_correction;
    if (a.horizon > 0) mpo.horizon = a.horizon;
    ControlModelOptions mo;
    mo.grid = grid_opts(a, a.grid);
    mo.field.threads = a.grid.threads;
    mo.field.cycle.max_rhs_evaluations = kCliCycleBudget;
    try {   // judged once, in the library; named here by their flags
        opt.validate();
        lo.validate();
        mpo.validate();
        mo.validate();
    } catch (const std::invalid_argument& e) {
        throw UsageError(std::string("--time, --stop-radius, --hysteresis, --horizon, --switch-cost or the grid: ") + e.what());
    }
    if (a.time / sc.plate.T > static_cast<double>(kMaxControlPeriods))
        throw UsageError("--time " + fmt(a.time) + " s is more than " + fmt(static_cast<double>(kMaxControlPeriods)) +
                         " plate periods");
    const Truth truth = a.has("--truth") ? load_truth(a.truth) : Truth{};
    const std::optional<Camera> camera = a.has("--camera") ? std::optional<Camera>(load_camera(a.camera)) : std::nullopt;
    const ControlModel model = build_control_model(sc, load_motion_library(a.library, sc), mo);
    if (multi) return run_multi(a, model, lo, truth, camera, parts, opt, cio);
    std::unique_ptr<Policy> policy;
    try {
        policy = a.policy == "mpc" ? make_mpc_policy(mpo) : make_library_policy(lo);
        policy->reset(model, goal);   // (what the policy cannot steer, refused before the run)
    } catch (const std::invalid_argument& e) {
        throw UsageError(std::string("--policy ") + a.policy + ": " + e.what());
    }
    const ControlSummary s = run_control(model, *policy, truth, camera, goal, q0, opt);
    write_file_atomic(a.out, [&](std::ostream& out) { write_control_csv(out, s, model, sc.part.point); });
    cio.out << control_summary_json(s, model, goal).dump(2) << "\n";
    if (s.stop.reason != StopReason::None) {
        cio.err << "plate control: " << a.scene << ": the true part stopped: " << s.stop.describe() << std::endl;
        return s.stop.reason == StopReason::ContactLost ? 3 : 1;
    }
    return s.reached ? 0 : 1;
}

}   // namespace

Command add_control(CLI::App& app) { return make_command(app, cmd_control); }

}   // namespace plate::cli
