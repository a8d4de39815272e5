// Identification of a part's parameters from camera tracks (issue 52, point 3): the friction
// coefficients and the centre-of-mass offset that make the hybrid simulation reproduce what the
// cameras filmed, by least squares (Ceres' Levenberg-Marquardt; docs/decisions/identification.md says
// why Ceres and how each choice below was made), with their covariance, 95 % intervals and a verdict on
// what the tracks cannot separate.
//
// The parameters, by name (a comma-separated list on the command line):
//   mu_k              every contact's kinetic coefficient, one shared value
//   mu_k1 mu_k2 mu_k3 contact i's kinetic coefficient (rigid parts)
//   mu_s              every contact's static coefficient, one shared value
//   mu_s1 mu_s2 mu_s3 contact i's static coefficient (rigid parts)
//   com_x com_y       the centre of mass's offset from the scene's, in the part frame [m]: every contact
//                     moves by -offset (as uncertainty.cpp's "com" does; the inertia is kept, and the
//                     camera is taken to see the centre of mass)
// A contact's coefficient is fitted by at most one name (mu_k with mu_k2 is refused). Static >= kinetic
// holds by construction: the solver moves a static coefficient's excess over the kinetic one(s) it
// must exceed, bounded below by 0 (a shared mu_s over per-contact kinetic ones: its excess over their
// largest). A static coefficient not fitted keeps the scene's value, raised to its contact's fitted
// kinetic one where that is larger; in a scene with one coefficient per contact (no static ones of
// its own: static = kinetic) it follows the fitted kinetic one.
//
// The model of a track: the part starts at t = 0 (the camera's zero) at rest relative to the plate, at
// a configuration fitted per track (nuisance parameters, started at the track's first frame), as
// observe() films it; frames before settle_periods plate periods may be left out (default none), so
// that a part filmed with another start twist fits once friction has damped the difference. Each kept frame gives the residuals
// (s_x, s_y) / sd_xy and theta / sd_theta (a point part: no theta), the camera's noise sds, so that
// the sum of squares is a chi-square at the truth.
#pragma once

#include "plate/dynamics.hpp"
#include "plate/model.hpp"
#include "plate/observe.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace plate {

// What an identification asks: validated once, by validate() (std::invalid_argument naming the field).
struct IdentifyOptions {
    std::vector<std::string> params;   // the names above, each once; at least one
    Dynamics level = Dynamics::Full;   // the model the tracks are fitted with (Full or U)
    // Multi-start: the scene's values, then seeded draws within the bounds, until one fits as well as
    // the noise allows (chi-square within 3 sds of its mean at the truth) or all have run. After a
    // usable fit, a later start takes the best fit's coordinates but for the static coefficients'
    // excesses (identify_detail::restart). starts and time_limit: the settings of the benchmarks' coverage
    // runs (docs/decisions/identification.md, "The defaults: two starts within 150 s").
    int starts = 2;
    std::uint64_t seed = 1;      // of the drawn starts
    int max_iterations = 25;     // Levenberg-Marquardt iterations per start
    double time_limit = 150;     // [s] over all starts; a start under way stops at it
    double settle_periods = 0;   // frames before this many plate periods are left out
    // The simulation's tolerance (IntegrationOptions::rtol): 1e-7 keeps fig4's kinetic estimates within
    // their sd of those at 1e-8 at about a third of the time (docs/decisions/identification.md, Measured).
    double rtol = 1e-7;
    // Simulations in parallel (every track's at a search point at once); the fit does not depend on it.
    int threads = 2;
    // The search (docs/decisions/identification.md, "A cheaper search"): each start first fits the tracks'
    // starts alone (the named parameters held: three coordinates a track, cheap), then everything, its
    // Jacobian by forward differences (one simulation a column) unless central_search (two). The
    // covariance, the intervals and --suggest always use central differences.
    bool fit_starts_first = true;
    bool central_search = false;
    // The search's first stage ("Pieces first"): each start fits the tracks cut into pieces of
    // segment_seconds (whole periods), each piece from its own start at rest with its first
    // segment_settle_periods periods left out, then the whole tracks from there; 0, no track as long as
    // two pieces, or a plate turning about more than one axis (not periodic: coning): no such stage.
    double segment_seconds = 2;
    double segment_settle_periods = 4;
    // Levenberg-Marquardt's first trust-region radius (Ceres' initial_trust_region_radius): the damping
    // starts at each parameter's floored information over it, and grows or shrinks from there
    // (docs/decisions/identification.md, "The first trust region").
    double initial_trust_radius = 1e4;
    // Chord steps ("Chord steps: a track's Jacobian reused -- measured, not the default"): after the search
    // computes a track's Jacobian by forward differences, the next jacobian_reuse evaluations that ask for
    // it get it back (only their residuals simulated, 1 prediction instead of 1 + parameters + start's);
    // a solve that converged so is confirmed by one without reuse. 0: computed at every evaluation. The
    // covariance, the check, the profiles and --suggest always compute theirs.
    int jacobian_reuse = 0;
    // Hops ("Hops: the search goes on from a better end"): after the fit, while the interval check finds a
    // chi-square lower by more than 1 at an end of its paths, the search goes on from there, at most this
    // many times within time_limit. 0: never.
    int hops = 4;
    // Coarse steps first ("Coarse steps first"): before its pieces, each start takes up to this many
    // Levenberg-Marquardt steps of the kinetic coefficients and offsets on the whole tracks, their starts
    // held at the first frames and the static coefficients' excesses held (identify_detail::coarse_steps).
    // 0: none.
    int coarse_iterations = 2;
    // Wide steps last ("Wide steps across the cells"): after the search, the best fit takes up to this many
    // Levenberg-Marquardt steps with the Jacobian by central differences identify_detail::kWideFactor times
    // the fine steps (a secant over the chi-square's cells, where the fine steps' tangent sees one cell's
    // floor), every coordinate the search moves and every track's start at once; then ("Line steps over the
    // cells") up to this many Gauss-Newton steps at each of identify_detail::kLineFactors times the fine steps,
    // each step's length the one of identify_detail::kLineLengths whose chi-square is lowest. Where either
    // kind lowers the chi-square by more than 1, the fine search goes on from there and its end is the fit if
    // lower still. 0: none.
    int wide_iterations = 4;
    // Cells near the fit ("The spread over the chi-square's cells"): the interval's sd also takes the
    // spread of the chi-square's cell minima near the fit, found from this many points drawn about it (half
    // at the linearised covariance, half at twice its sds), each taken one Gauss-Newton step to its cell's
    // minimum and weighted by its likelihood (identify_detail::cell_spread). 0: the linearised sd alone.
    int cell_samples = 32;
    // The envelope across the cells ("The envelope across the cells"): the within-cell sd is replaced by the
    // one from the fit's Jacobian by differences 3, 10 or 30 times the fine steps where that is wider (a secant
    // over several cells, where the fine Jacobian is one cell's tangent), the cells' spread added to it as
    // before; the widening is FittedParameter::sd_envelope. false: the within-cell sd and the cells' spread alone.
    bool envelope = true;
    double mu_min = 0.05, mu_max = 1.5;   // physical bounds of a friction coefficient
    double com_max = 0.02;                // [m]: |com_x|, |com_y| at most this
    void validate() const;
};

