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
    double error = 0;      // final-configuration error against the most complete model:
                           // max(|ds| / rho, |dtheta| [rad]); a point part's theta stays at theta0
    double seconds = 0;    // its cost
    bool ok = false;       // it ran to the end (no stop)
    std::string note;      // why not ok
    std::string name() const;   // e.g. "thin / u"
};

struct ModelChoice {
    double tol = 0;
    Rung picked;               // the cheapest with error <= tol (the reference itself if none)
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

}  // namespace plate
