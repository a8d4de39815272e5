// Asymptotic twist fields on SE(2) (rigid parts) and asymptotic velocity fields on R^2
// (point parts), Section IV-B; their fixed points and stability (Section IV-D); and integral
// curves of the field, to compare with U- and full-dynamics trajectories (Section IV-C).
#pragma once

#include "plate/limit_cycle.hpp"
#include "plate/progress.hpp"
#include "plate/tasks.hpp"

#include <functional>
#include <string>
#include <vector>

namespace plate {

// A regular grid over (s_x, s_y, theta). theta spans a full turn [th0, th0 + 2 pi) without
// repeating its end point. Point parts use nth = 1 (theta is meaningless).
struct GridSpec {
    int nx = 7, ny = 7, nth = 7;
    double x0 = -0.05, x1 = 0.05;
    double y0 = -0.05, y1 = 0.05;
    double th0 = 0;
    double dx() const { return nx > 1 ? (x1 - x0) / (nx - 1) : 0; }
    double dy() const { return ny > 1 ? (y1 - y0) / (ny - 1) : 0; }
    double dth() const { return 2 * kPi / nth; }
    Vec3 at(int i, int j, int k) const { return Vec3(x0 + i * dx(), y0 + j * dy(), th0 + k * dth()); }
    int index(int i, int j, int k) const { return (i * ny + j) * nth + k; }
    int size() const { return nx * ny * nth; }
};

struct FieldPoint {
    Vec3 q = Vec3::Zero();
    Vec3 twist = Vec3::Zero();   // xi_a(q) (36); NaN where undefined
    bool converged = false;
    int periods = 0;
    double residual = 0;
    double min_normal_force = 0;
    StopReason stop = StopReason::None;
    long rhs_evals = 0;
    std::array<double, 3> stick_fraction{};   // of the cycle's period, per contact (modes.hpp)
};

struct Field {
    GridSpec grid;
    bool point_part = false;
    std::vector<FieldPoint> points;   // GridSpec::index order
    double seconds = 0;               // wall time
    long rhs_evals = 0;
    int threads = 0;             // (0: FieldOptions::tasks shared the work)
    bool budget_spent = false;   // FieldOptions::max_rhs_evaluations was exceeded
};

struct FieldOptions {
    LimitCycleOptions cycle;
    int threads = 0;                                     // 0: all cores
    bool warm_start = true;                              // start each theta from the previous theta's cycle
    std::function<void(int done, int total)> progress;   // called from worker threads, serialised
    // Polled while the field runs (progress.hpp; nullptr: this thread's, if any): once set, the field
    // throws Interrupted within a step of the integrator on every worker.
    const StopRequest* stop = nullptr;
    // The field's work budget in right-hand sides (0: none). Once spent, the configurations not yet
    // started are left undefined with stop StepLimit and Field::budget_spent is set (which ones
    // depends on the threads' order: such a field is not a result, see the CLI); it is also set when
    // the field's total work exceeds the budget, so that any sharing of the work agrees on it.
    long max_rhs_evaluations = 0;
    // Shares the field's independent tasks (set: `threads` is not used). With the shooting solver
    // the lines (x_i, y_0, theta_k) and (x_i, y_j, theta_0) are solved first, in order, in every
    // process (each start is predicted from the points solved before it); then a task per plane x_i
    // solves its other points from those and its own (the plane is its own predictor). Otherwise a
    // task per line (x_i, y_j, theta), warm-started along theta. A task's points do not depend on
    // where it ran, so the field is the same, bit for bit, on any threads or ranks (sweep/farm.hpp
    // shares them over MPI ranks). The budget above is then counted per process.
    TaskRunner tasks;
};

Field compute_field(const Scene& scene, GridSpec grid, const FieldOptions& opt = {});

// Bounded work for a field (issue 18), judged here for the CLI and Python alike: five cycles from rest
// (the grid's centre and four spread configurations) run first; the field costs about their mean per
// configuration (warm starts save, sticking cycles cost more). (docs/decisions/cycles-and-fields.md,
// A field's work is estimated up front and bounded)
struct FieldWorkEstimate {
    double per_configuration = 0;   // right-hand sides
    double total = 0;               // right-hand sides, the whole grid
    double seconds = 0;             // the whole grid on one core, timed from the five cycles
};
FieldWorkEstimate estimate_field_work(const Scene& scene, const GridSpec& grid, const LimitCycleOptions& cycle);
// The default budget (right-hand sides): minutes on two cores.
constexpr long kDefaultFieldWork = 2'000'000'000L;
// Throws std::invalid_argument, with the estimate and how to raise the budget (`raise_with`: the CLI's
// --max-work, Python's max_work=), when the field is estimated over `budget` (> 0).
void require_field_work(const Scene& scene, const GridSpec& grid, const LimitCycleOptions& cycle, long budget,
                        const std::string& raise_with);

// One evaluation of the field with a warm start (updated in place). Throws FieldUndefined
// where the asymptotic twist is undefined (contact lost, sticking, not converged).
struct FieldUndefined : std::runtime_error {
    FieldUndefined(const std::string& what, StopReason why) : std::runtime_error(what), reason(why) {}
    StopReason reason;
};
Vec3 field_at(const Scene& scene, const Vec3& q, const LimitCycleOptions& opt, Vec3* warm = nullptr,
              long* rhs_evals = nullptr);   // adds the work spent (right-hand sides) to *rhs_evals

// --- fixed points ------------------------------------------------------------------------
// Centre: the Jacobian's eigenvalues are a complex pair whose real parts are zero within the finite-
// difference Jacobian's own error (the linearisation cannot decide; the orbits around it are closed
// to first order).
enum class Stability { Stable, Unstable, Saddle, Centre };
const char* stability_name(Stability s);
// The stability the eigenvalues ev of a Jacobian say, their real parts taken as zero within
// 3 x `error` (the Jacobian's own error, estimated); `skip`: an eigenvalue left out (along a line).
Stability classify_eigenvalues(const Eigen::VectorXcd& ev, double error, int skip = -1);

struct FixedPoint {
    Vec3 q = Vec3::Zero();                                     // theta in (-pi, pi]
    Eigen::Vector3cd eigenvalues = Eigen::Vector3cd::Zero();   // of the field's Jacobian (point part: 2 used)
    Stability stability = Stability::Saddle;
    double residual = 0;      // |xi_a(q)| [m/s, angular times rho]
    double eigen_error = 0;   // estimated error of the eigenvalues' real parts [1/s] (two difference steps)
};

// A curve of fixed points (Fig. 1): sampled points, its direction, and the stability given by
// the Jacobian's eigenvalues transverse to the line.
struct FixedLine {
    std::vector<Vec3> points;
    Vec3 direction = Vec3::Zero();
    Stability stability = Stability::Saddle;
    Eigen::Vector3cd eigenvalues = Eigen::Vector3cd::Zero();   // at the first point; the one nearest 0 is along the line
    double length = 0;                                         // in (s_x, s_y, rho theta) [m]
    double eigen_error = 0;                                    // as FixedPoint::eigen_error [1/s]
};

// A connected set of grid configurations where the part is stuck all period (twist exactly 0, every
// contact held the whole cycle): every configuration in it is fixed, so it is a region, not points.
// Its extent is that of its grid points (the region's true edge lies within a cell of it).
struct StuckRegion {
    Vec3 lo = Vec3::Zero(), hi = Vec3::Zero();   // bounds of s_x, s_y [m] and theta [rad]; theta from lo
                                                 // to hi going up, hi possibly beyond pi (wraps)
    bool all_theta = false;                      // every theta of the grid (rigid parts)
    int grid_points = 0;
    bool touches_edge = false;   // reaches the grid's s_x or s_y edge: it may extend beyond the grid
};

// A periodic orbit of the field that turns once in theta while the position returns: the part's
// position settles at `q` (s_x, s_y) while theta turns at a steady mean `rate` (rigid parts), or, on a
// plate motion symmetric about the plate's z axis (heave and yaw only), the part turns rigidly about
// the axis: the part's own point `pivot` stays at `centre` = (0, 0) while its position circles it at
// `radius` (a relative equilibrium; fig6: the part turns about its tip contact).
struct RotatingAttractor {
    Vec3 q = Vec3::Zero();   // (s_x, s_y) on the section theta = q[2]
    double rate = 0;         // mean dtheta/dt over the orbit [rad/s]; sign: direction (+: counter-clockwise)
    double period = 0;       // time for one turn [s]
    Eigen::Vector2cd multipliers = Eigen::Vector2cd::Zero();   // of the return map's Jacobian on the section
    Stability stability = Stability::Saddle;                   // |multipliers| < 1: Stable
    double residual = 0;                                       // |return(q) - q| [m]
    double wobble = 0;                                         // largest distance from q along the orbit [m]
    Vec2 centre = Vec2::Zero();   // the point the position circles [m] (the position itself when settled)
    double radius = 0;            // the position's distance from `centre` [m] (0: settled)
    Vec2 pivot = Vec2::Zero();    // the part's point held at `centre`, in the part's frame [m]
};

struct FixedPointOptions {
    // The cycles evaluated while refining. Newton needs a field whose noise is well below ftol: the
    // twist of a cycle carries the integrator's error, tens of rtol v_ref, which makes the line search
    // fail at random, so the refinement runs at rtol <= 1e-3 ftol and cycle tol <= 1e-2 ftol whatever
    // this asks for. (docs/decisions.md, Fixed-point refinement at a tighter tolerance than the field)
    LimitCycleOptions cycle;
    double ftol = 1e-6;   // |xi_a| accepted as zero, relative to v_ref
    int max_newton = 25;
    double null_ratio = 0.02;   // singular value ratio that makes a line candidate
    // Bounded work: no further cell is searched once the refinement's cycles have spent this many
    // right-hand-side evaluations (0: no bound; deterministic, unlike a time limit); the cells left
    // are counted and the summary says so. (The scale: docs/decisions.md, Fixed-point refinement at a
    // tighter tolerance than the field.)
    long max_rhs_evaluations = 20'000'000;
    // Rotating attractors: searched from the grid's (s_x, s_y) columns where omega keeps one sign over
    // every theta, at most this many Newton starts on the return map (0: not searched).
    int max_orbit_starts = 4;
    const StopRequest* stop = nullptr;   // as FieldOptions::stop
};

struct FixedPoints {
    bool point_part = false;
    std::vector<FixedPoint> points;
    std::vector<FixedLine> lines;
    int candidates = 0;         // grid cells where every component changes sign
    int cells = 0;              // grid cells searched
    int undefined_cells = 0;    // cells skipped because a corner's twist is undefined (no cycle there)
    int unsearched_cells = 0;   // cells left when the evaluation budget was spent
    int stuck_cells = 0;        // cells with a corner where the part is stuck all period (twist exactly 0:
                                // every configuration there is fixed; a region, not points to refine)
    long evaluations = 0;       // field evaluations spent refining
    long rhs_evaluations = 0;   // their cycles' right-hand-side evaluations
    std::vector<StuckRegion> stuck_regions;
    std::vector<RotatingAttractor> rotating;
    // Cells without a sign change at their corners whose field is nevertheless near zero (each
    // component's zero, extrapolated linearly, within half a cell of the cell) and not next to a zero
    // found: the corners cannot say whether they hold a zero. Each is refined once, by the field at its
    // centre; where every component then changes sign it is searched by Newton (near_zero_cells, at most
    // 16; beyond, or when the budget is spent: near_zero_unsearched). `coarse_zeros` counts the zeros
    // found only so (the grid missed them). Any of these counts but near_zero_cells, or
    // unresolved_cells, makes the sentence warn that the grid may be too coarse.
    int near_zero_cells = 0;
    int near_zero_unsearched = 0;
    int coarse_zeros = 0;
    // Candidate cells whose field at the centre is farther from its corners' mean (the interpolant
    // there) than the corners' whole spread, in some component: the corners do not resolve the field
    // between them (fig1 on 4 points: omega is zero at every theta of the grid and largest between).
    int unresolved_cells = 0;
    int suggested_grid = 0;   // a finer grid to try when warning (0: no warning)
};

// Zeros of the field: candidate cells of `field` (every component changes sign), refined by
// Gauss-Newton with a finite-difference Jacobian, classified by its eigenvalues; a zero whose
// Jacobian is singular is followed along its null direction and reported as a line when it
// continues across the grid.
FixedPoints find_fixed_points(const Scene& scene, const Field& field, const FixedPointOptions& opt = {});
// What was found, in words that say what was not searched: "2 fixed points and 1 line", "no fixed
// point", each followed, when some cells had an undefined corner, by "in the defined part (k of n
// cells undefined)", and by the cells where the part is stuck all period.
std::string fixed_points_sentence(const FixedPoints& fp);
// "a stable rotating attractor at (x, y) m turning at r rad/s (one turn in T s)".
std::string rotating_attractor_words(const RotatingAttractor& r);

// --- integral curves -----------------------------------------------------------------------
// q' = xi_a(q) from q0 (classical RK4, step h), sampled every sample_dt. Stops where the field
// is undefined (the stop says why).
Trajectory field_curve(const Scene& scene, const Vec3& q0, double duration, double sample_dt, const LimitCycleOptions& opt = {},
                       double h = 0.05);

// Wraps theta to (-pi, pi].
double wrap_angle(double th);

}   // namespace plate
