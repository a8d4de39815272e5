// Robustness of a plate motion under an uncertainty spec (issue 51): where the part goes on the
// plates a real rig may be, by Monte Carlo over the spec's draws, and to first order by the implicit
// function theorem.
//
// PER DRAW (uncertainty.hpp's draw(nominal, spec, i), i = 0 .. draws - 1): the field on the grid, its
// fixed points, and one OUTCOME --
//   unique        one stable fixed point (no stable line, no stuck cell) and it is the target's:
//                 within match_distance and match_angle of the target;
//   competing     the target's stable point is there, and so is another attractor (a stable point,
//                 a stable line, or cells where the part is stuck all period);
//   none          no stable fixed point at the target;
//   contact lost  a configuration of the grid loses contact (the part would fly: the field there,
//                 and where the part goes, is not defined);
//   failed        a cycle did not converge or the work budget was spent (never a crash).
// From seeded starts (the same for every draw) the time the field's integral curve takes to come
// within arrive_distance and arrive_angle of the target; for the first full_draws draws also the full
// dynamics' (at the period's start, the time after which it stays within them).
//
// SENSITIVITIES. At the nominal fixed point q* the field xi(q, p) vanishes; for small deviations p of
// the spec's parameters (uncertain_parameters) the fixed point moves by dq = S p with
// S = -(d xi / d q)^-1 (d xi / d p) (implicit function theorem), both Jacobians by central differences.
// Its predicted covariance is S diag(sd^2) S^T; the Monte Carlo draws' own p give each draw's linear
// prediction S p, compared with where its fixed point really went (the response is linear where they
// agree).
#pragma once

#include "plate/field.hpp"
#include "plate/uncertainty.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace plate {

enum class Outcome { unique, competing, none, contact_lost, failed };
const char* outcome_name(Outcome o);   // "unique", "competing", "none", "contact lost", "failed"
inline constexpr int kOutcomes = 5;

struct RobustnessOptions {
    int draws = 200;
    // The fixed point followed (point parts: theta unused). Not set: the nominal field's stable fixed
    // point, which must then be its only one.
    std::optional<Vec3> target;
    GridSpec grid;                    // the field of every draw (default 7^3 over [-0.05, 0.05]^2 m)
    FixedPointOptions fixed;          // its cycles (fixed.cycle) and the refinement
    double match_distance = 0.01;     // a stable fixed point this near the target is the target's [m]
    double match_angle = 0.5;         // and this near in theta [rad] (a half-turn twin is pi away)
    int starts = 8;                   // seeded starts, uniform over the grid's square and the full turn
    double arrive_distance = 0.005;   // arrival: within this of the target [m]
    double arrive_angle = 0.05;       // and this in theta [rad]
    double horizon = 60;              // the longest arrival followed [s] (later: not arrived)
    double curve_step = 0.5;          // RK4 step of the field's integral curves [s] (the arrival times' resolution)
    int full_draws = 4;               // draws (the first ones) also run in full dynamics from the starts
    bool sensitivities = true;
    int threads = 0;    // draws in parallel (0: all cores)
    TaskRunner tasks;   // (set: shares the draws instead of `threads`)
    // Called as each draw is done (done of total), in the calling thread, one call at a time.
    std::function<void(int done, int total)> progress;
};

struct DrawResult {
    std::uint64_t index = 0;   // the draw's index (the nominal: -1 as 2^64 - 1)
    Outcome outcome = Outcome::failed;
    std::string note;                  // what decided the outcome (the competitor, the stop)
    bool matched = false;              // a stable fixed point at the target
    Vec3 fixed_point = Vec3::Zero();   // it (theta in (-pi, pi])
    double rate = 0;                   // its convergence rate, -max Re(eigenvalue) [1/s]
    int attractors = 0;                // stable points + stable lines (+1 for stuck cells)
    std::vector<double> p;             // the draw's deviations (uncertain_parameters)
    std::vector<double> arrival;   // per start, the field curve's arrival time [s]; inf: not within the horizon; nan: undefined
    std::vector<double> arrival_full;   // the same in full dynamics (full_draws only)
};

