// Limit cycles of the reduced U-dynamics and asymptotic twists (Section IV-A/B).
//
// From an initial twist at a frozen configuration q0, integrate (35) period by period until
// the state at the start of a period repeats (Observation 1, Theorem 1), then return the
// period average (36). Convergence is judged by the error estimate of a contracting
// fixed-point iteration: with residual r_k = |x_k - x_{k-1}| and contraction c = r_k/r_{k-1},
// the distance to the cycle is about r_k c / (1 - c); the cycle is accepted when that is below
// tol (both in units of the slip-speed scale Scene::v_ref(), angular rates times rho).
#pragma once

#include "plate/simulate.hpp"

#include <string>
#include <vector>

namespace plate {

// How the fixed point of the period map P (state at t = 0 -> state at t = T) is found:
//   PeriodByPeriod  x_{k+1} = P(x_k) until the contraction estimate says the cycle is reached
//   Anderson        the same periods, but each new start is Anderson's extrapolation from the last
//                   (up to 3) pairs (x_j, P(x_j)); falls back to period by period if a start leaves
//                   the model
//   Newton          Newton shooting on P(x) - x = 0 (GSL multiroot, gnewton), monodromy by finite
//                   differences of P (3 extra periods per iteration)
//   Shooting        Newton shooting with the monodromy M = dP/dx from the variational equations
//                   (the generated d q''/d q', trapezoidal rule on the engine's steps) along the
//                   first period; then chord steps with that M (plain periods) while they contract,
//                   a fresh M where they stop. The reported twist is the last period's average
//                   corrected to first order by its sensitivity to the start and the last step.
//                   Needs a warm start near the cycle (fields predict one from solved neighbours);
//                   without one (qd0 = 0), or with `record`, it is Anderson. Falls back to Anderson.
//                   Through stick-slip: a period in which the part sticks as a whole has M = 0
//                   exactly (its end does not depend on its start: the next period is the cycle);
//                   one with a pivot or a partial stick takes M by forward differences of P, the
//                   product of the sliding flows and the saltations at the switches, when its start
//                   is within 1e-3 of the scales of its image (else Anderson's periods are cheaper).
// The speed-accuracy study (plate bench) charts cost against accuracy for each.
enum class CycleSolver { PeriodByPeriod, Anderson, Newton, Shooting };
const char* cycle_solver_name(CycleSolver s);
CycleSolver parse_cycle_solver(const std::string& name);   // throws std::invalid_argument

// The cycles' integration: rtol 1e-8, and ten times that on steps where every slip is large
// (IntegrationOptions::large_slip_factor).
inline IntegrationOptions cycle_integration() {
    IntegrationOptions io;
    io.rtol = 1e-8;
    io.large_slip_factor = 10;
    return io;
}

struct LimitCycleOptions {
    IntegrationOptions integration = cycle_integration();
    double tol = 1e-7;       // accepted distance to the cycle, relative to v_ref
    int max_periods = 400;   // then "not converged"
    bool record = false;     // keep every accepted step (for plots and tests)
    // Observation 1 makes the cycle independent of the initial twist. When contact is lost in the
    // transient (a part released at rest can tip where its sliding cycle does not), start again from
    // other twists (slip speed v_ref along x, then y, then a spin) up to this many times. A cycle
    // that loses contact from every start is reported as contact lost.
    int restarts = 3;
    CycleSolver solver = CycleSolver::Shooting;   // the fastest on fig4's field (plate bench)
    int anderson_memory = 3;
    // The work budget of one cycle, all its periods, restarts and fallbacks together: right-hand
    // sides (a cycle takes 10^3 to 10^5; 2e7 is about 3 s). Then StepLimit ("work budget").
    long max_rhs_evaluations = 20'000'000;
    // Shooting: the first period at one tolerance (integration.large_slip_factor then applies from the
    // second period on, if the first did not change mode): a field sets it where the point before
    // this one changed mode.
    bool first_period_tight = false;
};

struct LimitCycleSummary {
    bool converged = false;
    int periods = 0;                                                         // periods integrated
    double residual = 0;                                                     // last r_k, relative to v_ref
    double error_estimate = 0;                                               // r_k c/(1-c), relative to v_ref
    double contraction = 0;                                                  // c, per period
    Vec3 twist = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());   // xi_a (36)
    Vec3 qd_start = Vec3::Zero();   // the cycle's start (a warm start): the last period's start; shooting: its Newton update
    // Shooting: the monodromy dP/dx (its eigenvalues are the cycle's Floquet multipliers; all zero
    // for a cycle in which the part sticks as a whole) in the
    // scaled twist (v_ref, v_ref, v_ref / rho), at the start where it was last computed.
    bool has_monodromy = false;
    Mat3 monodromy = Mat3::Zero();
    double min_normal_force = 0;   // smallest N_i over the last period [N]
    double step_hint = 0;          // the step proposed at the end, relative to T: a first step
                                   // (IntegrationOptions::h0) for a neighbouring configuration
    // Stick-slip over the cycle's last period: the fraction of the period each contact had zero slip
    // (held: stuck, or the pivot), the mode at the period's start and every change of mode (t from
    // the period's start). A part stuck all period long has stick fractions 1 and twist exactly 0.
    std::array<double, 3> stick_fraction{};
    Mode start_mode;
    std::vector<ModeEvent> mode_events;
    bool stuck_all_period() const { return converged && start_mode.kind == ModeKind::Stuck && mode_events.empty(); }
    StopEvent stop;
    Stats stats;                              // accumulated over restarts
    int restarts = 0;                         // starts abandoned because contact was lost in the transient
    std::vector<StopEvent> transient_stops;   // why each abandoned start stopped
    std::vector<Sample> path;                 // with record: every accepted step from t = 0
    std::string note;                         // why no cycle was sought, if so

    bool contact_lost() const { return stop.reason == StopReason::ContactLost; }
    bool sticking() const { return stop.reason == StopReason::Sticking; }
    std::string report() const;   // a few lines saying what happened
};

LimitCycleSummary limit_cycle(const Scene& scene, const Vec3& q0, const LimitCycleOptions& opt = {},
                              const Vec3& qd0 = Vec3::Zero());

// The period map of the reduced U-dynamics at q0: the twist at t = T from qd0 at t = 0.
// Returns false (and leaves `out` unchanged) if the period leaves the model (stop says why).
bool period_map(const Scene& scene, const Vec3& q0, const Vec3& qd0, Vec3& out, const IntegrationOptions& opt = {},
                StopEvent* stop = nullptr);

}   // namespace plate
