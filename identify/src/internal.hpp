// The identification's inner pieces, shared by its sources: the parameter layout (names <-> the
// solver's internal coordinates) and the prediction of a track.
#pragma once

#include "plate/identify.hpp"
#include "plate/simulate.hpp"

#include <ceres/ceres.h>

#include <atomic>
#include <limits>
#include <string>
#include <vector>

namespace plate::identify_detail {

// One named parameter: what it sets and of which contact (-1: every contact).
struct Param {
    enum Kind { Kinetic, Static, ComX, ComY } kind = Kinetic;
    int contact = -1;
    std::string name;
};

// The named parameters of a scene in the solver's coordinates: a kinetic coefficient as itself, a
// static one as its excess over the kinetic one(s) it must exceed (>= 0), a centre-of-mass offset in
// millimetres (so that every coordinate is of order 0.1-10 and the difference steps below fit all).
struct Layout {
    std::vector<Param> p;
    Part part;   // the scene's part (the values of what is not fitted)

    Layout(const Scene& scene, const std::vector<std::string>& names);   // std::invalid_argument for a bad name
    int size() const { return static_cast<int>(p.size()); }
    // Scene units (friction, metres) from internal coordinates, and back.
    std::vector<double> natural(const std::vector<double>& x) const;
    std::vector<double> internal(const std::vector<double>& v) const;
    // The scene's values of the named parameters (its static ones raised to the kinetic where below).
    std::vector<double> scene_values() const;
    // Bounds in internal coordinates, and the physical range used to judge identifiability.
    double lower(int j, const IdentifyOptions& o) const;
    double upper(int j, const IdentifyOptions& o) const;
    double range(int j, const IdentifyOptions& o) const;
    // Central-difference step in internal coordinates (docs/decisions/identification.md).
    double step(int j) const;
    const char* unit(int j) const { return p[j].kind == Param::ComX || p[j].kind == Param::ComY ? "m" : "1"; }
};

// A later start of the search after a fit that did not fit as well as the noise allows: the fit's
// coordinates but for the static coefficients' excesses over their kinetic ones, which come from
// `statics` (docs/decisions/identification.md, "Coarse steps first"); `draw` where no static coefficient
// is fitted.
std::vector<double> restart(const Layout& layout, const std::vector<double>& fit, const std::vector<double>& statics,
                            const std::vector<double>& draw);

// The scene at internal coordinates x.
Scene at(const Scene& scene, const Layout& layout, const std::vector<double>& x);

// What the track's camera, noise- and drop-free, records of the part started at rest at q0 at t = 0
// under `scene` at the track's own stamps (simulate_at and film, observe.hpp). False if the run stops
// before the last stamp (contact lost: no prediction).
bool predict(const Scene& scene, const Track& track, Dynamics level, const Vec3& q0, const IntegrationOptions& opt,
             std::vector<Vec3>& q);

// The index of the first frame at or after settle_periods periods.
int first_used_frame(const Track& track, double T, double settle_periods);

// The tracks cut into pieces of `seconds` (rounded to whole plate periods; a track's last piece also
// takes its remainder), each re-timed by a whole number of periods so that its camera stamps start
// within its first period and the plate's phase is kept: the search's first stage fits them, each from
// its own start at rest, its first frames left out (IdentifyOptions::segment_seconds). shifts: each
// piece's re-timing [s] (0 for a track's first piece).
std::vector<Track> segments(const std::vector<Track>& tracks, double T, double seconds, std::vector<double>& shifts);

// A track's scaled residuals r (from frame `first` on) and their Jacobians by the named parameters at
// internal coordinates x (Jx) and by the track's start q0 (mm, mm, rad; a point part without theta:
// Jq), by the fit's own central differences (identify.cpp). False if a simulation stops.
bool track_jacobian(const Scene& scene, const Layout& layout, const Track& track, int first, const IdentifyOptions& o,
                    const std::vector<double>& x, const std::vector<double>& q0, Eigen::VectorXd& r, Eigen::MatrixXd& Jx,
                    Eigen::MatrixXd& Jq);
// ... every track's at once (first[t]: track t's first frame), their simulations as one set of tasks on
// `threads` (PointSimulations); track_jacobian is this for one track on one thread.
bool tracks_jacobians(const Scene& scene, const Layout& layout, const std::vector<Track>& tracks, const std::vector<int>& first,
                      const IdentifyOptions& o, const std::vector<double>& x, const std::vector<std::vector<double>>& q0,
                      int threads, std::vector<Eigen::VectorXd>& r, std::vector<Eigen::MatrixXd>& Jx,
                      std::vector<Eigen::MatrixXd>& Jq);

// The named parameters' Gauss-Newton information J^T J with the tracks' starts (J's last starts_size
// columns) eliminated by the Schur complement, in range-scaled internal units (each coordinate divided
// by its physical range): 1.96 / sqrt(an eigenvalue) is a direction's 95 % half-width as a share of
// the ranges (judge.cpp).
Eigen::MatrixXd scaled_information(const Layout& layout, const IdentifyOptions& o, const Eigen::MatrixXd& J, int starts_size);

// The tracks' starts' regression on the named parameters, -F_qq^+ F_qx (F = J^T J over the n named
// coordinates, then the starts): the quadratic model's minimum over the starts moves by it times dx when
// the parameters move by dx (judge.cpp).
Eigen::MatrixXd start_regression(const Eigen::MatrixXd& F, int n);

// d(named values)/d(internal coordinates) at x (judge.cpp).
Eigen::MatrixXd natural_jacobian(const Layout& layout, const std::vector<double>& x);

// The named parameters' covariance in internal coordinates from the whole Jacobian J (the tracks' starts'
// starts_size columns last): the range-scaled information (scaled_information) inverted along its
// directions whose 95 % half-width lies within the ranges, none along the others; each of those is
// appended to `weak` (its half-width as a share of the ranges, and its unit vector) where given (judge.cpp).
Eigen::MatrixXd identifiable_covariance(const Layout& layout, const IdentifyOptions& o, const Eigen::MatrixXd& J, int starts_size,
                                        std::vector<std::pair<double, Eigen::VectorXd>>* weak);
// Covariance, intervals and identifiability at internal coordinates x from the whole Jacobian J (the
// named parameters' columns, then the starts'), into s.params, s.covariance, s.unidentifiable; returns
// the named parameters' covariance in internal coordinates (none along the directions judged not
// identifiable) (judge.cpp).
Eigen::MatrixXd judge(const Layout& layout, const IdentifyOptions& o, const std::vector<double>& x, const Eigen::MatrixXd& J,
                      int starts_size, IdentifySummary& s);

// One track's residual block: parameter blocks (the named parameters, internal coordinates) and (the
// track's start: s_x, s_y [mm], theta [rad]; a point part without theta). Its Jacobian by the fit's own
// differences: central (`central`), else forward (backward at an upper bound); one-sided at a bound
// (docs/decisions/identification.md).
//
// Profile mode (profile.cpp): block 0 holds z, the internal coordinates with the profiled parameter j's
// own replaced by its value in scene units (held: its column is left zero), so that a static
// coefficient stays at that value while its kinetic base moves; the differences stay within [lo, hi].
struct Prepared;

class TrackCost final : public ceres::CostFunction {
public:
    TrackCost(const Scene& scene, const Layout& layout, const Track& track, int first, const IdentifyOptions& o, bool central);
    void profile(int j, const std::vector<double>& lo, const std::vector<double>& hi);
    // The internal coordinates x of block 0 (the identity outside profile mode); false if z puts a
    // static coefficient below its kinetic base.
    bool internal_of(const double* z, std::vector<double>& x) const;
    bool residuals(const double* z, const double* q0, double* r) const;
    bool Evaluate(double const* const* parameters, double* r, double** jacobians) const override;
    long simulations() const { return sims_; }   // predictions run so far
    // Chord steps (IdentifyOptions::jacobian_reuse; the search's forward differences only): the next
    // Evaluate that asks for Jacobians computes them anew; those after it reuse them up to that many times.
    void fresh_jacobian() const { reused_ = kFresh; }
    void reuse(int times) { reuse_ = central_ ? 0 : times; }