// One fitted parameter, in the scene's units.
// The verdict of the interval's check at its ends (FittedParameter::dchi2_lo, dchi2_hi). A quadratic
// profile crossing 3.84 within a fifth of the linearised half-width of the ends (ProfileOptions::agreement)
// has 3.84 / 1.2^2 = 2.67 to 3.84 / 0.8^2 = 6.0 there; the path's rise bounds the profile's from above.
enum class Linearity {
    Holds,         // both ends' rise within [2.67, 6.0]
    TooNarrow,     // an end's rise below 2.67 (or below 0: a better fit on the path): the profile, no higher,
                   // crosses further out; the linearised interval is too narrow (--profile)
    Unconfirmed,   // an end's rise above 6.0, none below 2.67: the path rises faster than a quadratic; the
                   // profile, which may rise more slowly, decides (--profile)
    NotChecked     // not identifiable, an end outside the physical bounds, or a simulation stopped on the path
};
const char* to_string(Linearity l);

struct FittedParameter {
    std::string name, unit;   // unit "1" (friction) or "m"
    double estimate = 0;
    double sd = 0;              // from the covariance (the cells' spread included); NaN where not identifiable
    double sd_cells = 0;        // of which the spread over the chi-square's cells' minima near the fit
    double sd_envelope = 0;     // of which the envelope's widening of the within-cell sd (IdentifyOptions::envelope):
                                // sd^2 - sd_cells^2 - sd_envelope^2 is the linearised (within its cell) variance
    double lo = 0, hi = 0;      // 95 %: estimate -+ 1.96 sd; NaN where not identifiable
    bool identifiable = true;   // false: part of a combination the tracks cannot separate
    bool at_bound = false;      // the estimate lies on a physical bound (the interval is then one-sided at best)
    // Is the chi-square quadratic over the interval? Its rise over the fit's at the interval's ends along
    // the linearised profile's path (the other parameters and the tracks' starts moved by their regression
    // on this one): 3.84 at both ends where it is (docs/decisions/identification.md, "Checked at its ends").
    // NaN where not checked.
    double dchi2_lo = std::numeric_limits<double>::quiet_NaN(), dchi2_hi = std::numeric_limits<double>::quiet_NaN();
    Linearity linearity = Linearity::NotChecked;
};

// A combination of the parameters the tracks cannot place within the physical ranges: the singular
// vector (weights per name, unit length in range-scaled units) and its 95 % half-width in those units
// (> 1: wider than the whole range; infinite: the tracks do not depend on it at all).
struct Unidentifiable {
    std::vector<std::pair<std::string, double>> combination;
    double half_width = 0;
};

