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

#include "plate/friction.hpp"
#include "plate/model.hpp"

#include <array>
#include <cmath>
#include <memory>

namespace plate {

enum class Dynamics { Full, U, ReducedU };

// R2 (2): the part's orientation theta about z, S -> P.
inline Mat3 rot_z(double theta) {
    const double c = std::cos(theta), s = std::sin(theta);
    Mat3 R;
    R << c, -s, 0, s, c, 0, 0, 0, 1;
    return R;
}
const char* dynamics_name(Dynamics d);

// The plate's state as one evaluation sees it. R1 and omega1 enter only the full dynamics
// (the U-dynamics approximate R1 = I and drop products of x and u, Section III-G).
struct PlateState {
    Mat3 R1 = Mat3::Identity();   // (1)  P -> W
    Vec3 w1 = Vec3::Zero();       // (4)  omega1, in W
    Vec3 pdd = Vec3::Zero();      // p'', in W       (u, eq. 11)
    Vec3 wd = Vec3::Zero();       // omega1', in W   (u, eq. 11)
};

PlateState plate_state(const PlateMotion& plate, double t, Dynamics level, const Mat3& R1 = Mat3::Identity());

namespace detail {
struct WorkspaceInternals;   // numeric/src/workspace.hpp

// An owning pointer that copies what it points to (a copied workspace has its own scratch). Its
// members are instantiated where T is complete (dynamics.cpp: Workspace's special members).
template <class T>
class ValuePtr {
public:
    ValuePtr() : p_(std::make_unique<T>()) {}
    ValuePtr(const ValuePtr& o) : p_(std::make_unique<T>(*o.p_)) {}
    ValuePtr& operator=(const ValuePtr& o) {
        *p_ = *o.p_;
        return *this;
    }
    T& operator*() const { return *p_; }

private:
    std::unique_ptr<T> p_;
};
}   // namespace detail

// Workspace ("Data"): the settings and results of an evaluation, and its scratch. Preallocated; the
// evaluation itself does not allocate. A workspace serves one Scene at a time: the part's
// constants are loaded into the kernels' inputs on first use with a scene (call prepare() again
// after changing a scene in place). The scratch -- the generated kernels' inputs and cached slots,
// the factorisations, and the stick-slip state the engine sets (hints, creep) -- is numeric's own
// (numeric/src/workspace.hpp).
struct Workspace {
    Workspace();
    Workspace(const Workspace& o);
    Workspace& operator=(const Workspace& o);
    ~Workspace();

    void prepare(const Scene& scene);

    // Settings (the caller's): how a sliding contact's friction depends on its slip (friction.hpp);
    // eps in m/s.
    FrictionLaw law = FrictionLaw::Coulomb;
    double law_eps = 0;

    // Results of the last evaluation.
    Vec3 qdd = Vec3::Zero();                      // [s_x'', s_y'', theta'']
    Vec3 n = Vec3::Zero();                        // [N1, N2, N3] (point part: N1 only)
    std::array<Vec2, 3> slip = zeros<Vec2>();     // sliding velocity of each contact, P frame (text after 14)
    Vec6 b = Vec6::Zero();                        // b of the last evaluation, except on the reduced U path
    std::array<Vec2, 3> f_held = zeros<Vec2>();   // static friction of held contacts (pivot, stuck) [N], P frame
    Vec2 F_needed = Vec2::Zero();                 // stuck: the friction total that keeps the part with the plate
    double tau_needed = 0;                        // stuck: its moment about s (z)
    std::array<Vec2, 3> r = zeros<Vec2>();        // R2 c_i (horizontal) at the kernels' last theta
    Mat6 A = Mat6::Zero();                        // accelerations_reference: A of (31)
    long evals = 0;                               // number of evaluations (right-hand sides)
    int creep_iterations = 0;                     // Newton iterations of the last creep solve (diagnostics)

    // numeric's scratch (numeric/src/workspace.hpp: detail::kernels(ws), detail::stick_slip(ws)).
    detail::WorkspaceInternals& internals() { return *internals_; }
    const detail::WorkspaceInternals& internals() const { return *internals_; }

private:
    detail::ValuePtr<detail::WorkspaceInternals> internals_;
};

// Solves for q''_part and n at configuration q = (s_x, s_y, theta) and twist qd: the production
// path, on the kernels generated from the symbolic derivation (numeric/generated/): a thick part
// solves the 3x3 system left after eliminating s'' and theta'' by cofactors (a pivoted Eigen
// fixed-size LU when that system is near singular), a thin part uses (38)'s constant inverse, a
// point part the explicit solution. In the reduced U-dynamics the configuration is frozen: what
// depends on it alone is computed once per configuration (the generated reduced_U_*_config
// kernels), and an evaluation does only what the slip directions and u(t) change.
void accelerations(const Scene& scene, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& plate, Workspace& ws);

// d q''/d q' of the U- and reduced U-dynamics (32)/(35) at (q, q'): from the generated factors
// dA_du and dslip_dqd and the friction law's d u_i/d v_i (b~ does not depend on q', so
// d z/d q' = -A^-1 (dA/dq') z). Evaluates the accelerations first (ws holds them after). For the
// implicit integrators; throws std::invalid_argument for full dynamics.
void twist_jacobian(const Scene& scene, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& plate, Workspace& ws,
                    Mat3& dqdd_dqd);

// The hand-written reference implementation of the same equations (generic 6x6 Eigen solve),
// kept to check the generated kernels against.
void accelerations_reference(const Scene& scene, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& plate,
                             Workspace& ws);

// Sliding velocity of each contact: s' + omega2^ R2 c_i (horizontal; P frame).
void slip_velocities(const Part& part, const Vec3& q, const Vec3& qd, std::array<Vec2, 3>& v);
// The same in two parts, for callers that keep the offsets r_i = R2 c_i of an orientation (a point
// part's are not read).
void contact_offsets(const Part& part, double theta, std::array<Vec2, 3>& r);
void slip_velocities_at(const Part& part, const std::array<Vec2, 3>& r, const Vec3& qd, std::array<Vec2, 3>& v);

// Right-hand side b of (31)/(32) for a rigid part (exposed for tests and the kernels).
Vec6 rhs_b(const Scene& scene, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& plate);

// DERIVATION NOTES (where the printed paper differs from the derivation):
//  (28) prints -R2^T w2^ R1 w1; differentiating (27) gives -R2^T w2^ R1^T w1 (R1 transposed),
//       as (30) has it.
//  (38) third row prints g e_z^T inside a sum of column vectors; it is g e_z.
//  (33) writes s_0; in U-dynamics it is the current s (in reduced U-dynamics the frozen s_0).
//  U-dynamics drop the part's own gyroscopic term w2^ J w2 of (30) (a product of states);
//  it vanishes for J_xz = J_yz = 0: the parts of fig1, fig4-fig6 and the stick-slip scenes, not
//  fig3_random's random part (its theta'^2 (-J_yz, J_xz, 0) is then left to the full dynamics).

}   // namespace plate
