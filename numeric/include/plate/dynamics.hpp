// Part accelerations and normal forces in three-point kinetic Coulomb sliding contact
// (Section III). One evaluation solves A z = b, with z = [q''_part; n]:
//   Full dynamics     (31) with b = [f_dagger (19); tau_dagger (30)]
//   U-dynamics        (32) with b~ = [f~_dagger (33); tau~_dagger (34)]
//   reduced U         (35): the same system as (32) at a frozen configuration q_part0.
// Point parts: one contact at the centre of mass, no rotation (Section I, [11]).
//
// These are the hand-written reference equations. They are written from the derivation in
// the project's notes, not copied from the printed paper; see DERIVATION NOTES below.
#pragma once

#include "plate/model.hpp"

#include <array>

namespace plate {

enum class Dynamics { Full, U, ReducedU };
const char* dynamics_name(Dynamics d);

// The plate's state as one evaluation sees it. R1 and omega1 enter only the full dynamics
// (the U-dynamics approximate R1 = I and drop products of x and u, Section III-G).
struct PlateState {
    Mat3 R1 = Mat3::Identity();   // (1)  P -> W
    Vec3 w1 = Vec3::Zero();       // (4)  omega1, in W
    Vec3 pdd = Vec3::Zero();      // p'', in W       (u, eq. 11)
    Vec3 wd = Vec3::Zero();       // omega1', in W   (u, eq. 11)
};

PlateState plate_state(const PlateMotion& plate, double t, Dynamics level,
                       const Mat3& R1 = Mat3::Identity());

// Workspace ("Data"): scratch and results of the last evaluation. Preallocated; the
// evaluation itself does not allocate.
struct Workspace {
    Mat6 A = Mat6::Zero();
    Vec6 b = Vec6::Zero();
    Vec6 z = Vec6::Zero();
    Eigen::PartialPivLU<Mat6> lu{6};
    Vec3 qdd = Vec3::Zero();               // [s_x'', s_y'', theta'']
    Vec3 n = Vec3::Zero();                 // [N1, N2, N3] (point part: N1 only)
    std::array<Vec2, 3> slip{};            // sliding velocity of each contact, P frame (text after 14)
    long evals = 0;                        // number of evaluations (right-hand sides)
};

// Solves for q''_part and n at configuration q = (s_x, s_y, theta) and twist qd.
void accelerations(const Scene& scene, Dynamics level, const Vec3& q, const Vec3& qd,
                   const PlateState& plate, Workspace& ws);

// Sliding velocity of each contact: s' + omega2^ R2 c_i (horizontal; P frame).
void slip_velocities(const Part& part, const Vec3& q, const Vec3& qd, std::array<Vec2, 3>& v);

// Would contact k stay stuck if its sliding velocity were zero now? Solves Newton-Euler with
// contact k carrying an unknown tangential force F (the other contacts sliding) and the
// constraint that c_k does not accelerate relative to the plate, then tests |F| <= mu_k N_k.
struct StickTest {
    bool sticks = false;
    double friction_needed = 0;   // |F| [N]
    double friction_available = 0;  // mu_k N_k [N]
};
StickTest stick_test(const Scene& scene, Dynamics level, int k, const Vec3& q, const Vec3& qd,
                     const PlateState& plate);

// Would the whole part stay stuck to the plate (every contact at zero slip, q'' = 0)? The
// required frictional wrench (f_xy, tau_z) follows from b; the normal forces then follow
// exactly from the z force and the x, y torques (the friction total is known, so its moment
// about the raised centre of mass is too). The part sticks if that wrench lies in the set of
// wrenches the three friction disks |F_i| <= mu_i N_i can supply: tested through the set's
// support function on 2000 directions (a necessary condition, exact up to that sampling).
StickTest stick_test_all(const Scene& scene, Dynamics level, const Vec3& q, const Vec3& qd,
                         const PlateState& plate);

// Right-hand side b of (31)/(32) for a rigid part (exposed for tests and the kernels).
Vec6 rhs_b(const Scene& scene, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& plate);

// DERIVATION NOTES (where the printed paper differs from the derivation):
//  (28) prints -R2^T w2^ R1 w1; differentiating (27) gives -R2^T w2^ R1^T w1 (R1 transposed),
//       as (30) has it.
//  (38) third row prints g e_z^T inside a sum of column vectors; it is g e_z.
//  (33) writes s_0; in U-dynamics it is the current s (in reduced U-dynamics the frozen s_0).
//  U-dynamics drop the part's own gyroscopic term w2^ J w2 of (30) (a product of states);
//  it vanishes for J_xz = J_yz = 0, so for every part of the paper.

}  // namespace plate
