// Inverse design: the plate motion that makes the asymptotic twist field do what is wanted
// (issue 16). Options in, summary out, like the rest of the library; every design is verified
// before it is reported (the field's fixed points on a grid, and full-dynamics runs from seeded
// random starts), and a design that fails verification says so.
//
// EXACT SYMMETRIES the search uses (checked in tests/design/test_design_symmetry.cpp against fields computed both ways):
//   rotate_motion(u, a)   the plate motion turned by a about z (x/y and rx/ry harmonics rotate, z and
//                         rz stay): the field turns with it, xi'(R s, theta + a) = (R v, omega)
//                         (friction disks are isotropic);
//   shift_motion(u, D)    -alpha x D added to the linear acceleration (alpha: the angular one): the
//                         plate point at D now moves as the centre did, so the field shifts by D,
//                         xi'(s + D, theta) = xi(s, theta) (exact in the U-dynamics: the plate's
//                         acceleration at r is p'' + alpha x r, its tilt the same everywhere).
// So a design for a target at the centre moves exactly onto any other target, and the search only
// shapes the field about the centre. And with only odd harmonics and no z or rz motion, turning the
// motion by pi equals shifting it by half a period, so the field is odd about the centre
// (xi(-s, theta + pi) = -xi(s, theta) for the translation part): a point part's centre is then a
// fixed point by construction, and a rigid part's fixed points come in pairs (s, theta),
// (-s, theta + pi) with the same stability -- a unique one cannot exist with such motions.
#pragma once

#include "plate/design_target.hpp"
#include "plate/field.hpp"
#include "plate/peaks.hpp"
#include "plate/robustness.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace plate {

PlateMotion rotate_motion(const PlateMotion& u, double angle);
PlateMotion shift_motion(const PlateMotion& u, const Vec2& D);
// A plate motion from coefficients, the designs' parameter layout: per axis a (of `axes`) and harmonic
// h (of `harmonics`), u = c cos(n w t) + s sin(n w t) with c = p[2 (a H + h)], s = p[2 (a H + h) + 1]
// (H = harmonics.size()), i.e. amp sin(n w t + phase); zero amplitudes are left out.
PlateMotion motion_from(const std::vector<double>& p, const std::vector<Axis>& axes, const std::vector<int>& harmonics, double T);

// CONING. The plate's angular acceleration is periodic with zero-mean angular velocity, but rotations
// do not commute: rx and ry out of phase (circular tilting, fig4's) make the plate's orientation
// precess about z at a steady second-order rate, |psi'| = (1/2) |<(theta x theta')_z>| for the small
// rotation theta(t). With
// theta_a = -A_a e^{i n w t} / (n w)^2 per harmonic (A = amp e^{i phase} of the angular acceleration,
// as amp sin(n w t + phase)) it is sum_n Im(A_rx,n conj(A_ry,n)) / (2 (n w)^3) [rad/s] (harmonics of
// different n average out): 0.0025 rad/s for fig4. The asymptotic field (first-order averaging) does
// not see it; the full dynamics does: fig4's part, at the field's stable fixed point (0, 0, 0),
// turns steadily in the plate frame at psi', sign included. Rigid-part designs are constrained to
// |psi'| <= 1e-4 rad/s. (Checked in tests/design/test_design_symmetry.cpp against the full dynamics of fig4 and of its
// mirror image, within 1 %; the plate's own world-frame turn is not tested separately.)
// The whole field turns with it about the plate's centre, so a sink placed at D off the centre walks
// |D| |psi'| per second: a point-part sink is held to |psi'| <= sink_coning_limit (below), and every
// sink and fixed point is verified by a part released at the target staying within verify_distance
// over DesignOptions::hold seconds of full dynamics.
double coning_rate(const PlateMotion& u);
// The same second-order drift about the horizontal axes, (ry with rz, rz with rx): the components
// of (1/2) <theta x theta'> along x and y, sum_n Im(A_ry,n conj(A_rz,n)) / (2 (n w)^3) and
// sum_n Im(A_rz,n conj(A_rx,n)) / (2 (n w)^3) [rad/s], signed as coning_rate is: the plate itself
// turns about x and y at minus these (a test: a part on such a plate slides downhill that way, in
// full dynamics). Where it is not zero the plate's tilt grows steadily and gravity pulls every part
// downhill (docs/decisions.md: a trial design that left the plate). Rigid designs hold it to 2e-6
// rad/s (internal.hpp, kTiltDriftLimit); a motion without rz has none.
Vec2 tilt_drift_rate(const PlateMotion& u);