struct Sensitivity {
    UncertainParameter parameter;
    Vec3 dq = Vec3::Zero();      // d q* / d p (per unit of the parameter)
    double variance_share = 0;   // of the predicted position variance (trace of the x-y block)
};

// A 2-D spread: the radius that holds 95 % of the fixed points' positions around the nominal one.
struct RobustnessSummary {
    Scene nominal;
    Vec3 target = Vec3::Zero();
    DrawResult nominal_result;   // the nominal plate, like a draw
    std::vector<DrawResult> draws;
    std::vector<Vec3> starts;
    std::array<int, kOutcomes> counts{};   // per Outcome
    // Over the matched draws, the offset of their fixed point from the nominal one.
    Vec3 mean_offset = Vec3::Zero();
    double radius95 = 0;   // [m]: 95th percentile of |offset_xy|
    double angle95 = 0;    // [rad]: of |offset_theta|
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    // First order (sensitivities set): at the nominal fixed point.
    std::vector<Sensitivity> sensitivities;
    Eigen::Matrix3d jacobian = Eigen::Matrix3d::Zero();               // d xi / d q there
    Eigen::Matrix3d predicted_covariance = Eigen::Matrix3d::Zero();   // S diag(sd^2) S^T
    double predicted_radius95 = 0, predicted_angle95 = 0;
    double sensitivity_seconds = 0;
    // Each matched draw's offset against its linear prediction S p: the median and the largest
    // |offset - S p| / |offset| (in (s_x, s_y, rho theta)), and how many exceed 0.3.
    double linear_error_median = 0, linear_error_max = 0;
    int nonlinear_draws = 0;
    std::vector<std::string> notes;   // what was not computed, and why
    double seconds = 0;
};

// Throws InputError (a spec or scene that gives no valid draw) and std::invalid_argument (no target:
// the nominal has no stable fixed point or several).
RobustnessSummary robustness(const Scene& nominal, const UncertaintySpec& spec, const RobustnessOptions& opt = {});

// How the sensitivities are computed. `refine`: the cycles tightened to 1e-8 v_ref (steps 1e-9) and q*
// moved onto that field's zero by two Newton steps first -- what plate robustness does; without it the
// cycles are `cycle`'s and q* is taken as given (a design's search, where q* is a zero by symmetry and
// a hundred such evaluations must be cheap).
struct SensitivityOptions {
    bool refine = true;
};

// The sensitivities alone, at a fixed point q* of the nominal; fills `out`'s first-order fields.
void fixed_point_sensitivities(const Scene& nominal, const UncertaintySpec& spec, const Vec3& q_star,
                               const LimitCycleOptions& cycle, RobustnessSummary& out, const SensitivityOptions& so = {});

// The radius r holding probability `level` of a centred 2-D normal distribution of covariance C
// (P(|x| <= r) = level), by a one-dimensional integral; exact for a degenerate C too.
double normal_radius(const Eigen::Matrix2d& C, double level = 0.95);

// The summary as JSON, every quantity with its unit in its key (_m, _mm, _rad, _s, _per_s): the
// outcomes' shares with 95 % intervals, the spread (Monte Carlo and predicted), the sensitivities
// (largest share of the variance first), the rates, the arrival times and every draw. An arrival time
// is a number of seconds, null when not within the horizon, "undefined" when the field or the run
// stopped on the way.
nlohmann::json robustness_json(const RobustnessSummary& s, const RobustnessOptions& opt, const UncertaintySpec& spec);

// A share k / n with its 95 % Wilson score interval.
struct Share {
    double value = 0, low = 0, high = 0;
};
Share wilson(int k, int n);

}   // namespace plate
