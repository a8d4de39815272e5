// Closed-loop control of several point parts on one plate (issue 53, point 3): the camera watches every
// part, one frame per plate period each; the controller chooses ONE plate motion a period for all of them;
// the true plate runs it, and each part follows it through the full dynamics. A translating plate moves
// every point part alike (its field is uniform), so only motions whose field depends on where the part is
// (sinks, turning plates) can bring two parts to two different goals.
//
// Point parts do not interact: each is a point with its own contact, and the truth simulates each on the
// same true plate independently (no collision between parts is modelled). They are the scene's part, all
// alike: a truth's part deviations (one draw per run) are shared by every part, as are the plate's
// tracking errors (one plate). Each part has its own camera stream: the camera's model, noise, latency
// and drops, with seed `seed + i` for part i, so that one part's run is the single-part loop's.
#pragma once

#include "plate/control.hpp"

#include <vector>

namespace plate {

// ---- the parts ----------------------------------------------------------------------------------
//
// The parts file (JSON; unknown or missing fields are errors):
//
//   { "parts": [ {"goal": [0.02, -0.01], "start": [-0.03, 0.04], "weight": 1},   // start, weight optional
//                {"goal": [-0.02, 0.01]} ] }                                      // (origin, 1)
struct MultiPart {
    Vec3 goal = Vec3::Zero();    // (s_x, s_y, 0), in the world frame as Goal::q
    Vec3 start = Vec3::Zero();   // at rest on the plate, plate frame (as run_control's q0)
    double weight = 1;           // its distance's weight in the policy's cost, > 0
};
struct MultiParts {
    std::string source;   // file it was read from (for messages; "" when built in code)
    std::vector<MultiPart> parts;
    double tolerance = 1e-3;   // [m]: a part is at its goal within this (every part's)
    // InputError naming source and the field ("parts[1].weight", "tolerance") unless there are 1 to
    // kMaxParts parts, every goal and start finite (|s| <= kMaxPartReach) and weight in (0, kMaxWeight], and
    // tolerance > 0; and unless `nominal`'s part is a point part ("part": multi-part control is for point parts).
    void validate(const Scene& nominal) const;
    Goal goal(std::size_t i) const;   // part i's Goal (point, this tolerance)
};
inline constexpr int kMaxParts = 64;
inline constexpr double kMaxPartReach = 10;   // [m]
inline constexpr double kMaxWeight = 1e6;
MultiParts load_parts(const std::string& path);                               // throws InputError
MultiParts parse_parts(const std::string& text, const std::string& source);   // throws InputError

// ---- the policy ---------------------------------------------------------------------------------

// A controller of several parts: decide() once per period from every part's newest frame.
class MultiPolicy {
public:
    virtual ~MultiPolicy() = default;
    virtual std::string name() const = 0;
    virtual void reset(const ControlModel& model, const MultiParts& parts) = 0;
    virtual Decision decide(const std::vector<Observation>& obs, long period) = 0;
};

// `library` for several parts: each period the library motion that, kept for `horizon` periods, has the
// least SUM over the parts of weight_i times part i's mean distance to its goal over the horizon (each
// part's path predicted as the single-part library policy predicts it: the switch's first step, then
// q + xi_m(q) T at the part's own predicted position; the latency bridged per part along the motions
// chosen). The sum, not the largest (docs/decisions/control.md): a motion that brings one part in
// without moving the other counts, and the cost does not jump between parts as their distances cross.
// Inside stop_radius -- every part's distance -- the still plate (its frames averaged per part), left only
// when some part is beyond stop_radius + hysteresis; elsewhere the current motion is kept unless another
// costs less by more than `hysteresis`. With one part of weight 1 it decides as make_library_policy does.
// Options: LibraryPolicyOptions' stop_radius, hysteresis and horizon (two_phase is not read); `aggregate`
// max: the largest weighted distance instead of the sum (kept for comparison).
enum class Aggregate { sum, max };
std::unique_ptr<MultiPolicy> make_multi_library_policy(const LibraryPolicyOptions& opt = {},
                                                       Aggregate aggregate = Aggregate::sum);

// ---- the loop -----------------------------------------------------------------------------------

struct MultiControlSummary {
    std::string policy;
    long periods = 0;
    // One per part: its rows (observed and true pose, the motion and decision shared) and its time to
    // goal, first entry, final error and worst overshoot as ControlSummary judges them; its `switches`
    // and decision times are the run's (the same in every part's).
    std::vector<ControlSummary> parts;
    bool reached = false;                                             // every part reached and held its goal
    double time_to_goal = std::numeric_limits<double>::quiet_NaN();   // the last part's time to goal
    int switches = 0;
    double decision_mean = 0, decision_max = 0, decision_p99 = 0;   // [s], wall clock
    StopEvent stop;                                                 // some part's true dynamics stopped (the run stops with it)
    bool interrupted = false;
};

// Runs the loop from every part at rest on the plate at its start, for opt.duration: each period the
// policy decides from every part's newest frame (the camera per part, as above), the true plate
// (true_scene, one per period) runs the motion and each part follows it through the full dynamics from
// its carried state. With one part: run_control's run to the bit. Throws std::invalid_argument for bad
// options, InputError for bad parts (MultiParts::validate), a camera or truth that is refused.
MultiControlSummary run_multi_control(const ControlModel& model, MultiPolicy& policy, const Truth& truth,
                                      const std::optional<Camera>& camera, const MultiParts& parts,
                                      const ControlOptions& opt = {}, const std::function<bool()>& keep_going = {});

// The run's rows as CSV: t, then per part i (from 1) obs_s_x_i, obs_s_y_i, x_i, y_i, then the motion and
// the decision's time; the summary as JSON (per part: goal, start, reached, time to goal, final error, ...).
void write_multi_control_csv(std::ostream& out, const MultiControlSummary& s, const ControlModel& model);
nlohmann::json multi_control_summary_json(const MultiControlSummary& s, const ControlModel& model, const MultiParts& parts);

}   // namespace plate