    // An evaluation's simulations one by one (PointSimulations runs every track's at once; Evaluate
    // runs its own in turn). A Jacobian column of block b (0: the named parameters, 1: the start):
    // its step and the sides simulated (none: the column is zero -- the profiled parameter's).
    struct Column {
        int b = 0, j = 0;
        double h = 0;
        bool up = false, down = false;
    };
    std::vector<Column> columns(const double* const* parameters, bool block0, bool block1) const;
    // The residuals with column c's coordinate moved up (upper) or down by its step.
    bool moved(const double* const* parameters, const Column& c, bool upper, double* out) const;
    // Column c of its block's Jacobian from the residuals at the point (r) and moved (plus, minus: may
    // be null where c does not simulate that side).
    void difference(const Column& c, const double* r, const double* plus, const double* minus, double* jacobian) const;
    // Chord steps: true (the kept Jacobians copied) where this evaluation reuses them; keep() after a
    // Jacobian computed anew.
    bool reuse_kept(double* const* jacobians) const;
    void keep(double* const* jacobians) const;
    // While set, Evaluate copies what a PointSimulations prepared (minimise sets and clears it).
    void use(const Prepared* prepared) { prepared_ = prepared; }

private:
    const Scene& scene_;
    const Layout& layout_;
    const Track& track_;
    int first_, dim_;
    const IdentifyOptions& o_;
    bool central_;
    IntegrationOptions opt_;
    int profiled_ = -1;
    std::vector<double> lo_, hi_;
    mutable std::atomic<long> sims_{0};
    static constexpr int kFresh = 1 << 30;
    int reuse_ = 0;                         // 0: a Jacobian computed at every Evaluate that asks
    mutable int reused_ = kFresh;           // times the kept Jacobians were reused since computed
    mutable std::vector<double> kept_[2];   // the last computed Jacobians, blocks 0 and 1
    const Prepared* prepared_ = nullptr;
};

// One track's residuals and Jacobians at the point Ceres evaluates next, as PointSimulations prepared
// them (false: a simulation stopped).
struct Prepared {
    bool ok = false;
    std::vector<double> r, jacobian[2];
};

// Every track's simulations at an evaluation point as one set of tasks on `threads` (a Ceres
// EvaluationCallback; the tracks' costs copy the results while it lives): the residuals where the point
// differs from the last one prepared, and with Jacobians every column's differences (block 0's unless x
// is held whole). Ceres' own threads would share the work out by track (5 tracks on 2 threads keep 83 %
// of them busy), and would simulate the residuals again at a point it has just evaluated (its line
// search's accepted step; the Jacobian after it).
class PointSimulations final : public ceres::EvaluationCallback {
public:
    PointSimulations(const std::vector<TrackCost*>& costs, const std::vector<double>& x,
                     const std::vector<std::vector<double>>& q0, bool x_held, int threads);
    ~PointSimulations() override;
    PointSimulations(const PointSimulations&) = delete;
    PointSimulations& operator=(const PointSimulations&) = delete;
    void PrepareForEvaluation(bool evaluate_jacobians, bool new_evaluation_point) override;

private:
    const std::vector<TrackCost*>& costs_;
    const std::vector<double>& x_;
    const std::vector<std::vector<double>>& q0_;
    bool x_held_;
    int threads_;
    std::vector<Prepared> prepared_;
    std::vector<double> last_x_;   // the point prepared last
    std::vector<std::vector<double>> last_q0_;
};

// Every track's residuals at each of `points` (internal coordinates), the tracks' starts starts[p] (or
// starts[0] for every point), as one set of tasks on `threads`: one stacked vector a point (track 0's
// residuals first), empty where a simulation stopped; `simulations` counts them (residuals.cpp).
std::vector<Eigen::VectorXd> stacked_residuals(const std::vector<TrackCost*>& costs,
                                               const std::vector<std::vector<double>>& points,
                                               const std::vector<std::vector<std::vector<double>>>& starts, int threads,
                                               long& simulations);

// One Levenberg-Marquardt solve over block 0 (`x`, the coordinates in `held` kept) and the tracks'
// starts q0, within [lo, hi], as the fit runs it; x and q0 hold the result. `callback` (may be null)
// can end it early; initial_radius: IdentifyOptions::initial_trust_radius.
struct Solve {
    double chi2 = 0;
    bool usable = false, converged = false;
    int iterations = 0;
    std::string termination;
};
Solve minimise(const std::vector<TrackCost*>& costs, std::vector<double>& x, std::vector<std::vector<double>>& q0,
               const std::vector<int>& held, const std::vector<double>& lo, const std::vector<double>& hi, int max_iterations,
               double seconds, int threads, ceres::IterationCallback* callback = nullptr, double initial_radius = 1e4);

// The search's coarse first steps (coarse.cpp; IdentifyOptions::coarse_iterations) and its wide last ones
// (IdentifyOptions::wide_iterations): up to `iterations` Levenberg-Marquardt steps from x, the coordinates
// in `held` kept, within [lo, hi] and `seconds`, the Jacobian by central differences `factor` times the
// fine steps (Layout::step; a track's start: start_step). Coarse (`wide` false): the
// static coefficients' excesses kept and the tracks' starts held at q0. Wide: every named coordinate and
// every track's start moved. x and q0 hold the result (unchanged if no step lowered the chi-square).
constexpr double kCoarseFactor = 100, kWideFactor = 10;
// The fine difference step of a track's start coordinate c: s_x, s_y [mm] 1e-3, theta [rad] 1e-5.
constexpr double start_step(int c) { return c < 2 ? 1e-3 : 1e-5; }
// The coordinates a secant moves: the named ones in `free`, then (with `starts`) every track's start; `rows`:
// each track's first row in the stacked residuals, and the total last; `count`: the coordinates (coarse.cpp).
struct Columns {
    std::vector<int> free, rows;
    bool starts = false;
    int count = 0;
};
Columns columns_of(const std::vector<TrackCost*>& costs, const std::vector<std::vector<double>>& q0, std::vector<int> free,
                   bool starts);
// The named coordinates not in `held`, of n.
std::vector<int> not_held(int n, const std::vector<int>& held);
// The Jacobian by central differences `factor` times the fine steps (coarse.cpp) over c's columns: the named
// coordinates in c.free (within [lo, hi]; a side whose simulation stopped: the column left zero) first, then,
// with c.starts, each track's start coordinates (that track's rows alone).
Eigen::MatrixXd secant_jacobian(const std::vector<TrackCost*>& costs, const Layout& layout, const IdentifyOptions& o,
                                const std::vector<double>& x, const std::vector<std::vector<double>>& q0, const Columns& c,
                                const std::vector<double>& lo, const std::vector<double>& hi, double factor, long& simulations);
struct CoarseResult {
    int iterations = 0;   // steps taken (each lowered the chi-square)
    double chi2_before = 0, chi2_after = 0, seconds = 0;
    long simulations = 0;
};
CoarseResult coarse_steps(const std::vector<TrackCost*>& costs, const Layout& layout, const IdentifyOptions& o,
                          std::vector<double>& x, std::vector<std::vector<double>>& q0, const std::vector<int>& held,
                          const std::vector<double>& lo, const std::vector<double>& hi, double seconds, int iterations,
                          double factor, bool wide);

// The line steps (coarse.cpp; the wide steps' second rung, "Line steps over the cells"): from x and q0, at each
// of kLineFactors in turn (widest first), up to `iterations` Gauss-Newton steps of every named coordinate not
// in `held` (within [lo, hi]) and every track's start, the Jacobian by central differences that factor times
// the fine steps, each step's length the one of kLineLengths (times the Gauss-Newton step) whose chi-square is
// lowest, kept where lower than before; a factor's steps stop at the first no length lowers. Within `seconds`;
// x and q0 hold the result (unchanged if no step lowered the chi-square).
constexpr double kLineFactors[] = {300, 100, 30};
constexpr double kLineLengths[] = {0.125, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0};
CoarseResult line_steps(const std::vector<TrackCost*>& costs, const Layout& layout, const IdentifyOptions& o,
                        std::vector<double>& x, std::vector<std::vector<double>>& q0, const std::vector<int>& held,
                        const std::vector<double>& lo, const std::vector<double>& hi, double seconds, int iterations);

// A point of the search's space (internal coordinates, the tracks' starts) and the tracks' chi-square there.
struct PathEnd {
    double chi2 = std::numeric_limits<double>::infinity();
    std::vector<double> x;
    std::vector<std::vector<double>> q0;
};

// The linearised intervals' check at their ends (FittedParameter::dchi2_lo, dchi2_hi, linearity): for
// each identifiable parameter, the tracks' chi-square at x and q0 moved 1.96 linearised sds along the
// quadratic model's profile path (cov_internal: judge()'s; the starts by their regression on the
// parameters), less s.chi2; 2 predictions a track a parameter, on o.threads. `better`: the end with the
// lowest chi-square (chi2 infinite if none was checked) (judge.cpp).
void check_linearity(const Layout& layout, const IdentifyOptions& o, const std::vector<TrackCost*>& costs,
                     const std::vector<double>& x, const std::vector<std::vector<double>>& q0, const Eigen::MatrixXd& J,
                     const Eigen::MatrixXd& cov_internal, IdentifySummary& s, PathEnd& better);

// The spread of the estimate over the chi-square's cells near the fit (cells.cpp; "The spread over the
// chi-square's cells", docs/decisions/identification.md): o.cell_samples points drawn about the fit at
// internal coordinates x and starts q0 (cell_moves), their residuals simulated, each taken one
// Gauss-Newton step by the fit's Jacobian J (cell_mixture). Returns the cells' covariance in internal
// coordinates (zero where nothing was drawn). r0: the residuals at the fit. The draws are seeded by
// o.seed: the result does not depend on threads. Its simulations run after the search (as the interval
// check's), beyond o.time_limit.
Eigen::MatrixXd cell_spread(const Layout& layout, const IdentifyOptions& o, const std::vector<TrackCost*>& costs,
                            const std::vector<double>& x, const std::vector<std::vector<double>>& q0, const Eigen::MatrixXd& J,
                            const Eigen::VectorXd& r0, const Eigen::MatrixXd& cov_internal);
// The draws' moves over the named coordinates then the starts: the named ones from the linearised
// covariance cov_internal, the first half at its sds and the rest at twice them, kept within the bounds;
// the starts by their regression on them.
std::vector<Eigen::VectorXd> cell_moves(const Layout& layout, const IdentifyOptions& o, const std::vector<double>& x,
                                        const Eigen::MatrixXd& J, const Eigen::MatrixXd& cov_internal);
// From the residuals r[k] at each move (empty: a simulation stopped there): the linear model through the
// draw's residuals (the fit's Jacobian J) has its minimum shifted from the fit by -F^+ J^T d_k (d_k = r[k]
// - r0 - J move_k, the departure from the fit's linear model: the cells the move crossed; the starts
// eliminated, along the identifiable directions of cov_internal only, within [lower, upper] of the shift),
// with its chi-square there, the starts at their best; the fit's own by the same formula. The fit and those
// minima, each weighted by exp(-chi2 / 2), make a mixture; its second moment about the fit is returned
// (n x n, n = cov_internal's size). A non-finite minimum is left out.
Eigen::MatrixXd cell_mixture(const Eigen::MatrixXd& J, const Eigen::VectorXd& r0, const Eigen::MatrixXd& cov_internal,
                             const std::vector<double>& lower, const std::vector<double>& upper,
                             const std::vector<Eigen::VectorXd>& moves, const std::vector<Eigen::VectorXd>& r);

// s's covariance, sds and intervals with the cells' covariance (internal coordinates) added (judge.cpp).
void add_cells(const Layout& layout, const std::vector<double>& x, const Eigen::MatrixXd& cov_cells, IdentifySummary& s);

// The chi-square's envelope across its cells ("The envelope across the cells", docs/decisions/identification.md):
// the fit's Jacobian by central differences kEnvelopeFactors times the fine steps (secant_jacobian: every
// named coordinate but those in `held`, and every track's start) is a secant over several cells, where
// the fine one is the tangent of one cell's floor; 3 to 30 fine steps span the scales from the cliffs
// between cells (1-4e-4 apart along a static coefficient) to the static coefficients' sds (about 3e-3).
// Each factor's covariance as judge() forms it; returns per named parameter its largest sd over the
// factors (scene units; 0 where no factor places it) (cells.cpp). `simulations` counts them.
constexpr double kEnvelopeFactors[] = {3, 10, 30};
std::vector<double> envelope_sds(const Layout& layout, const IdentifyOptions& o, const std::vector<TrackCost*>& costs,
                                 const std::vector<double>& x, const std::vector<std::vector<double>>& q0,
                                 const std::vector<int>& held, const std::vector<double>& lo, const std::vector<double>& hi,
                                 long& simulations);
// s's sds with the envelope (per parameter, scene units): sd^2 = max(within, sd_envelope)^2 + cells^2, the
// within-cell sd (sqrt(sd^2 - sd_cells^2)) replaced by the envelope's where that is wider, the cells' spread
// (sd_cells, from add_cells) kept beside it. Where the sd grows, the covariance's row and column are scaled
// by the ratio (its correlations kept), the interval set anew, and sd_envelope takes the added share
// (sqrt(envelope^2 - within^2)), so that within_cell_sd stays the same (judge.cpp).
void add_envelope(const std::vector<double>& sd_envelope, IdentifySummary& s);

}   // namespace plate::identify_detail
