// Integrating the dynamics in time: U- and full-dynamics trajectories (Section III-F/G), through
// stick-slip (modes.hpp): the part slides, pivots about a contact or rides the plate, and the
// engine locates each change of mode as an event.
//
// Stops (never silently integrated through):
//   ContactLost        a normal force N_i reaches zero (the part would fly; Section III-F)
//   StepCollapse       the adaptive step fell below h_min (the method cannot resolve the motion)
//   StepLimit          more than max_steps steps
//   EventAccumulation  more than a thousand mode changes within 1e-9 T (a Zeno point)
//   NotConverged       (limit cycles, fields) no cycle within the period cap
//   Sticking           only from the methods of the speed study that have no stick-slip model
//                      (methods.hpp); the engine itself never stops at a stick
#pragma once

#include "plate/dynamics.hpp"
#include "plate/modes.hpp"
#include "plate/model.hpp"

#include <string>
#include <vector>

namespace plate {

struct IntegrationOptions {
    double rtol = 1e-9;       // local error tolerance on the scaled state (see engine)
    double slip_eps = 1e-6;   // slip speed counted as zero, relative to Scene::v_ref()
    double h_min = 1e-12;     // smallest step, relative to the period T
    double h0 = 0;            // first step, relative to T; 0: a small one from rtol (a neighbouring
                              // run's LimitCycleSummary::step_hint saves the ramp-up)
    // The work budget of one run: accepted steps, and right-hand sides (rejected tries, event
    // location, creep solves) at ten per step; then StepLimit.
    long max_steps = 20'000'000;
    // Steps that start with every contact sliding at more than 3e-2 v_ref (no creep, no held
    // contact) take large_slip_factor * rtol, up to 1e-6 (never less than rtol). There the dynamics
    // are smooth and contract (friction damps the relative motion), so a local error only shifts the
    // path; near zero slip it also shifts when a contact sticks, breaks away or reverses, which is
    // where the sticking cycles' error comes from. 1: one tolerance everywhere (trajectories); the
    // shooting of limit cycles uses 10 (cycle_integration(), limit_cycle.hpp; Anderson and plain
    // periods take 1 whatever is set).
    double large_slip_factor = 1;
};

enum class StopReason { None, ContactLost, Sticking, StepCollapse, StepLimit, NotConverged, EventAccumulation };
const char* stop_name(StopReason r);

struct StopEvent {
    StopReason reason = StopReason::None;
    int contact = -1;               // 0-based contact index (ContactLost, Sticking)
    double t = 0;                   // time of the event [s]
    std::string describe() const;   // e.g. "contact 2 lost at t = 0.0312 s"
};

struct Stats {
    long rhs_evals = 0;
    long steps = 0;
    long rejected = 0;
    long slip_reversals = 0;       // slips that reached zero and slid on (the stick test failed)
    long mode_switches = 0;        // changes of contact mode (modes.hpp)
    double min_normal_force = 0;   // smallest N_i seen at accepted steps [N]
    // Adds the counts of another run (restarts, fallbacks); min_normal_force is left as it is.
    Stats& operator+=(const Stats& o) {
        rhs_evals += o.rhs_evals;
        steps += o.steps;
        rejected += o.rejected;
        slip_reversals += o.slip_reversals;
        mode_switches += o.mode_switches;
        return *this;
    }
};

struct Sample {
    double t = 0;
    Vec3 q = Vec3::Zero();    // (s_x, s_y, theta)
    Vec3 qd = Vec3::Zero();   // (s_x', s_y', theta')
    Vec3 n = Vec3::Zero();    // (N1, N2, N3)
    Mode mode;                // contact mode on the step that ended here
};

// A change of contact mode at time t.
struct ModeEvent {
    double t = 0;
    Mode from, to;
};

struct Trajectory {
    std::vector<Sample> samples;   // every sample_dt, and the stop time
    StopEvent stop;
    Stats stats;
    std::vector<ModeEvent> events;       // every change of contact mode
    std::array<double, 3> held_time{};   // time each contact had zero slip [s]
};

// A part at rest relative to the plate at q0 rides with it while friction can hold it (the gauge of
// friction.hpp, from the needed wrench of `level`'s right-hand side; full dynamics: the plate tilted as
// its zero-mean motion has it). Returns the first time >= t0 at which it breaks away, located as the
// engine locates it, or NaN if it stays stuck for a whole period.
double breakaway_time(const Scene& scene, const Vec3& q0, double t0, Dynamics level = Dynamics::U);

// Simulates U-dynamics (32) or full dynamics (31) from configuration q0 and twist qd0 (relative to
// the plate) at t = 0 for `duration` seconds, through stick-slip. Full dynamics start the plate on
// its zero-mean periodic motion (PlateMotion::velocity/displacement). A start at rest (qd0 = 0) is
// stuck while friction can hold the part.
Trajectory simulate(const Scene& scene, Dynamics level, const Vec3& q0, const Vec3& qd0, double duration, double sample_dt,
                    const IntegrationOptions& opt = {});

// simulate() sampled at the given times (finite, increasing, >= 0; std::invalid_argument else), the
// engine stepping to each exactly: the states a camera's frames show (observe.hpp). A run that stops
// ends with a sample at the stop time, as simulate()'s.
Trajectory simulate_at(const Scene& scene, Dynamics level, const Vec3& q0, const Vec3& qd0, const std::vector<double>& times,
                       const IntegrationOptions& opt = {});

// STROBOSCOPIC AVERAGING of the full dynamics (a heterogeneous multiscale method, after Calvo,
// Chartier, Murua and Sanz-Serna's stroboscopic averaging). Over one period the configuration q and
// the plate's orientation phi (which drifts: coning, design.hpp) move little, while the twist
// settles onto its cycle within a period or two. Heun's method steps (q, phi) over macro steps of
// K periods (K from the step's error estimate, H/2 |k2 - k1| relative to (rho, rho, 1 rad), held
// below macro_tol, at most max_macro_periods); each stage's slope is measured by a burst of the
// full dynamics at that stage's time:
// `relax` periods for the twist to settle, then one period's change over T, the burst started
// (relax + 1/2) periods' drift early so that the measured period is centred on the stage's point.
// An accepted macro step costs 2 (relax + 1) periods instead of K. Unlike the asymptotic field's integral
// curve (field_curve: U-dynamics, first-order average) it keeps everything the full dynamics have --
// coning, the tilt's and the rotating frame's second-order drifts, stick-slip within a burst. The
// start is integrated directly (the transient from qd0): at least start_periods, and on until the
// twist at the periods' starts changes by at most macro_tol of its scales over a period (the bursts'
// relax periods assume a settled twist); so is a last partial period. Samples every sample_dt: the start's own, then cubic
// Hermite interpolants of the macro points (their qd and n NaN). A burst that stops ends the averaging: the rest is integrated
// directly from the last accepted macro point, so a stop (contact lost) is reported with its real time and state (a stopped
// predictor at K > 1 is only a rejected step). Stats are the bursts' (steps and rejected: also the macro steps'); events and
// held_time are not kept; opt.max_steps bounds each burst.
struct AveragingOptions {
    double macro_tol = 1e-3;      // local error of a macro step, relative to (rho, rho, 1 rad)
    int max_macro_periods = 40;   // the largest K
    int relax_periods = 2;
    int start_periods = 5;   // at least (also the first K); 0: no direct start
};
Trajectory simulate_averaged(const Scene& scene, const Vec3& q0, const Vec3& qd0, double duration, double sample_dt,
                             const IntegrationOptions& opt = {}, const AveragingOptions& avg = {});

}   // namespace plate
