// Stick-slip: the contact modes of three-point Coulomb contact with friction disks.
//
// THE MODE SET. Let Z be the set of contacts with zero slip v_i = s' + theta' e_z x r_i
// (r_i = R2 c_i, horizontal). A planar rigid motion relative to the plate that leaves two
// distinct points at rest is at rest (its instantaneous centre would have to be both points),
// so for three distinct coplanar contacts |Z| is 0, 1 or 3 -- never exactly 2:
//   Slide    Z empty: every contact kinetic, f_i = -mu_i N_i v_i/|v_i| (17); today's model.
//   Pivot k  Z = {k}: the part turns about contact k (s' = -theta' e_z x r_k), contact k carries
//            an unknown static friction f_k with |f_k| <= mu_k N_k, the other two slide.
//   Stuck    the relative twist is zero; the part rides the plate. The friction *distribution* is
//            statically indeterminate, but the needed total wrench (F, tau_z) is not, nor are the
//            normal forces (the tangential forces' moment about the raised centre of mass depends
//            on F alone); the mode holds while (F, tau_z) lies in the set the three friction disks
//            can supply (FrictionGauge).
// A point part has one contact: Slide or Stuck. The set is complete: every state has exactly
// one Z, and a mode change is a change of Z (located as an event by the engine).
//
// DERIVED, NOT TYPED: symbolic/derivation_parts.cpp (pivot_modes, stuck_mode) derives each mode from the same Newton-Euler
// equations as the sliding model -- the pivot's constraint by differentiating contact k's sliding
// velocity (and checks that the frozen configuration of (35) drops theta'^2 r_k), the stuck
// part's normal forces and needed wrench (and checks exactly that internal force pairs change
// nothing, so they are determinate), the support function of the friction set with its gradient
// and Hessian -- and generates the kernels pivotK_system, stuck_solve and friction_support used
// here (numeric/generated/plate_kernels.hpp).
//
// TRANSITIONS (guards; each is positive while its mode holds, events are their roots):
//   Slide -> Pivot k / Stuck   v_k reaches zero and the needed static friction lies in the disk
//                              (pivot), or every slip reaches zero and the gauge is <= 1 (stuck)
//   Pivot k -> Slide           mu_k N_k - |f_k| reaches zero: contact k breaks away in the
//                              direction opposite f_k (maximal dissipation at the disk's rim)
//   Pivot k -> Stuck/...       theta' reaches zero: every slip is zero; resolved as from rest
//   Stuck -> Slide / Pivot k   the gauge reaches 1: the needed wrench leaves the friction set at a
//                              boundary point whose friction distribution is unique; contacts at
//                              the rim slip opposite their friction, a contact inside the rim (the
//                              boundary's ruled face) is the pivot
//   any -> (stop)              a normal force reaches zero: the part would fly (Section III-F)
#pragma once

#include "plate/dynamics.hpp"

#include <array>
#include <string>

namespace plate {

enum class ModeKind { Slide = 0, Pivot = 1, Stuck = 2 };

struct Mode {
    ModeKind kind = ModeKind::Slide;
    int k = -1;         // the pivot contact (0-based), Pivot only
    double sense = 0;   // Pivot: sign of theta' while the mode holds (+1 / -1)
    bool operator==(const Mode& o) const { return kind == o.kind && k == o.k; }
    bool operator!=(const Mode& o) const { return !(*this == o); }
    // Does contact i have zero slip in this mode?
    bool holds(int i) const { return kind == ModeKind::Stuck || (kind == ModeKind::Pivot && k == i); }
};
// "slide", "pivot1", "pivot2", "pivot3", "stuck" (1-based contacts, as in messages)
std::string mode_name(const Mode& m);

// Mode-aware accelerations: fills ws.qdd and ws.n as accelerations() does, for any mode.
//   Slide   accelerations(); a contact whose slip is below hint_speed uses the unit direction hint[i]
//           (the break-away direction), since v/|v| is undefined at zero slip; a creeping contact
//           (creep, slip below creep_speed) the direction along which it accelerates,
//           solved here (Newton on its angle): the slip direction's relaxation, at a rate
//           ~ |d a/d phi| / |v| that makes explicit steps collapse as a slip grows from zero after a
//           break-away, is left out (its error is bounded by the engine, engine.hpp)
//   Pivot k Newton-Euler with contact k carrying the unknown f_k (ws.f_held[k]) and the
//           constraint that c_k does not accelerate relative to the plate:
//             s'' + theta'' e_z x r_k - kappa theta'^2 r_k = 0
//           (kappa = 1 where r_k turns with the part, U and full dynamics; kappa = 0 in the
//           reduced U-dynamics (35), whose configuration is frozen)
//   Stuck   q'' = 0; the needed friction wrench (ws.F_needed, ws.tau_needed) and the normal forces
//           (z force and x, y torques, with the friction total's moment about the raised s)
// (hint_speed, hint, creep: the stick-slip state the engine and choose_mode set in the workspace,
// numeric/src/workspace.hpp; an evaluation outside the engine has none.)
void mode_accelerations(const Scene& scene, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& plate,
                        const Mode& mode, Workspace& ws);

// Relative acceleration of contact i: d/dt v_i = s'' + theta'' e_z x r_i - kappa theta'^2 r_i.
Vec2 contact_acceleration(const Part& part, Dynamics level, int i, const Vec3& q, const Vec3& qd, const Vec3& qdd);

// The mode a state at zero slip of the contacts `zero` (a bit mask) enters, and the slip
// directions of contacts that break away (written to the workspace's hints). `qd` is projected in place onto
// zero slip of those contacts (all of them: qd = 0). Returns the new mode; `lost` is set (and
// the mode meaningless) if a normal force is negative there.
struct ModeChoice {
    Mode mode;
    bool lost = false;
    int lost_contact = -1;
    double gamma = 0;   // the gauge (zero twist) or |f_k|/(mu_k N_k) (pivot test)
};
// Clears the creep (the engine marks the contacts that break away). hold = false: the state has just left the stuck set (the
// gauge crossed 1), so break away even if the gauge is 1 to rounding.
ModeChoice choose_mode(const Scene& scene, Dynamics level, const Vec3& q, Vec3& qd, const PlateState& plate, unsigned zero,
                       Workspace& ws, bool hold = true);

// Would contact k stay stuck if its sliding velocity were zero now? The pivot mode's dynamics
// (Newton-Euler with contact k carrying an unknown tangential force F, the others sliding,
// c_k not accelerating relative to the plate), then |F| <= mu_sk N_k (friction.hpp) with every N_i >= 0. A point
// part: the stuck mode's statics.
struct StickTest {
    bool sticks = false;
    double friction_needed = 0;      // |F| [N]
    double friction_available = 0;   // mu_sk N_k [N] (stick_test_all: sum_i mu_si max(N_i, 0))
};
StickTest stick_test(const Scene& scene, Dynamics level, int k, const Vec3& q, const Vec3& qd, const PlateState& plate);

// Would the whole part stay stuck to the plate (every contact at zero slip, q'' = 0)? The needed
// frictional wrench (f_xy, tau_z) follows from b; the normal forces then follow exactly from the z
// force and the x, y torques (the friction total is known, so its moment about the raised centre of
// mass is too). The part sticks if the normal forces are >= 0 and the friction-disk gauge of that
// wrench is <= 1 (friction_gauge: exact, by duality).
StickTest stick_test_all(const Scene& scene, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& plate);

}   // namespace plate