// ORIENTATION HARMONICS. At a position s the twist's theta' is a function of theta alone,
//     theta'(theta) = M + sum_k B_k sin(k theta + phi_k)
// sampled on a ring of n equally spaced orientations (harmonics_of: the discrete Fourier transform;
// harmonics k < n/2 are resolved, k = n/2 only its cosine part, and harmonics above n/2 alias onto
// lower ones). What a rigid part's one stable orientation needs: with r = rest() = |M| + B_2 + ...,
// B_1 > r puts every zero of theta' in the two arcs |sin(theta + phi_1)| <= r / B_1, and if also
// B_1^2 > r^2 + slope_bound()^2 (slope_bound = sum_{k>=2} k B_k) theta' is monotonic in them: exactly
// one stable orientation (one_stable()). B_1 > r alone is not enough (scenes/foot.json's weathervane
// has three stable orientations: docs/inverse-design.md, "What one orientation needs"). If instead the
// pi-periodic part (M, B_2, B_4, ...) dominates, stable orientations pair about a half turn apart, and
// one is unique only with M tuned onto a saddle-node of that part, which leaves a bottleneck of
// theta' < B_1 where its twin was. bench_orientation_drive measures how large B_1 can be within the
// design limits.
struct OrientationHarmonics {
    bool defined = false;            // every cycle on the ring converged
    double mean = 0;                 // M [rad/s]
    std::vector<double> amplitude;   // B_k for k = 0..n/2 [rad/s] (amplitude[0] = |M|)
    double first() const { return amplitude.size() > 1 ? amplitude[1] : 0.0; }
    double rest() const;          // |M| + B_2 + ... + B_{n/2}
    double slope_bound() const;   // sum_{k>=2} k B_k >= |d theta' / d theta - B_1 cos(theta + phi_1)|
    bool one_stable() const;      // B_1^2 > rest()^2 + slope_bound()^2: exactly one stable orientation
};
// theta' on the ring theta_k = 2 pi k / n (n >= 4) as harmonics.
OrientationHarmonics harmonics_of(const std::vector<double>& theta_dot);
OrientationHarmonics orientation_harmonics(const Scene& scene, const Vec2& s, const LimitCycleOptions& opt, int n = 12);

// PEAKS: axis_peaks (plate/peaks.hpp, numeric: identification judges its suggested motions by them too).

