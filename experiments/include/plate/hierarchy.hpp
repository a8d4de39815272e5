// Model no more than a scene needs. Two ladders, cheapest first:
//   the part:      point (one contact at the centre of mass, no rotation)
//                < thin (contacts moved into the plane of the centre of mass, J_xz = J_yz = 0:
//                  decoupled normal forces, Appendix A)
//                < thick (the part as given; coupled 6x6 system)
//   the dynamics:  reduced U (the field's integral curve, Section IV-C) < U (32) < full (31).
// `choose_model` answers one question on the scene -- where the part goes from q0 in `duration`
// seconds -- with every rung the scene allows, measures each rung's error against the most
// complete model, and picks the cheapest rung whose measured error is below the tolerance.
// It reports what it picked and the measured error of every simplification.
#pragma once

#include "plate/dynamics.hpp"
#include "plate/model.hpp"

#include <string>
#include <vector>

namespace plate {

enum class PartModel { Point, Thin, Thick };
const char* part_model_name(PartModel p);

// The scene with its part simplified (Thick returns the part as given).
Scene simplified(const Scene& scene, PartModel p);

struct Rung {
    PartModel part = PartModel::Thick;
    Dynamics dynamics = Dynamics::Full;
    double error = 0;           // final-configuration error against the most complete model:
                                // max(|ds| / rho, |dtheta| [rad]); a point part's theta stays at theta0
    double seconds = 0;         // its cost
    long work = 0;              // and in right-hand-side evaluations (deterministic)
    bool ok = false;            // it ran to the end (no stop)
    std::string note;           // why not ok
    std::string name() const;   // e.g. "thin / u"
};

struct ModelChoice {
    double tol = 0;
    Rung picked;   // the cheapest with error <= tol (the reference itself if none)
    bool any_simplification = false;
    std::vector<Rung> rungs;   // all, cheapest first; the last is the reference (error 0)
    std::string explain() const;
    // The cheapest rung cheaper than the reference whose measured error is <= tol (the reference if
    // none): the choice choose_model made at its own tolerance, and the one it would make at another.
    const Rung& pick(double tol) const;
};

// Rungs are ordered by cost: the dynamics ladder first (reduced U, U, full), the part ladder
// within it. The reference is the scene's own part under full dynamics.
ModelChoice choose_model(const Scene& scene, const Vec3& q0, double duration, double tol);

// A PRIORI: each simplification's error on the same question (final configuration after
// `duration` from rest at q0, relative to rho and in radians), predicted before any trajectory is
// run from a few reduced-U limit cycles at q0 (milliseconds) and the scene's dimensionless numbers:
//   part      xi, the scene's own part's asymptotic twist at q0 (scaled: v / rho, omega), and the
//             simplified parts' cycles there from rest: a thin part drifts differently by
//             |xi_thin - xi| D; a point part by |v_point - v| D / rho and cannot turn (|omega| D);
//             each ends its transient displaced by the difference of the transients' offsets.
//   U         what (32)-(34) drop against what drives the drift, friction mu g: the tilt the plate's
//             rotations give gravity, g sum alpha / (n w)^2, the Coriolis and centripetal terms
//             2 |w1| v_ref and |w1|^2 |s| (|w1| = sum alpha / (n w)): eps_U, times the path xi D,
//             plus U against full at the end of the transient from rest (both run through it: the
//             tilted plate delays the break-away and shifts the phase the cycle is entered at).
//   reduced   the field's integral curve from q0 misses the transient's offset X - xi t (X the
//             displacement of the run from rest to its cycle) and the in-period excursion about
//             the curve, both read off the same cycle.
// Where the field spreads neighbouring paths (its Jacobian's largest eigenvalue lambda at q0 > 0),
// the drift terms grow by Gronwall's factor (e^{lambda D} - 1) / (lambda D).
// A rung's prediction is kSafety times the sum of its simplifications' terms.
struct ModelEstimate {
    double duration = 0;
    bool ok = false;   // the cycles converged (else no prediction: auto keeps the reference)
    std::string note;
    double xi = 0;   // scaled |xi| of the own part [1/s]
    double e_point = 0, e_thin = 0, eps_U = 0, offset = 0, excursion = 0;
    double transient = 0;     // scaled displacement of the run from rest until its cycle
    double u_transient = 0;   // U against full at the end of that transient (both simulated through it)
    double lambda = 0;        // the field's largest growth rate at q0 (>= 0) [1/s]
    long work = 0;            // right-hand-side evaluations the estimate cost
    double growth() const;    // (e^{lambda D} - 1) / (lambda D): Gronwall's factor on the drift terms
    static constexpr double kSafety = 4;
    double part_term(PartModel p, PartModel own) const;
    double dynamics_term(Dynamics d) const;
    double predicted(PartModel p, PartModel own, Dynamics d) const { return kSafety * (part_term(p, own) + dynamics_term(d)); }
};
ModelEstimate estimate_model_errors(const Scene& scene, const Vec3& q0, double duration);

// `auto` decided up front: the first rung in cost order (reduced U, U, full; point, thin, thick
// within) whose predicted error is <= tol, run alone; with `verify` the reference is run too and
// the measured error reported. rungs holds the chosen rung (and the reference when verifying).
struct APrioriChoice {
    ModelEstimate estimate;
    Rung picked;
    double predicted = 0;   // of the picked rung
    bool verified = false;
    double measured = 0;   // with verify: the picked rung's error against the reference
    double reference_seconds = 0;
    long reference_work = 0;   // with verify: the reference's right-hand-side evaluations
    std::string explain() const;
};
APrioriChoice choose_model_a_priori(const Scene& scene, const Vec3& q0, double duration, double tol, bool verify);
// The rung alone, from an estimate: the first in cost order predicted within tol (the scene's own
// part under full dynamics when none is, or when the estimate failed). Returns its prediction.
double a_priori_pick(const Scene& scene, const ModelEstimate& estimate, double tol, PartModel& part, Dynamics& dynamics);

// `auto` for a run from rest at q0 (the command line's and Python's simulate): the rung picked from the
// estimate, not run; `scene` is the scene with its part simplified to the rung's.
struct ModelPick {
    ModelEstimate estimate;
    Rung rung;              // part and dynamics (error, seconds, work unset: not run)
    double predicted = 0;   // its predicted error [of rho and radians]
    Scene scene;
};
ModelPick pick_model(const Scene& scene, const Vec3& q0, double duration, double tol);

}   // namespace plate
