// Closed-loop control (issue 53): a controller watches the part through a camera, one frame per plate
// period, and chooses each period's plate motion; a "true" plate and part -- the controller's model
// perturbed -- run that motion through the full dynamics (stick-slip included). Read top to bottom:
// the truth the loop runs against, the carried state at a switch, the library of motions and the
// model the controller holds, the goal, the policies, the loop and its summary.
//
// Frames and times. A configuration q = (s_x, s_y, theta) is the plate frame's, as everywhere in plate;
// the plate's centre oscillates about the world's origin by its zero-mean displacement (up to about a
// millimetre for the shipped motions). The goal and the errors are the world's. Period k runs from t = k T to (k + 1) T, the
// plate at phase 0 of its motion at t = k T; the motion can change only there.
#pragma once

#include "plate/field.hpp"
#include "plate/model.hpp"
#include "plate/observe.hpp"
#include "plate/simulate.hpp"
#include "plate/uncertainty.hpp"

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace plate {

// ---- the truth ----------------------------------------------------------------------------------
//
// The plate and part the loop runs against: the nominal scene perturbed by an uncertainty spec
// (uncertainty.hpp) and its friction scaled. The file (TRUTH.json; unknown or missing fields are errors):
//
//   { "friction_scale": 0.8,              // optional (1): every friction coefficient times this
//     "uncertainty": { ...an uncertainty spec, inline (uncertainty.hpp)... },   // optional (none)
//     "tracking": "per_period",            // optional ("per_period") | "per_run"
//     "draw": 0,                           // optional (0): which draw of the spec this run is
//     "measured": [                        // optional: what the real plate did when commanded a motion
//       { "commanded": "e_fast.json",      //   a scene file whose plate motion the controller commands
//         "cycle": "e_fast_recorded.csv",  //   one recorded period of the plate (measured_cycle.hpp)
//         "harmonics": 5 } ] }             //   the highest harmonic kept of it
//
// Paths are relative to the truth file's folder. A commanded motion that equals an entry's (same
// harmonics, to the bit) runs on the plate's recorded cycle instead, the cycle's period the commanded
// one's (1e-9 relative); the spec's tracking errors, if any, are drawn on top of it.
//
// The part's deviations (friction, mass, inertia, contacts, centre of mass) and the period's are drawn
// once per run: they are the part's and the drive's. The plate's tracking errors (amplitude, phase,
// unmodelled harmonics) are drawn anew every period ("per_period", the default: a real plate's errors
// vary cycle to cycle) or once per run for each motion ("per_run"). docs/decisions/control.md.
enum class Tracking { per_period, per_run };

// A plate motion as commanded and as a real plate ran it (a recorded cycle's harmonics).
struct MeasuredMotion {
    std::string commanded_source, cycle_source;   // files (for messages)
    PlateMotion commanded, measured;
};

struct Truth {
    std::string source;   // file it was read from (for messages)
    double friction_scale = 1;
    std::optional<UncertaintySpec> uncertainty;
    Tracking tracking = Tracking::per_period;
    std::uint64_t draw = 0;
    std::vector<MeasuredMotion> measured;
    // InputError naming source and the field unless friction_scale lies in (0, kMaxFrictionScale] and the
    // spec is admissible (validate_uncertainty).
    void validate() const;
};
inline constexpr double kMaxFrictionScale = 10;

// The closed-loop issue's test plate: friction x friction_scale, every harmonic's amplitude off by a
// relative `spread` and its phase by `spread` rad (normal draws, seed 53), drawn anew each period;
// `draw` numbers the run (one per start).
Truth spread_truth(double friction_scale, double spread, std::uint64_t draw);
// Its starts: start i uniform over the square [-0.05, 0.05]^2 m (seed 1000 + i; y drawn first, then x),
// and for a rigid part (with_theta) theta uniform over (-pi, pi], drawn third; else theta 0.
Vec3 square_start(std::uint64_t i, bool with_theta);
// Its camera: stroboscopic, one frame per period of T, phase 0, world frame, 0.1 mm noise (a rigid part's
// theta: 5 mrad), one period of latency (T), seed `seed`.
Camera issue_camera(double T, std::uint64_t seed, bool rigid);

Truth load_truth(const std::string& path);   // throws InputError
// dir: where the measured entries' relative paths start (load_truth: the file's folder).
Truth parse_truth(const std::string& text, const std::string& source, const std::string& dir = "");   // throws InputError

// The true scene of one period: `motion`'s plate (its recorded cycle if the truth has one) with period
// `period`'s tracking errors (or the run's,
// per_run), on the run's true part and period. `motion` indexes the motions a loop was given (a
// motion a policy made itself: index -1, always drawn per period). Without a spec: the nominal part
// with its friction scaled, the motion as commanded. Deterministic in (spec seed, draw, motion, period).
Scene true_scene(const Truth& truth, const Scene& commanded, int motion, long period);

// ---- the state carried over a period boundary ---------------------------------------------------
//
// At a boundary the plate changes from `from` (at the end of its period, which is its phase 0) to `to`
// at its phase 0: the plate's position, orientation and velocity may jump (the motions' zero-mean
// integrals differ at phase 0). The part does not: friction is bounded by mu N and transmits no
// impulse, so the part's world position and its world velocity in the plate's plane, and its heading
// and yaw rate about the world's z, are continuous; the normal components follow the plate (the plate
// pushes). Returns the part's plate-frame (q, qd) for `to` (qd: relative to the plate, in its frame,
// as the full dynamics take it). The identity when from == to.
void carry_state(const Part& part, const PlateMotion& from, const PlateMotion& to, Vec3& q, Vec3& qd);
// The part's world pose (world_pose, observe.hpp) at phase 0 of sc's plate from its plate-frame q.
Vec3 world_pose_at_phase0(const Scene& sc, const Vec3& q);

// ---- the library of motions and the controller's model ------------------------------------------
//
// The library file (JSON; unknown or missing fields are errors; scene paths relative to the file):
//
//   { "motions": [ {"name": "east_fast", "scene": "east_fast.json"},
//                  {"name": "still", "still": true},                 // the plate at rest
//                  ... ] }
//
// Every scene's part must be the nominal scene's and its period the nominal's (else an InputError naming
// the library file and the motion).
struct MotionLibrary {
    std::string source;
    std::vector<std::string> names;
    std::vector<PlateMotion> motions;   // all with the nominal's period
    int still = -1;                     // the still plate's index, -1 if none
};
MotionLibrary load_motion_library(const std::string& path, const Scene& nominal);   // throws InputError
// The same from the file's text; `source` names it in messages, scene paths are relative to `dir`.
MotionLibrary parse_motion_library(const std::string& text, const std::string& source, const std::string& dir,
                                   const Scene& nominal);

// A motion's field as the controller reads it: uniform (a plate that only translates, with a point
// part or a rigid part whose contacts share one friction coefficient, which moves as that point part
// without turning: nothing in its dynamics depends on where the part is, so one twist serves everywhere) or
// tabulated on a grid over the region and interpolated (bilinear in (s_x, s_y) for a point part;
// trilinear with periodic theta for a rigid part). Outside the grid the nearest edge's value.
struct MotionField {
    bool uniform = false;
    GridSpec grid;
    std::vector<Vec3> twist;   // GridSpec::index order; one entry when uniform
    Vec3 at(const Vec3& q) const;
};

struct ControlModelOptions {
    GridSpec grid;   // where fields that are not uniform are tabulated (point parts: nth 1)
    FieldOptions field;
    bool transitions = true;   // tabulate the first period after each switch (ControlModel::transitions)
    // Also the pairs where a field is tabulated on the grid (M (M - 1) one-period runs per grid point);
    // false: those pairs step by the new motion's field. Unset: on a point part's 2-D grid, not on a rigid
    // part's 3-D one (fig4's library: 84 s against 1.3 s, for nothing measurable; docs/decisions/control.md).
    std::optional<bool> grid_transitions;
    void validate() const;   // std::invalid_argument naming the option
};

// The controller's constant model: the nominal scene, the library and each motion's field,
// computed once before the loop (fields where a motion's twist is undefined -- contact lost -- are an
// InputError naming the motion).
struct ControlModel {
    Scene nominal;
    MotionLibrary library;
    std::vector<MotionField> fields;
    // The first period after a switch from a to b: not xi_b T, because the part arrives with a's cycle
    // velocity (and, in the world, keeps it: carry_state), which b's cycle does not share (entering
    // scenes/designs/point_sink.json from a 2 mm/period transport: a ~1.6 mm kick). transitions[a * M + b] holds that period's
    // world displacement divided by T, from the nominal full dynamics: the part settled kSettlePeriods on a's cycle, carried to
    // b, one period of b. Pairs of uniform fields are computed once; others on the grid (as grid_transitions says): M (M
    // - 1) one-period runs per grid point where a field is not uniform (a rigid part's 3-D grid with a large library is costly:
    // coarsen the grid or turn them off). Empty when ControlModelOptions::transitions is false.
    std::vector<MotionField> transitions;
    double T() const { return nominal.plate.T; }
    int motions() const { return static_cast<int>(library.motions.size()); }
    // The predicted displacement over the next period on motion `to` after a period on `from` (-1: none).
    Vec3 step(int from, int to, const Vec3& q) const;
};
inline constexpr int kSettlePeriods = 6;
ControlModel build_control_model(const Scene& nominal, MotionLibrary library, const ControlModelOptions& opt = {});

// ---- the goal -----------------------------------------------------------------------------------

struct Goal {
    Vec3 q = Vec3::Zero();           // (s_x, s_y, theta); a point part's theta is not read
    double tolerance = 1e-3;         // [m], on the position
    double tolerance_theta = 0.02;   // [rad] (rigid parts)
    // The weighted distance's length for an angle: |(dx, dy, theta_weight * dtheta)| [m/rad].
    double theta_weight = 0.02;
    bool point = true;
    double error(const Vec3& q) const;         // the position's distance to the goal [m]
    double theta_error(const Vec3& q) const;   // |theta - goal| wrapped (0 for a point part)
    bool within(const Vec3& q) const;
    double distance(const Vec3& q) const;   // the weighted distance
};

// ---- policies -----------------------------------------------------------------------------------

// What the controller sees at a decision: the newest frame it has (a frame stamped at or before the
// decision's time), the time of the state it shows, and whether any frame has arrived.
struct Observation {
    double t = 0;   // the decision's time k T [s] (T the true plate's period)
    bool seen = false;
    double stamp = 0;        // [s]
    double state_time = 0;   // stamp - latency [s]
    Vec3 q = Vec3::Zero();   // plate frame (a world-frame camera's frames are taken as the plate's)
};

// A period's plate motion: a library index, or a motion of the policy's own (motion -1).
struct Decision {
    int motion = -1;
    std::optional<PlateMotion> plate;
};

// A controller. reset() before a run; decide() once per period k, at t = k T, within its time budget.
class Policy {
public:
    virtual ~Policy() = default;
    virtual std::string name() const = 0;
    virtual void reset(const ControlModel& model, const Goal& goal) = 0;
    virtual Decision decide(const Observation& obs, long period) = 0;
};

// `library`: each period, from the observed configuration predicted forward to the decision's time with
// the model's steps of the motions it chose (latency), the motion that, kept for `horizon` periods,
// stays nearest the goal on average (Goal::distance after each period: the first period's step from the
// current motion, ControlModel::step, then q + xi_m(q) T). Against chattering: inside stop_radius it
// holds the still plate (if the library has one), averaging the frames while the part rests there, and
// leaves it only beyond stop_radius + hysteresis; elsewhere it keeps its motion unless another lands
// nearer by more than `hysteresis`.
//
// A rigid part (two_phase, the default): the motions split into those that keep its orientation (the
// still plate and uniform fields -- translating plates, which do not turn a part whose contacts share
// one friction coefficient) and those that turn it. While the orientation is off by more than
// turn_enter (a fraction of the goal's tolerance_theta) it turns: the turning motion whose theta, kept
// for `horizon` periods, stays nearest the goal's on average, until within turn_exit; then the position
// is steered with the keeping motions as for a point part (the distance is the position's), and the
// orientation, which they do not change, is the mean of the frames since the turning ended (the
// camera's noise shrinks as 1/sqrt(n)). false, or a library without both kinds of motion (a part whose
// contacts' friction differs has no uniform field): one choice over every motion by Goal::distance.
struct LibraryPolicyOptions {
    double stop_radius = 0.5e-3;   // [m], weighted distance; 0: never stop
    double hysteresis = 0.1e-3;    // [m]
    int horizon = 2;               // [periods], 1 to kMaxHorizon
    bool two_phase = true;         // rigid parts only
    double turn_enter = 0.6;       // of Goal::tolerance_theta, in (turn_exit, 1]
    double turn_exit = 0.25;       // of Goal::tolerance_theta, in (0, turn_enter)
    void validate() const;         // std::invalid_argument naming the option
};
inline constexpr int kMaxHorizon = 1000;
std::unique_ptr<Policy> make_library_policy(const LibraryPolicyOptions& opt = {});

// `mpc`: each period, the sequence of `horizon` library motions -- a switch allowed at
// every period -- whose predicted path has the least cost, the mean over the horizon of (the weighted
// distance to the goal after the period, plus switch_cost if the period switched motion); its first motion
// is applied (receding horizon). The path is
// the model's steps (ControlModel::step) corrected online: between consecutive frames the observed
// displacement against the model's over the same stretch (the motions then chosen), fitted by
// exponentially forgotten least squares (`forgetting` per frame) as
//     dq_seen = gain dq_model + drift (dt / T),
// a gain on the model's transport (friction changes the speeds) and a drift per period (tracking errors,
// a tilt), with a prior (gain 1, drift 0) worth prior_travel of predicted travel and prior_frames frames.
// A rigid part's angle enters the fit with the same gain (its steps' theta, weighted by the goal's
// theta_weight) and no drift; its cost is the goal's weighted distance, in one phase (no turn-first rule).
// Inside stop_radius the still plate, left only beyond stop_radius + hysteresis (the library policy's
// rule). Every motions^horizon sequence is searched (a tree: the prefixes' steps shared).
struct MpcPolicyOptions {
    int horizon = 3;                // [periods], 1..kMaxMpcHorizon, motions^horizon <= kMaxMpcSequences
    double switch_cost = 0.05e-3;   // [m] per switch
    double forgetting = 0.9;        // per frame, in (0, 1]
    bool correct = true;            // false: the nominal model, uncorrected
    double prior_travel = 0.5e-3;   // [m]
    double prior_frames = 1;
    double stop_radius = 0.5e-3;   // [m]
    double hysteresis = 0.1e-3;    // [m]
    void validate() const;         // std::invalid_argument naming the option
};
inline constexpr int kMaxMpcHorizon = 8;
inline constexpr long kMaxMpcSequences = 1'000'000;
// The correction an mpc policy holds (its latest), for the run's summary and tests.
struct MpcEstimate {
    double gain = 1;
    Vec2 drift = Vec2::Zero();   // [m per period]
    int frames = 0;              // frame pairs fitted
};
std::unique_ptr<Policy> make_mpc_policy(const MpcPolicyOptions& opt = {});
// The estimate of a policy made by make_mpc_policy (std::invalid_argument for another policy).
MpcEstimate mpc_estimate(const Policy& mpc);

// Open loop, for comparison: a model of one motion -- the plate of the scene file at `path`, kept all
// run (its field is not needed: the model's one field is a zero placeholder) -- and the policy that
// never switches from it. What an open-loop design does on the same truth and starts.
ControlModel open_loop_model(const Scene& nominal, const std::string& path);   // throws InputError
std::unique_ptr<Policy> make_open_loop_policy();

// ---- the loop -----------------------------------------------------------------------------------

struct ControlOptions {
    double duration = 10;   // [s]: whole periods of the true plate up to it
    IntegrationOptions integration;
    void validate() const;   // std::invalid_argument naming the option
};
// The longest run, in periods.
inline constexpr long kMaxControlPeriods = 10'000'000;

// One row per period, at its start t = k T (and a last one at the run's end): what the controller saw
// (NaN before the first frame) and chose, and where the part truly was -- in the world: the plate
// frame's q moved by the plate's displacement at phase 0 (world_pose), which differs from motion to
// motion by up to a millimetre for the shipped ones, and is 0 on a still plate. The goal is judged there.
struct ControlRow {
    double t = 0;
    Vec3 observed = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
    Vec3 truth = Vec3::Zero();   // world pose (x, y, heading)
    int motion = -1;             // -1: the policy's own motion, or the run's end
    double decision_seconds = 0;
};

// What happened. Time to goal: the first row's t from which the true configuration is within the
// goal's tolerance at every later period start to the end of the run (NaN if the last is not). The
// worst overshoot: the largest position error after the part first came within tolerance.
struct ControlSummary {
    std::string policy;
    long periods = 0;
    bool reached = false;
    double time_to_goal = std::numeric_limits<double>::quiet_NaN();
    double first_within = std::numeric_limits<double>::quiet_NaN();
    double final_error = 0, final_theta_error = 0;
    double worst_overshoot = 0;
    int switches = 0;
    double decision_mean = 0, decision_max = 0;   // [s], wall clock (a preempted decision counts in full)
    double decision_p99 = 0;                      // [s], the 99th percentile
    StopEvent stop;                               // the truth's dynamics stopped (contact lost, ...)
    bool interrupted = false;                     // keep_going said stop
    std::vector<ControlRow> rows;
};

// The loop a period at a time, for a caller that decides itself (Python's ControlEnv): observe() what
// the camera shows at the period's start, step() the period with a decision, summary() at any time.
// run_control is this with a Policy deciding. Construction validates opt and truth and starts the part at
// rest on the plate at q0; the camera's frames are drawn as run_control draws them.
class ControlLoop {
public:
    ControlLoop(const ControlModel& model, const Truth& truth, const std::optional<Camera>& camera, const Goal& goal,
                const Vec3& q0, const ControlOptions& opt = {});
    ControlLoop(ControlLoop&&) noexcept;
    ControlLoop& operator=(ControlLoop&&) noexcept;
    ~ControlLoop();
    long periods() const;          // the run's length: whole periods of the true plate within opt.duration
    long period() const;           // the next period's index k
    bool done() const;             // every period run, or the truth's dynamics stopped
    Observation observe() const;   // the camera's newest frame at t = k T
    // Runs period k on decision d (a library index, or the policy's own motion when d.plate is set;
    // std::invalid_argument for an index outside the library, std::logic_error when done()): the row
    // (decision_seconds recorded in it), the true dynamics from the carried state, the frames.
    void step(const Decision& d, double decision_seconds = 0);
    // The part's world pose at phase 0 of the last period's true plate (at q0 before the first step): the
    // run's end row would show it.
    Vec3 true_pose() const;
    const StopEvent& stop() const;
    // The rows so far and the end row, summarised under the policy's name (interrupted: keep_going said stop).
    ControlSummary summary(const std::string& policy, bool interrupted = false) const;

private:
    struct State;
    const ControlModel* model_;
    Goal goal_;
    std::unique_ptr<State> st_;
};

// Runs the loop from the part at rest on the plate at q0, for options.duration: each period the policy
// decides from the camera's newest frame, the true plate (true_scene) runs the motion through the full
// dynamics from the carried state (carry_state at every boundary), the camera films (one stroboscopic
// frame per period of the true plate: noise, latency, drops -- observe.hpp's Camera; nullopt: a perfect
// camera at phase 0). `keep_going` (if set) is asked each period; false ends the run (interrupted).
// A ControlLoop stepped with the policy's decisions.
ControlSummary run_control(const ControlModel& model, Policy& policy, const Truth& truth, const std::optional<Camera>& camera,
                           const Goal& goal, const Vec3& q0, const ControlOptions& opt = {},
                           const std::function<bool()>& keep_going = {});

// The run's rows as CSV (units in the header, 17 significant digits) and the summary as JSON.
void write_control_csv(std::ostream& out, const ControlSummary& s, const ControlModel& model, bool point);
nlohmann::json control_summary_json(const ControlSummary& s, const ControlModel& model, const Goal& goal);

}   // namespace plate
