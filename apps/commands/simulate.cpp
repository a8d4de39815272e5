// plate simulate: a U-dynamics, full-dynamics, averaged or field-integral-curve trajectory, as CSV;
// --dynamics auto picks the cheapest model predicted within --model-tol; --observe CAMERA.json writes
// what a camera records of a full or U-dynamics run instead (observe.hpp).
#include "commands.hpp"

#include "plate/hierarchy.hpp"
#include "plate/observe.hpp"
#include "plate/output.hpp"
#include "plate/simulate.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

namespace plate::cli {
namespace {

constexpr double kMaxRows = 1e7;   // rows of a trajectory CSV

struct SimulateArgs : Options {
    std::string scene, dynamics, out = "-", observe;
    std::vector<double> start, twist;
    double time = 0, sample = 0, model_tol = 1e-2;
    double rtol = IntegrationOptions{}.rtol, tol = LimitCycleOptions{}.tol;
    long max_steps = 0;
    bool verify = false;
    MeasuredArgs measured;
    explicit SimulateArgs(CLI::App& app)
        : Options(app, "simulate", "U-dynamics, full-dynamics or field-integral-curve trajectory, CSV",
                  "Trajectory from configuration --start with part twist --twist relative to the plate\n"
                  "(default: at rest). full: full dynamics (31) with the plate on SO(3); u: U-dynamics (32);\n"
                  "field: integral curve of the asymptotic twist field (RK4, 0.05 s steps). averaged: stroboscopic\n"
                  "averaging of the full dynamics (macro steps of many periods, each slope from a burst of the full\n"
                  "dynamics; coning included; rows after the first five periods interpolated, their twist and\n"
                  "normal forces nan).\n"
                  "auto: the cheapest of point/thin/thick part x field/u/full dynamics whose final configuration\n"
                  "is predicted within --model-tol E (default 1e-2; of rho and radians) of the scene's part\n"
                  "under full dynamics, decided up front from a few limit cycles at --start and the scene's\n"
                  "dimensionless numbers (hierarchy.hpp); --verify also runs the full model and reports the\n"
                  "measured error. The choice and its estimates go to stderr.\n"
                  "CSV with header t,s_x,s_y,theta,s_x_dot,s_y_dot,theta_dot,N1,N2,N3,mode (point parts:\n"
                  "t,s_x,s_y,s_x_dot,s_y_dot,N1,mode) every --sample seconds (default T/4 of the plate period...\n"
                  "0.0125 s for T = 0.05); mode is the contact mode on the step that ended there (slide, pivot1-3,\n"
                  "stuck: stick-slip is simulated through). Exit code 3\n"
                  "when a normal force reaches zero (the part would fly): the CSV then ends at that time.\n"
                  "--max-steps N: the work budget (integrator steps; for field, RK4 steps of the curve; default\n"
                  "2e7, field 1e4). The work is estimated up front from one plate period (or one RK4 step) and a\n"
                  "run that would exceed the budget is refused with the estimate (exit 2); at most 10^7 rows.\n"
                  "--observe CAMERA.json (full or u): --out gets the track a camera records instead of the\n"
                  "trajectory -- frames at rate_hz or once per period at a phase (stroboscopic), with pixel noise,\n"
                  "latency and dropped frames, in the plate's or the world's frame (the plate's own motion\n"
                  "included): '#' header lines (format version, scene name and scene_id, camera, frame, part), then\n"
                  "t [s],s_x [m],s_y [m],theta [rad] (point parts: no theta). t is the camera's stamp; the state\n"
                  "shown is at t - latency_s. The camera file: docs/guide.md, Observations.\n") {
        scene_file(scene);
        text("--dynamics", dynamics, "full|u|field|averaged|auto", "the model; required");
        numbers("--start", start, 2, 3, "SX SY THETA", "the start (point parts: SX SY); required");
        deprecated("--from", "--start");
        number("--time", time, "the duration T [s]; required", "");
        numbers("--twist", twist, 2, 3, "VX VY OMEGA", "the part's twist relative to the plate at the start");
        number("--sample", sample, "seconds between rows", "a quarter of the plate's period");
        text("--out", out, "FILE", "the CSV file (default: standard output)");
        text("--observe", observe, "CAMERA.json", "write the camera's track instead of the trajectory");
        number("--rtol", rtol, "integrator tolerance");
        number("--tol", tol, "limit-cycle tolerance of the field curve");
        unused("--max-periods");
        number("--model-tol", model_tol, "auto: the error allowed");
        add_measured_options(*this, measured);
        flag("--verify", verify, "auto: also run the full model and report the measured error");
        whole("--max-steps", max_steps, 1, 1'000'000'000'000L, "work budget, integrator steps", "2e7, field 1e4");
    }
};

// Bounded work (issue 18): the steps of a run of `dyn` over T seconds, extrapolated from one period
// (one RK4 step of a field curve, whose limit cycles are taken to `tol`) run first, against the
// budget (UsageError above it). `rows`: the CSV's, each of which ends a step.
void check_simulate_work(const Scene& sc_run, const std::string& dyn, const Vec3& q0, const Vec3& qd0, double T, double dt,
                         double rows, double tol, const IntegrationOptions& io, long budget) {
    const auto t0 = std::chrono::steady_clock::now();
    double steps = 0, pilot_steps = 0;
    std::string what;
    if (dyn == "field") {
        // RK4 steps of 0.05 s, and at least one per sample.
        LimitCycleOptions lo;
        lo.tol = tol;
        const double h = std::min(0.05, dt), span = std::min(T, h);
        const Trajectory pilot = field_curve(sc_run, q0, span, span, lo);
        pilot_steps = 1;
        steps = std::ceil(T / h);
        what = fmt(steps) + " RK4 steps of the field curve (one per 0.05 s, and per --sample)";
    } else {
        // Up to five periods: a start from rest can stick through the first.
        const double Tp = sc_run.plate.T, span = std::min(T, 5 * Tp);
        // (averaged: its bursts are full dynamics; the estimate is the direct run's, an upper bound)
        const Trajectory pilot = simulate(sc_run, dyn == "u" ? Dynamics::U : Dynamics::Full, q0, qd0, span, span, io);
        pilot_steps = std::max<double>(pilot.stats.steps, 1) * std::min(span, Tp) / span;   // per period
        steps = std::max(pilot_steps * T / std::min(span, Tp), rows);                       // (every row ends a step)
        what = fmt(steps) + " integrator steps (" + fmt(T / Tp) + " plate periods at " + fmt(pilot_steps) + " steps each)";
    }
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (steps > budget)
        throw UsageError("--time " + fmt(T) + " s would take about " + what + ", about " + fmt(secs / pilot_steps * steps) +
                         " s here, above the budget of " + fmt(static_cast<double>(budget)) +
                         " steps: raise it with --max-steps or shorten --time");
}

// The run's end: a run cut off by the budget is no result (nothing written); else `write` to --out,
// then exit 3 when a normal force reached zero, 1 at another stop, 0.
int finish(const SimulateArgs& a, const StopEvent& stop, const std::function<void(std::ostream&)>& write, Io& cio) {
    if (stop.reason == StopReason::StepLimit)   // the estimate was low: a cut-off run is not a result
        throw std::runtime_error(a.scene + ": stopped: " + stop.describe() +
                                 " (the up-front estimate was low: raise --max-steps); nothing written");
    write_file_atomic(a.out, write, cio.out);
    if (stop.reason != StopReason::None) {
        cio.err << "plate simulate: " << a.scene << ": stopped: " << stop.describe() << std::endl;
        return stop.reason == StopReason::ContactLost ? 3 : 1;
    }
    return 0;
}

// --observe: the camera's track of a full or U-dynamics run (observe()), at most kMaxRows frames, the
// work bounded as a trajectory's with a row per frame.
int observe_run(const SimulateArgs& a, const Scene& sc, const std::string& dyn, const Vec3& q0, const Vec3& qd0,
                IntegrationOptions io, Io& cio) {
    if (dyn != "full" && dyn != "u") throw UsageError("--observe goes with --dynamics full or u");
    if (a.has("--sample")) throw UsageError("--sample goes without --observe: the camera's schedule sets the frames");
    const Camera cam = load_camera(a.observe);
    const double T = a.time, per_second = cam.stroboscopic() ? cam.per_period / sc.plate.T : cam.rate;
    const double frames = std::floor(T * per_second) + 1;
    if (frames > kMaxRows)
        throw UsageError("the camera takes about " + fmt(frames) + " frames in --time " + fmt(T) + " s, above the limit of " +
                         fmt(kMaxRows));
    const std::size_t stamps = frame_stamps(cam, sc.plate.T, T).size();
    if (stamps < static_cast<std::size_t>(kMinTrackFrames))
        throw UsageError(a.observe + ": the camera takes " + std::to_string(stamps) + " frames in --time " + fmt(T) +
                         " s: a track needs at least " + std::to_string(kMinTrackFrames));
    io.max_steps = a.has("--max-steps") ? a.max_steps : io.max_steps;
    check_simulate_work(sc, dyn, q0, qd0, T, std::min(sc.plate.T, 1 / per_second), frames, a.tol, io, io.max_steps);
    Trajectory exact;
    const Track tr = observe(sc, cam, dyn == "full" ? Dynamics::Full : Dynamics::U, q0, qd0, T, io, &exact);
    if (exact.stop.reason != StopReason::StepLimit && tr.t.size() < static_cast<std::size_t>(kMinTrackFrames))
        throw std::runtime_error(a.scene + ": the camera recorded " + std::to_string(tr.t.size()) +
                                 " frames (dropped or after a stop): a track needs at least " + std::to_string(kMinTrackFrames) +
                                 "; nothing written");
    return finish(
        a, exact.stop, [&](std::ostream& out) { write_track_csv(out, tr); }, cio);
}

int cmd_simulate(const SimulateArgs& a, Io& cio) {
    const Scene sc = measured_arg(a, a.measured, scene_arg(a.scene, cio), cio);
    std::string dyn = a.dynamics;
    if (dyn != "full" && dyn != "u" && dyn != "field" && dyn != "averaged" && dyn != "auto")
        throw UsageError("--dynamics: expected full, u, field, averaged or auto");
    const Vec3 q0 = config_arg(a, "--start", a.start, sc, true);
    const Vec3 qd0 = config_arg(a, "--twist", a.twist, sc, false);
    if (!a.has("--time")) throw UsageError("missing --time T");
    const double T = a.time;
    const double dt = a.has("--sample") ? a.sample : sc.plate.T / 4;
    if (!(T > 0) || !(dt > 0)) throw UsageError("--time and --sample must be > 0");
    IntegrationOptions io;
    io.rtol = a.rtol;
    Trajectory tr;
    ProgressPrinter prog{"simulate"};
    prog.to = &cio.err == &std::cerr && progress_wanted() ? &cio.err : nullptr;
    Scene used = sc;
    bool verify_auto = false;
    if (dyn == "auto") {
        if (!qd0.isZero()) throw UsageError("--dynamics auto answers from rest: drop --twist");
        const double tol = a.model_tol;
        if (!(tol > 0)) throw UsageError("--model-tol must be > 0");
        const ModelPick pick = pick_model(sc, q0, T, tol);
        const ModelEstimate& est = pick.estimate;
        cio.err << "auto model, decided up front (tolerance " << tol << "): picked " << pick.rung.name() << " (predicted error "
                << pick.predicted << ")\n  estimates: |xi| " << est.xi << "/s, point " << est.e_point << ", thin " << est.e_thin
                << ", eps_U " << est.eps_U << ", transient offset " << est.offset << ", growth " << est.growth()
                << (est.ok ? "" : " (" + est.note + ")") << "\n";
        used = pick.scene;
        const Dynamics d = pick.rung.dynamics;
        dyn = d == Dynamics::Full ? "full" : d == Dynamics::U ? "u" : "field";
        verify_auto = a.verify && pick.rung.name() != Rung{}.name();
    } else if (a.verify) {
        throw UsageError("--verify goes with --dynamics auto");
    }
    const Scene& sc_run = used;
    if (a.has("--observe")) return observe_run(a, sc_run, dyn, q0, qd0, io, cio);
    // Bounded work (issue 18): rows, then the steps (check_simulate_work).
    const double rows = std::ceil(T / dt) + 1;
    if (rows > kMaxRows)
        throw UsageError("--time / --sample give " + fmt(rows) + " rows, above the limit of " + fmt(kMaxRows) +
                         ": sample less often");
    const bool field_dyn = dyn == "field";
    const long budget = a.has("--max-steps") ? a.max_steps : field_dyn ? 10'000 : io.max_steps;
    io.max_steps = budget;
    check_simulate_work(sc_run, dyn, q0, qd0, T, dt, rows, a.tol, io, budget);
    if (dyn == "field") {
        if (!qd0.isZero()) throw UsageError("--twist has no meaning for --dynamics field");
        LimitCycleOptions lo;
        lo.tol = a.tol;
        tr = field_curve(sc_run, q0, T, dt, lo);
    } else if (dyn == "averaged") {
        tr = simulate_averaged(sc_run, q0, qd0, T, dt, io);
    } else {
        tr = simulate(sc_run, dyn == "full" ? Dynamics::Full : Dynamics::U, q0, qd0, T, dt, io);
    }
    if (verify_auto && tr.stop.reason == StopReason::None && !tr.samples.empty()) {
        const Trajectory ref = simulate(sc, Dynamics::Full, q0, Vec3::Zero(), T, T, io);
        if (ref.stop.reason == StopReason::None && !ref.samples.empty()) {
            const Vec3 dq = tr.samples.back().q - ref.samples.back().q;
            cio.err << "  verified against the full model: measured error "
                    << std::max({std::abs(dq[0]) / sc.part.rho(), std::abs(dq[1]) / sc.part.rho(), std::abs(wrap_angle(dq[2]))})
                    << "\n";
        } else {
            cio.err << "  verify: the full model stopped: " << ref.stop.describe() << "\n";
        }
    }
    return finish(
        a, tr.stop, [&](std::ostream& out) { write_trajectory_csv(out, tr, sc_run.part.point); }, cio);
}

}   // namespace

Command add_simulate(CLI::App& app) { return make_command<SimulateArgs>(app, cmd_simulate); }

}   // namespace plate::cli
