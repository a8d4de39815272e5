// An independent nonsmooth reference for the engine's stick-slip (issue 14, point 6, the optional
// second reference): Moreau-Jean time stepping of the U-dynamics, each step's frictional contact
// problem solved by Siconos' fc3d solver (Debian libsiconos-numerics-dev). Built only where Siconos
// is found (the target plate_siconos); nothing else depends on it.
//
// It shares none of the engine's equations (only its inputs: the Scene, u(t) from PlateMotion). The
// part is a free rigid body (point part: a particle) in the plate's frame, written from Newton-Euler
// alone: in the U-dynamics the frame is level (R1 = I) and its angular velocity is dropped (products
// of x and u, Section III-G), so the frame's motion enters as the fictitious force
// -m (p'' + omega1' x x) with x the centre of mass (the frame's origin at the plate's) and, the
// fictitious forces being spread over the body, the torque -J omega1' about x; gravity -m g e_z. The
// part's own gyroscopic term -w x J w is kept, which the engine's U-dynamics drop (dynamics.hpp,
// DERIVATION NOTES): the two are the same model where J_xz = J_yz = 0, as for the scenes the tests use.
// The contacts are three unilateral points with Coulomb cones (Siconos' local frames: normal e_z,
// tangents e_x, e_y; the disk, not a pyramid), the plate's points at rest in its frame. Per step h:
//   V+ = V + h M^-1 F(t + h/2, x, R) + M^-1 H^T P,   U = H V+,  (P, U) Coulomb (De Saxce's cone
//   complementarity, Siconos' FrictionContactProblem with W = H M^-1 H^T, q = H V_free),
//   x += h v+,  R = exp(h w+) R,
// so each step is one contact solve, no events: sticking, pivoting and sliding are all the solver's
// answer, with no mode logic of ours. The scheme is first order; where a stick starts or ends inside
// a step its error's size and sign jump from one h to the next (tests/test_siconos.cpp).
// Three contacts give nine impulses against six velocities: a stuck part's friction distribution is
// indeterminate (as in the engine's gauge, friction.hpp), its velocities are not.
#pragma once

#include "plate/model.hpp"

namespace plate {

struct MoreauJeanOptions {
    long steps_per_period = 4000;   // h = T / steps_per_period
    double solver_tol = 1e-13;      // fc3d's error criterion (Siconos' NSGS, relative)
    int max_iterations = 100000;    // NSGS sweeps per step
};

struct MoreauJeanSummary {
    Vec3 q = Vec3::Zero();    // (s_x, s_y, theta) at the end; theta continuous from q0
    Vec3 qd = Vec3::Zero();   // (s_x', s_y', theta') at the end
    long steps = 0;
    double mean_iterations = 0;   // NSGS sweeps per step
    long solver_failures = 0;     // steps whose solve did not reach solver_tol
    double max_residual = 0;      // the largest final error of a step's solve (Siconos' natural-map residual
                                  // over max(|q|, |r|, |u|))
    double max_gap = 0;           // largest height of a contact above the plate [m] (lift-off)
};

// The part at rest relative to the plate at q0 at t = 0, for `duration` seconds.
// Throws std::invalid_argument for a non-positive duration or step count.
MoreauJeanSummary moreau_jean_u(const Scene& scene, const Vec3& q0, double duration, const MoreauJeanOptions& opt = {});

}   // namespace plate
