// Integrating the dynamics in time: U- and full-dynamics trajectories (Section III-F/G),
// with the model's assumptions watched at every accepted step.
//
// Stops (never silently integrated through):
//   ContactLost  a normal force N_i < 0 (Section III-F)
//   Sticking     a contact reaches zero slip and static friction could hold it (Section IV-E)
//   StepCollapse the adaptive step fell below h_min (the method cannot resolve the motion)
//   StepLimit    more than max_steps steps
//   NotConverged (limit cycles, fields) no cycle within the period cap
// A contact whose slip passes through zero while friction cannot hold it (a slip reversal)
// is a legitimate Coulomb transition: it is counted, not a stop.
#pragma once

#include "plate/dynamics.hpp"
#include "plate/model.hpp"

#include <string>
#include <vector>

namespace plate {

struct IntegrationOptions {
    double rtol = 1e-9;        // local error tolerance on the scaled state (see engine)
    double slip_eps = 1e-6;    // slip speed counted as zero, relative to Scene::v_ref()
    double h_min = 1e-12;      // smallest step, relative to the period T
    double h0 = 0;             // first step, relative to T; 0: a small one from rtol (a neighbouring
                               // run's LimitCycleSummary::step_hint saves the ramp-up)
    long max_steps = 20'000'000;
};

enum class StopReason { None, ContactLost, Sticking, StepCollapse, StepLimit, NotConverged };
const char* stop_name(StopReason r);

struct StopEvent {
    StopReason reason = StopReason::None;
    int contact = -1;     // 0-based contact index (ContactLost, Sticking)
    double t = 0;         // time of the event [s]
    std::string describe() const;   // e.g. "contact 2 lost at t = 0.0312 s"
};

struct Stats {
    long rhs_evals = 0;
    long steps = 0;
    long rejected = 0;
    long slip_reversals = 0;
    double min_normal_force = 0;   // smallest N_i seen at accepted steps [N]
    // Adds the counts of another run (restarts, fallbacks); min_normal_force is left as it is.
    Stats& operator+=(const Stats& o) {
        rhs_evals += o.rhs_evals;
        steps += o.steps;
        rejected += o.rejected;
        slip_reversals += o.slip_reversals;
        return *this;
    }
};

struct Sample {
    double t = 0;
    Vec3 q = Vec3::Zero();    // (s_x, s_y, theta)
    Vec3 qd = Vec3::Zero();   // (s_x', s_y', theta')
    Vec3 n = Vec3::Zero();    // (N1, N2, N3)
};

struct Trajectory {
    std::vector<Sample> samples;   // every sample_dt, and the stop time
    StopEvent stop;
    Stats stats;
};

// A part at rest relative to the plate rides with it while friction can supply the wrench that
// keeps it there (stick_test_all, from the U-dynamics' b~ (33)-(34)). Returns the first time >= t0 at which it breaks away and starts sliding, or NaN
// if it stays stuck for a whole period. Trajectories and limit cycles that start at rest
// begin sliding at this time.
double breakaway_time(const Scene& scene, const Vec3& q0, double t0);

// Simulates U-dynamics (32) or full dynamics (31) from configuration q0 and twist qd0
// (relative to the plate) at t = 0 for `duration` seconds. Full dynamics start the plate on
// its zero-mean periodic motion (PlateMotion::velocity/displacement). A start at rest (qd0 = 0)
// rides with the plate until breakaway_time; a part that never breaks away stops as Sticking.
Trajectory simulate(const Scene& scene, Dynamics level, const Vec3& q0, const Vec3& qd0, double duration,
                    double sample_dt, const IntegrationOptions& opt = {});

}  // namespace plate
