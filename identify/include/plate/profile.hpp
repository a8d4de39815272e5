// Profile likelihood of an identification's parameters (issue 52, point 3: "95 % intervals, profile
// likelihood where the problem is not linear enough for the covariance"). For a fitted parameter p, the
// profile is chi2(p) minimised over every other fitted parameter and every track's start (the fit's
// nuisance parameters), less the fit's chi-square; its 95 % interval is where it stays below 3.84 (the
// chi-square quantile of one degree of freedom), found by stepping p from the estimate outward in each
// direction, each step re-minimised by the fit's own Levenberg-Marquardt warm-started from the last,
// until the profile crosses 3.84 (the end by interpolation on sqrt(profile), exact for a quadratic one,
// then up to 3 re-minimised refinements: at the interpolated crossing, then bisecting) or p reaches its
// physical bound (the interval then runs to it).
//
// The bounds along a profile: a kinetic coefficient [mu_min, mu_max]; a static one from its kinetic
// base at the estimate (static >= kinetic: along its profile the base is kept at or below the value)
// to mu_max; a centre-of-mass offset +-com_max.
//
// Which interval is THE interval (ParameterProfile::interval_is_profile): the linearised one (estimate
// -+ 1.96 sd) where both of the profile's ends crossed 3.84 and each lies within `agreement` times the
// linearised half-width of the linearised end; otherwise the profile's -- one that runs to a bound says so, one
// that runs to both bounds is "not identifiable"; a profile cut short (a cap reached) keeps the
// linearised interval and says so (docs/decisions/identification.md, "Profile likelihood").
#pragma once

#include "plate/identify.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace plate {

// Validated once, by validate() (std::invalid_argument naming the field).
struct ProfileOptions {
    std::vector<std::string> params;   // the fitted parameters to profile (empty: every one)
    int max_steps = 8;                 // re-minimisations per direction, the refinement included
    int max_iterations = 10;           // Levenberg-Marquardt iterations per re-minimisation
    long max_simulations = 200000;     // over every profile (each a prediction of one track)
    double time_limit = 300;           // [s] over every profile
    double agreement = 0.2;            // linearised and profile ends within this share of the linearised half-width: agree
    void validate() const;
};

// Chi-square quantile of one degree of freedom at 95 %: the profile's threshold.
constexpr double kProfileThreshold95 = 3.841458820694124;
// Its square root, the normal distribution's 97.5 % quantile: a 95 % interval's half-width in sds.
constexpr double kZ95 = 1.959963984540054;

struct ProfilePoint {
    double value = 0;   // the parameter, scene units
    double dchi2 = 0;   // chi2 minimised over the rest, less the fit's chi2
};

// How an end of a profile interval was found.
enum class ProfileEnd {
    Crossed,   // the profile crossed 3.84 there
    AtBound,   // it stayed below 3.84 up to the physical bound: the interval is open to the bound
    CutShort   // a cap (steps, simulations, time) or a stopped simulation ended the walk first
};
const char* to_string(ProfileEnd e);

struct ParameterProfile {
    std::string name, unit;
    double estimate = 0;
    std::vector<ProfilePoint> points;   // by value, the estimate's (0) included
    double lo = 0, hi = 0;              // the profile's 95 % interval
    ProfileEnd lo_end = ProfileEnd::CutShort, hi_end = ProfileEnd::CutShort;
    double bound_lo = 0, bound_hi = 0;   // the physical bounds along the profile
    // The linearised interval within the fit's cell, estimate -+ 1.96 within_cell_sd (identify.hpp), the
    // profile's counterpart (NaN where judged not identifiable).
    double linear_lo = 0, linear_hi = 0;
    // THE 95 % interval is the profile's, each side widened by the cells' spread in quadrature (as the sd
    // takes it; not by the envelope, which the profile's re-minimisations see themselves) within the bounds (lo_reported,
    // hi_reported); else the linearised one with the cells' spread.
    bool interval_is_profile = false;
    double lo_reported = 0, hi_reported = 0;
    bool identifiable = true;   // false: the profile stays below 3.84 from bound to bound
    double chi2_drop = 0;       // the largest drop below the fit's chi2 seen along the profile (> 0: a better minimum)
    std::string verdict;
    long simulations = 0;
    double seconds = 0;
};

struct ProfileSummary {
    std::vector<ParameterProfile> profiles;   // in the fit's order of the parameters profiled
    double chi2_min = 0;                      // the fit's chi2, the profiles' zero
    long simulations = 0;
    double seconds = 0;
};

// The profiles of the parameters asked, about the fit `fit` (identify() on the same scene, tracks and
// options). Throws std::invalid_argument for a name that was not fitted, as validate() for bad options.
ProfileSummary profile_likelihood(const Scene& scene, const std::vector<Track>& tracks, const IdentifyOptions& o,
                                  const IdentifySummary& fit, const ProfileOptions& po);

// The identification's JSON (identify_json) with the profiles: each parameter's "interval95" becomes THE
// interval, beside "interval95_linearised", "interval95_profile" (ends flagged "crossed", "at bound",
// "cut short"), "interval_method" and the verdict; "profiles" holds the points (value, dchi2).
nlohmann::json identify_json(const IdentifySummary& s, const IdentifyOptions& o, const ProfileSummary& p,
                             const ProfileOptions& po);

}   // namespace plate