struct DesignOptions {
    // The limits: every designed motion keeps each axis' peak (axis_peaks) within them -- a constraint
    // of every search, on the motion as finally placed (turned, shifted, rz added), and checked again
    // by design() on the motion it returns (a design beyond them fails verification). A harmonic's
    // amplitude is not limited by itself: it may exceed the peak where others flatten its crest, by at
    // most 4 / pi (a coefficient is an average of u cos(n w t) over the period). The searches' box for
    // each cosine or sine coefficient stays +-limit: a search range, not the limit (it leaves out the
    // motions with a coefficient between 1 and 4 / pi of the limit; docs/decisions: why not wider).
    double lin_limit = 20;    // the peak of each linear axis' acceleration, x, y, z [m/s^2]
    double ang_limit = 150;   // the peak of each angular axis' acceleration, rx, ry, rz [rad/s^2]
    // Corner limits (0: none): what the plate's stops and its actuators' speed bound. The plate's
    // corners at (+-plate_half_size) keep the peak length of their displacement within
    // corner_displacement_limit [m] and of their velocity within corner_velocity_limit [m/s]
    // (corner_peaks, plate/peaks.hpp) -- a constraint of every search when either is set, and checked
    // by design() on the motion it returns, as the peaks are. plate_half_size zero: the corners of the
    // flight check's square (the region widened by a rigid part's reach).
    double corner_displacement_limit = 0;
    double corner_velocity_limit = 0;
    Vec2 plate_half_size = Vec2::Zero();   // [m]
    double period = 0;                     // plate period T [s]; 0: the part scene's
    double region = 0.05;                  // the plate region |s_x|, |s_y| <= region [m]
    // No flight: g + the vertical acceleration of every plate point in the region (for a rigid part
    // widened by its contacts' reach from its centre of mass) stays at or above this fraction of g,
    // all period long (a constraint of the search, never a penalty).
    double flight_margin = 0.2;
    std::uint64_t seed = 1;
    // Multi-start: seeded feasible random motions, each refined locally; 0: the target's default
    // (default_starts).
    int starts = 0;
    int local_evaluations = 400;   // per start (NLopt COBYLA)
    // The local search: COBYLA (derivative-free, the default), or SLSQP on forward-difference
    // gradients (each gradient n + 1 objective evaluations, counted in `evaluations`), kept to
    // measure what gradients buy (bench_design).
    enum class Local { Cobyla, SlsqpFiniteDifferences };
    Local local = Local::Cobyla;
    int threads = 0;   // starts in parallel (0: all cores)
    // Shares the starts, the verification field's planes and the verification runs (set: `threads`
    // is not used; e.g. sweep::farm_tasks over MPI ranks). The design is the same either way.
    TaskRunner tasks;
    LimitCycleOptions cycle = cycle_defaults();
    // Verification: the field's fixed points on a verify_grid^2 grid over the region, and the full
    // dynamics from verify_starts seeded random starts in the region, which must end within
    // verify_distance of the target.
    int verify_grid = 7;
    int verify_starts = 20;
    double verify_distance = 0.005;   // [m]
    // Hold: a part released at rest at the target stays within verify_distance for this long [s]
    // (sinks and fixed points; 0: not checked). Coning turns the field about the plate's centre, so
    // it bounds the coning a design may have (sink_coning_limit).
    double hold = 120;
    // The coning a point-part sink may have [rad/s]; negative: sink_coning_limit (from the hold).
    // (Infinite with a hold: the fastest sink, which the hold then judges.)
    double max_coning = -1;
    // A rigid fixed point designed as a half-turn pair (design_rigid_pair) is offered rz about its
    // centre -- at n = 2 to bring theta''s two minima near a saddle-node, at n = 1 to lift one of them.
    // A motion that verifies as unique replaces the pair (whose own full-dynamics runs are then not
    // made; its field is checked first); else the pair is verified in full, and the verified broken one
    // whose runs end at the target most often replaces it where that beats the pair's share. false: the
    // pair as found.
    bool break_pair = true;
    // break_pair's candidates with theta''s other wells lifted clear of zero along the curve s*(theta)
    // where the position's twist vanishes (the field's fixed points lie on it; the screen looks at the
    // centre only): rz's settings moved until the shallowest other well clears 0.003 rad/s. false: the
    // screen's candidates as they are (fig4: verified, every run at the target, but a second stable
    // fixed point on the grid, 1 mm off the target at the twin's orientation).
    bool lift_wells = true;
    double fixed_point_tolerance = 0.002;   // the field's stable fixed point within this of the target [m]
    // The search's freedom (the CLI's --axes and --harmonics): a harmonic on an axis not in `axes`, or
    // of order n above max_harmonic, is held at zero. Empty / 0: each target's own motion family --
    // sinks and half-turn pairs x, y, rx, ry at n = 1, 3; line sinks y, rx at n = 1; transport and the
    // weathervane x, y, z at n = 1, 2; rigid fixed points all six axes at n = 1, 2 -- which these only
    // narrow (a target whose family is left with nothing to move fails cleanly, naming why).
    std::vector<Axis> axes;
    int max_harmonic = 0;
    // ROBUST DESIGN (issue 51): with `robust`, the design must hold on the plates the spec draws, not only
    // on the nominal one (sinks and fixed points: DesignTargetKind::Sink and FixedPoint).
    //  - A point part's sink: the search also keeps the fixed point's first-order 95 % radius under the
    //    spec (robustness.hpp's sensitivities at the target, on the final motion) within 0.85 of
    //    robust_radius (a penalty, like the region's edge: 10 per radius over; the margin is for the
    //    verification's Monte Carlo, whose 95 % radius is an order statistic).
    //  - Verification adds `robust_draws` draws of the spec (plate robustness, seed spec.seed: draws the
    //    search never saw): the share with the target's fixed point unique and stable must reach
    //    robust_share and the draws' 95 % radius must be within robust_radius (a rigid part's angle within
    //    robust_angle); the field's integral curves from the robustness starts, on every draw, and the full
    //    dynamics from them on the first robust_full_draws draws, must come within verify_distance (and
    //    0.05 rad) of the target within `arrive` seconds.
    std::optional<UncertaintySpec> robust;
    double robust_radius = 0.002;   // [m]
    double robust_angle = 0.05;     // [rad]
    double robust_share = 0.95;
    int robust_draws = 200;
    int robust_full_draws = 10;
    double arrive = 60;   // [s]
    static LimitCycleOptions cycle_defaults() {
        LimitCycleOptions o;
        o.tol = 1e-6;
        o.integration.rtol = 1e-7;
        o.max_periods = 60;   // a candidate cannot cost seconds
        o.max_rhs_evaluations = 200'000;
        return o;
    }
};

