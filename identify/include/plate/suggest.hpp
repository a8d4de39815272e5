// Which motion to film (issue 52, point 4): a part that never sticks says nothing about its static
// friction, one that never slips nothing about its kinetic friction. suggest_motion() weighs a few
// candidate plate motions within the actuators' peak limits by the information the camera's tracks
// would carry about the wanted parameters, and proposes the best (docs/decisions/identification.md,
// "Suggested motion").
//
// The candidates: horizontal drives whose horizontal peak acceleration A runs over `levels` times the
// nominal part's mean static coefficient times g (a part at rest breaks away where A exceeds mu_s g and,
// sliding, sticks again where the plate's acceleration is below it) in three shapes -- x with its
// second harmonic at a third of the first (asymmetric: the part drifts along x, so a stroboscope sees
// it move; a symmetric drive brings it back to the same place every period), the same with a y second
// harmonic at a third, a quarter of its period later (a drift along y too: two numbers a period, two
// combinations of the coefficients), and each of these two with a yaw (rz) component (rigid parts only:
// the plate turning under the contacts loads each differently, so their coefficients separate). A
// candidate whose axis peaks (axis_peaks) exceed the limits is reported and not weighed. Each at the
// scene's plate period and at the multiples of it in `period_factors`.
//
// The information of a candidate: the fit's own Jacobian (identify_detail::track_jacobian) of the
// noise-scaled residuals of `tracks` tracks of `duration` s from seeded random starts at rest (x, y in
// +-start_box, theta any), filmed by `camera` without drops at the scene's nominal parameters, the
// tracks' starts eliminated (Schur complement), in range-scaled units. Where the plate turns (a yaw),
// what the tracks carry depends on where they start, so each candidate is weighed over `start_sets`
// sets of starts and judged by its worst: the winner maximises the smallest eigenvalue of the worst
// set's information (E-optimal, and max-min over the sets: the worst-determined combination of the
// parameters is the best determined wherever the part is put down). Deterministic: the k-th set is
// drawn from seed + k, the same for every candidate.
#pragma once

#include "plate/identify.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace plate {

// Validated once, by validate() (std::invalid_argument naming the field).
struct SuggestOptions {
    IdentifyOptions fit;                                 // params (the wanted ones), level, rtol, threads, the physical ranges
    double lin_limit = 20;                               // the peak of each linear axis' acceleration [m/s^2] (design's --limits)
    double ang_limit = 150;                              // the peak of each angular axis' acceleration [rad/s^2]
    int tracks = 5;                                      // planned tracks per candidate
    double duration = 10;                                // [s] each
    std::uint64_t seed = 1;                              // of the tracks' starts
    int start_sets = 3;                                  // sets of starts each candidate is weighed over
    double start_box = 0.05;                             // [m]: starts' |x|, |y| at most this
    std::vector<double> levels = {1.1, 1.4, 1.7, 2.0};   // horizontal peaks in units of mu_s g (nominal, mean)
    // The plate's period in units of the scene's: each shape and level at each. A longer period at the
    // same peaks moves the part further each period (more information a frame) and costs fewer periods
    // to simulate (docs/decisions/identification.md, "A longer period").
    std::vector<double> period_factors = {1, 2};
    void validate() const;
};

// One candidate motion, weighed.
struct MotionCandidate {
    std::string label;   // e.g. "x+2x+rz @ 1.4 mu_s g"
    PlateMotion motion;
    Vec6 peaks = Vec6::Zero();   // axis_peaks [m/s^2 x y z, rad/s^2 rx ry rz]
    bool within_limits = true;   // false: not weighed (the rest below left at 0 / empty)
    bool simulated = false;      // every planned track ran to its end (no contact lost)
    // The contacts' mean share of the planned tracks' time at zero slip (Trajectory::held_time): 1 a part
    // that never slides, 0 one that never sticks.
    double stick_fraction = 0;   // (pooled over every set)
    // Of the worst set of starts (the smallest eigenvalue):
    std::vector<FittedParameter> predicted;    // the nominal values with their predicted sd (NaN: not identifiable)
    Eigen::MatrixXd information;               // range-scaled, the starts eliminated (rows as params)
    double min_eigenvalue = 0;                 // of `information`
    int worst_set = 0;                         // its index k (starts drawn from seed + k)
    std::vector<double> set_min_eigenvalues;   // every set's smallest eigenvalue
    double seconds = 0;
};

struct SuggestSummary {
    std::vector<MotionCandidate> candidates;
    int best = -1;     // index of the winner (-1: no candidate simulated)
    Scene suggested;   // the nominal scene with the winner's plate motion
    double seconds = 0;
};

// The candidates of the header comment, for `scene`'s nominal part and period.
std::vector<MotionCandidate> candidate_motions(const Scene& scene, const SuggestOptions& o);

// Weighs `c.motion` (fills the rest of c): the information about o.fit.params that the planned
// tracks would carry. Throws as check_parameter_names, validate, and InputError for a camera without
// noise (the residuals' scale).
void weigh_motion(const Scene& scene, const Camera& camera, const SuggestOptions& o, MotionCandidate& c);

// Every candidate weighed, the winner chosen.
SuggestSummary suggest_motion(const Scene& scene, const Camera& camera, const SuggestOptions& o);

nlohmann::json suggest_json(const SuggestSummary& s, const SuggestOptions& o);

}   // namespace plate