struct TrackFit {
    std::string source;
    int frames = 0;              // used in the fit
    Vec3 start = Vec3::Zero();   // the fitted start configuration at t = 0 [m, m, rad]
    double rms_xy_mm = 0;        // residual RMS of s_x and s_y [mm]
    double rms_theta_mrad = 0;   // of theta [mrad] (0 for a point part)
    double chi2 = 0;             // the track's sum of squared scaled residuals
};

// The linearised sd within the fit's cell, sqrt(sd^2 - sd_cells^2 - sd_envelope^2): what the interval check
// and the profile are set beside (NaN where not identifiable).
double within_cell_sd(const FittedParameter& p);

// IdentifySummary::explains_tracks: a fit whose chi-square the noise alone exceeds less often than this.
constexpr double kFitPValueFloor = 1e-3;

struct IdentifySummary {
    std::vector<FittedParameter> params;   // in the order asked
    Eigen::MatrixXd covariance;            // of the estimates, rows and columns as params (NaN where not identifiable),
                                           // the spread over the chi-square's cells included
    std::vector<Unidentifiable> unidentifiable;
    std::vector<TrackFit> tracks;
    double chi2 = 0;              // sum of squared scaled residuals at the estimate
    int residuals = 0, dof = 0;   // dof: residuals - fitted parameters (the starts' included)
    double reduced_chi2 = 0;      // chi2 / dof: near 1 when the model and the noise sds are right
    // Goodness of fit: P(a chi-square of dof degrees >= chi2), what the noise alone would exceed (with
    // the cameras' sds exact and Gaussian). Below kFitPValueFloor the estimate does not explain the
    // tracks (explains_tracks false): a local minimum (its intervals then mean nothing), a model the
    // tracks contradict, or noise sds too small (at 1500 degrees of freedom 6 % too small is enough;
    // the intervals are then too narrow by about sqrt(reduced_chi2)). Sds too large are not flagged
    // (p near 1, intervals too wide). NaN where dof <= 0: not judged, explains_tracks left true.
    double p_value = std::numeric_limits<double>::quiet_NaN();
    bool explains_tracks = true;
    int starts_run = 0, best_start = 0;
    int held = 0;                  // named parameters no residual depended on at the first start: held there
    int iterations = 0;            // of the best start, its hops' included
    int pieces = 0;                // fitted in the first stage (segment_seconds; 0: no such stage)
    int coarse_iterations = 0;     // of the best start's coarse steps (IdentifyOptions::coarse_iterations)
    double coarse_seconds = 0;     // their time [s]
    double cells_seconds = 0;      // the cells' draws' time [s] (IdentifyOptions::cell_samples)
    double envelope_seconds = 0;   // the envelope's Jacobians' time [s] (IdentifyOptions::envelope)
    int wide_iterations = 0;       // the wide and line steps the fit took (IdentifyOptions::wide_iterations; 0: none kept)
    double wide_chi2_drop = 0;     // how far they and the fine searches after them lowered the chi-square
    double wide_seconds = 0;       // their time and those searches' [s] (IdentifyOptions::wide_iterations)
    int piece_iterations = 0;      // of the best start's first stage on the pieces
    int hops = 0;                  // times the search went on from a better end of the interval check's paths
    double piece_seconds = 0;      // its time [s]
    std::string termination;       // of the best start (Ceres' termination type and message)
    bool converged = false;
    double seconds = 0;
    std::vector<double> start_costs;   // each start's final chi2
    Scene fitted;                      // the scene at the estimates
};

// InputError naming the file (and line) of a track that cannot be fitted to `scene`: from another
// scene (check_track_scene), a rigid track for a point part or the reverse, a camera without noise
// (the residuals' scale), fewer than kMinTrackFrames frames after settle_periods.
void check_tracks(const Scene& scene, const std::vector<Track>& tracks, const IdentifyOptions& o);

// std::invalid_argument unless every name is one of the above, given once, that the scene's part has
// (mu_k2 for a point part, com_x for a point part: refused), no contact fitted by two names.
void check_parameter_names(const Scene& scene, const std::vector<std::string>& names);

// std::invalid_argument unless the pieces of the search's first stage (segment_seconds, in whole periods
// of scene's plate) are longer than the periods each leaves out (segment_settle_periods); none asked: fine.
void check_pieces(const Scene& scene, const IdentifyOptions& o);

// The scene with the named parameters at `values` (scene units; static below kinetic refused with
// std::invalid_argument). The one place a parameter reaches the part.
Scene apply_parameters(const Scene& scene, const std::vector<std::string>& names, const std::vector<double>& values);

// The least-squares fit over the tracks. Throws as check_parameter_names, check_tracks and validate.
IdentifySummary identify(const Scene& scene, const std::vector<Track>& tracks, const IdentifyOptions& o);

// The summary as the command writes it (units in the keys or beside the values).
nlohmann::json identify_json(const IdentifySummary& s, const IdentifyOptions& o);

}   // namespace plate