struct DesignStartRun {
    double x = 0, y = 0;       // the start [m]
    double theta = 0;          // (rigid parts: drawn uniformly over the turn)
    Vec3 end = Vec3::Zero();   // where the run ended
    double end_distance = 0;   // from the target after `seconds` of full dynamics [m] (rigid: the
                               // larger of the position's and the angle's, 0.05 rad counted as 5 mm;
                               // transport: from where the target velocity takes it over [from, seconds])
    double seconds = 0;
    double from = 0;               // transport: the run's second half only, past the start-up's lag [s]
    Vec3 at_from = Vec3::Zero();   // where the run was at `from`
    std::string stop;              // why the run stopped early, if it did
};

struct DesignSummary {
    bool verified = false;   // the design passed every check below
    bool unique = false;     // one stable fixed point on the grid, at the target
    std::string failure;     // why not verified
    Scene scene;             // the part with the designed plate motion
    // The search, at the centre before the shift (rigid fixed points: at the fixed point found near
    // it, central differences of 3 mm and 0.1 rad, ~1 % from the grid's refinement): the field's
    // Jacobian there and its convergence rate (-max Re of the eigenvalues) [1/s].
    double rate = 0;
    Eigen::Vector2cd eigenvalues = Eigen::Vector2cd::Zero();    // (point parts)
    Eigen::Vector3cd eigenvalues3 = Eigen::Vector3cd::Zero();   // (rigid parts)
    int starts = 0;                                             // the search's starts
    long evaluations = 0;                                       // objective evaluations (each a few limit cycles)
    long cycles = 0;                                            // limit cycles computed in the search
    // Verification.
    FixedPoints fixed_points;          // of the designed field on the grid
    Vec3 fixed_point = Vec3::Zero();   // the stable one nearest the target (a rigid part's sink: where
                                       // its position's field vanishes at the grid's first orientation)
    Eigen::Vector3cd fixed_point_eigenvalues = Eigen::Vector3cd::Zero();
    // Rigid parts: the share of the runs below that end at the target, and the other stable fixed
    // points on the grid with the share that ends at each (a design that is not unique says so).
    double basin_share = 0;
    // The largest share the design's symmetry allows (1: none known). A half-turn pair's twin basin is
    // the image of the target's under sigma: (s, theta) -> (2 D - s, theta + pi), D the design's centre,
    // so of the region R the part O = R and sigma(R) that is its own image goes at most half to the
    // target: share <= 1 - |O| / (2 |R|) for starts uniform over R and the turn, in the field's flow
    // (pair_basin_bound; the runs' basin_share is a finite sample from phase 0 and may exceed it).
    double basin_share_bound = 1;
    struct Competitor {
        FixedPoint point;
        double basin_share = 0;
    };
    std::vector<Competitor> competitors;
    std::vector<DesignStartRun> runs;   // full dynamics from random starts
    double worst_end_distance = 0;
    // Hold (sinks and fixed points): released at rest at the target, where the part is after
    // DesignOptions::hold seconds of full dynamics and how far that is (measured as end_distance).
    DesignStartRun held;
    double coning = 0;                      // the design's coning rate psi' [rad/s] (coning_rate)
    Vec6 peaks = Vec6::Zero();              // the designed motion's axis_peaks [m/s^2 x y z, rad/s^2 rx ry rz]
    CornerPeaks corner_peaks;               // ... and its corners' (at corner_half_size), whether limited or not
    Vec2 corner_half_size = Vec2::Zero();   // [m]
    double min_vertical_margin = 0;         // min over the period and the flight check's square of (g + a_z) / g
    // A rigid part's sink (position only: the part may turn as it pleases): at the target, per
    // orientation of the verification grid, where the position's velocity field vanishes and its
    // Jacobian's eigenvalues there.
    struct OrientationPull {
        double theta = 0;
        Vec2 zero = Vec2::Zero();
        Eigen::Vector2cd eigenvalues = Eigen::Vector2cd::Zero();
    };
    std::vector<OrientationPull> pulls;
    // Orient by transport (a weathervane, for parts with unequal friction coefficients): the twist at
    // the centre on the verification's ring of orientations (the same at every position); the stable
    // orientation is fixed_point[2], the travel there transport_mean, and transport_spread the largest
    // difference between positions on the grid (relative to v_ref and v_ref / rho).
    std::vector<double> ring_theta;
    std::vector<Vec3> ring_twist;
    // Transport: the field's mean velocity over the verification grid and its largest deviation from it
    // (a rigid part: also its largest |theta'| on the grid, transport_turn [rad/s]).
    Vec2 transport_mean = Vec2::Zero();
    double transport_turn = 0;
    double transport_spread = 0;      // [m/s]
    double transport_tolerance = 0;   // accepted |mean - target| [m/s]
    double seconds = 0;
    // Robust designs (DesignOptions::robust): the search's first-order 95 % radius at the design found
    // [m], and the verification's Monte Carlo over the spec.
    double predicted_radius95 = 0;
    std::optional<RobustnessSummary> robustness;
    std::vector<std::string> notes;   // the symmetries used, and what they imply
};

