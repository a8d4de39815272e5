// What a real plate and part differ from the nominal scene by (issue 51): an uncertainty spec (JSON),
// read and checked once here, and seeded draws of perturbed scenes from it.
//
//   { "seed": 7,                                                     // required, whole number >= 0
//     "friction":      {"spread": 0.10, "distribution": "uniform"},  // per contact, relative
//     "mass":          {"spread": 0.01, "distribution": "normal"},   // scale of m, relative
//     "inertia":       {"spread": 0.02, "distribution": "normal"},   // scale of J, relative
//     "contacts_mm":   {"spread": 0.2,  "distribution": "normal"},   // each contact, x and y, mm
//     "com_offset_mm": {"spread": 0.3,  "distribution": "normal"},   // centre of mass, x and y, mm
//     "amplitude":     {"spread": 0.03, "distribution": "normal"},   // per harmonic, relative
//     "phase":         {"spread": 0.03, "distribution": "normal"},   // per harmonic, rad
//     "unmodelled":    {"up_to": 5, "rms_fraction": 0.02},           // per axis, of its RMS
//     "period":        {"spread": 0.001, "distribution": "normal"} } // relative
//
// Every field but the seed is optional (absent: no spread); unknown fields are errors. A spread is
// the standard deviation of a normal draw and the half-width of a uniform one (spread 0.1 uniform:
// +-10 %). The distribution defaults to normal.
#pragma once

#include "plate/model.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace plate {

enum class Distribution { normal, uniform };

// One perturbation: zero-mean, of standard deviation `spread` (normal) or on [-spread, spread]
// (uniform, standard deviation spread / sqrt(3)).
struct Spread {
    double spread = 0;
    Distribution distribution = Distribution::normal;
    double standard_deviation() const;
};

struct UncertaintySpec {
    std::string source;   // file it was read from (for messages)
    std::uint64_t seed = 0;
    Spread friction;        // mu_i (1 + e_i), one e_i per contact
    Spread mass, inertia;   // m (1 + e), J (1 + e'), independent
    Spread contacts_mm;     // c_i + (e_ix, e_iy, 0) mm, each contact on its own
    Spread com_offset_mm;   // the centre of mass moved by (d_x, d_y, 0) mm: every c_i - d
    Spread amplitude;       // each harmonic's amp (1 + e)
    Spread phase;           // each harmonic's phase + e [rad]
    // Harmonics the plate adds unasked: on each axis with a commanded signal, every n from 1 to
    // unmodelled_up_to that the axis does not command, with random amplitudes and phases scaled so
    // that their sum's RMS is exactly unmodelled_rms_fraction of the commanded signal's RMS.
    int unmodelled_up_to = 0;
    double unmodelled_rms_fraction = 0;
    Spread period;   // T (1 + e)
};

// Ranges a spec must lie in: relative spreads up to kMaxRelativeSpread, phases up to pi, positions up
// to kMaxSpreadMm, unmodelled harmonics up to n = 1000 at up to the commanded RMS.
inline constexpr double kMaxRelativeSpread = 0.5, kMaxSpreadMm = 50;
// A draw that is no valid scene (validate_scene) is redrawn, up to this many times; then an InputError.
inline constexpr int kMaxRedraws = 100;

UncertaintySpec load_uncertainty(const std::string& path);                               // throws InputError
UncertaintySpec parse_uncertainty(const std::string& text, const std::string& source);   // throws InputError
void validate_uncertainty(const UncertaintySpec& spec);                                  // throws InputError

// Draw number `index` of the spec around `nominal`: a function of (spec.seed, index) and the spec
// only, so draws can be made in any order, on any thread or rank. Always a valid scene: a draw that
// fails validate_scene (negative friction, a part that tips, ...) is redrawn from the next stream of
// the same (seed, index). Named "<name>~<index>".
Scene draw(const Scene& nominal, const UncertaintySpec& spec, std::uint64_t index);

// THE SPEC AS PARAMETERS. A draw is the nominal scene moved by a vector p of independent scalar
// deviations, one per entry of uncertain_parameters (in its order): the linearisation the fixed
// points' sensitivities use (robustness.hpp) and the draws apply the same p through perturbed().
//   friction[i]        mu_i (1 + p), relative (a point part: one, for its one coefficient); a contact's
//                      static coefficient, if the scene has one, by the same factor
//   mass, inertia      m (1 + p), J (1 + p), relative (inertia: rigid parts)
//   contact[i].x/.y    c_i + p, m (rigid parts)
//   com.x/.y           every c_i - p, m: the centre of mass moved by p (rigid parts)
//   amp[h], phase[h]   harmonic h of the nominal plate (its order): amp (1 + p), phase + p [rad]
//   unmodelled[a,n].cos/.sin   an added harmonic p_c cos(n w t) + p_s sin(n w t) on axis a, in the
//                      axis's unit: every n <= up_to that a commanded axis a does not command
//   period             T (1 + p), relative
// standard_deviation is p's over draws: a Spread's, and for an unmodelled coefficient
// f RMS_a / sqrt(K_a) (K_a harmonics added on axis a at RMS fraction f: each harmonic's random
// amplitude and uniform phase give E[p_c^2] = E[p_s^2] = E[amp^2] / 2 = f^2 RMS_a^2 / K_a). Every
// entry is listed, a zero spread's too (standard deviation 0).
struct UncertainParameter {
    std::string name;                // as above, e.g. "friction[2]", "amp[rx,n=1]", "unmodelled[z,n=4].sin"
    const char* unit = "";           // "relative", "m", "rad", "m/s^2" or "rad/s^2"
    double standard_deviation = 0;   // of p over draws, in its unit
};
std::vector<UncertainParameter> uncertain_parameters(const Scene& nominal, const UncertaintySpec& spec);
// The nominal scene with deviations p applied (p.size() == uncertain_parameters(...).size(); zero: the
// nominal). Not validated: a large p may give no valid scene (draw() redraws such p).
Scene perturbed(const Scene& nominal, const UncertaintySpec& spec, const std::vector<double>& p);

// Draw number `index` with its deviations p (draw(nominal, spec, index) == perturbed(nominal, spec, p)).
struct Draw {
    Scene scene;
    std::vector<double> p;
};
Draw draw_with_deviations(const Scene& nominal, const UncertaintySpec& spec, std::uint64_t index);

// The RMS over a period of each axis of u(t) (x y z in m/s^2, rx ry rz in rad/s^2): harmonics of one
// axis and one n add as phasors.
Vec6 axis_rms(const PlateMotion& plate);

}   // namespace plate