// The largest coning rate a sink at `at` may have (DesignOptions::max_coning if set): the sink turns
// about the plate's centre at psi', and over the hold it may walk at most half the verification
// distance, |psi'| <= verify_distance / (2 |at| hold) (infinite at the centre or without a hold). At
// (0.02, -0.01) with the defaults 9.3e-4 rad/s, at the region's corners 3e-4.
double sink_coning_limit(const Vec2& at, const DesignOptions& opt);

// FLIGHT. The smallest (g + vertical acceleration) / g over the period and the corners of the square
// |x|, |y| <= half_width, with the plate's acceleration at r = p'' + alpha x r (what a part there feels;
// the U-dynamics' plate): every design keeps it at or above DesignOptions::flight_margin, on the square
// flight_region gives -- the region, widened for a rigid part by its contacts' reach from its centre of
// mass (they stand on plate points up to that far beyond it).
double vertical_margin(const PlateMotion& u, double g, double half_width);
double flight_region(const Scene& part, const DesignOptions& opt);

// The basin-share bound of a half-turn pair about D over the region |s_x|, |s_y| <= region (above):
// 1 - |R and (2 D - R)| / (2 |R|). fig4's pair at (0.02, -0.01): 0.76.
double pair_basin_bound(const Vec2& D, double region);

// The starts a design makes when DesignOptions::starts is 0: 4 for sinks and line sinks (16 and 4
// parameters: more starts bought little there, docs/decisions/design-and-tools.md), 16 for the rest.
int default_starts(const Scene& part_scene, const DesignTarget& target);

// Designs a plate motion for the part of `part_scene` (its plate block is ignored but for its
// period when opt.period is 0). Throws std::invalid_argument for a target the part cannot have.
DesignSummary design(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt = {});

}   // namespace plate
