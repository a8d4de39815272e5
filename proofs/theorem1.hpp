// Numerical checks of Theorem 1 and its Appendix (Vose, Umbanhowar & Lynch): the Lyapunov
// contraction of the relative twist (C), limit surfaces (B), periodicity (D) and the
// invertibility of A (Section III-E). Every check runs on the generated kernels through the
// production dynamics, is seeded and reproducible, and returns counts, worst cases and a verdict.
#pragma once

#include "plate/limit_cycle.hpp"
#include "plate/random_scene.hpp"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace plate::proofs {

// --- The checks tied to the dynamics --------------------------------------------------------
// The contraction (C) and limit-surface (B) checks below hold for *any* Coulomb friction with
// velocity-independent normal forces >= 0: a wrong normal-force solve, a wrong b~ or a wrong mu
// passes them. These tie them to the dynamics under test, at sampled states of a thin part in the
// U-dynamics (b~ of (33)-(34) written here from the paper, not taken from the kernels):
//   statics  its normal forces equal an independent solve of the part's statics -- Euler's x, y
//            rows and Newton's z row, where for c_z = 0, J_xz = J_yz = 0 neither friction nor
//            theta'' enters: sum c_iy N_i = tau~_x, -sum c_ix N_i = tau~_y, sum N_i = f~_z
//            (Cramer's rule);
//   wrench   its friction wrench by Newton-Euler, (m s'' + f~_xy, (J_zz theta'' + tau~_z) / rho),
//            equals the limit-surface wrench (39) of its relative twist (s', rho theta'), the
//            generated thin_wrench with the statics' normal forces and the scene's mu.
// Both to rounding: 1e-10 of m g (cond(A) of these parts is below 30; measured residuals 1e-15).
using DynamicsUnderTest =
    std::function<void(const Scene&, const Vec3& q, const Vec3& qd, const PlateState& plate, Vec3& qdd, Vec3& n)>;
DynamicsUnderTest production_dynamics();   // accelerations(), U-dynamics: the kernels the program runs

struct DynamicsTie {
    int samples = 0;
    double worst_statics = 0;   // max |N - N_statics| / (m g)
    double worst_wrench = 0;    // max |W_dynamics - w(xi)| / (m g)
    std::string failure;        // the first check that failed, what and where ("" if none)
    bool passed() const { return samples > 0 && failure.empty(); }
    void merge(const DynamicsTie& o);
};
constexpr double kTieTolerance = 1e-10;
// `samples` states of the thin `scene` near q0: random twists and plate times (seeded).
DynamicsTie check_dynamics_tie(const Scene& scene, const Vec3& q0, int samples, std::uint64_t seed,
                               const DynamicsUnderTest& dynamics);

// --- C. Trajectory convergence ------------------------------------------------------------
// Two copies of a part at one configuration, from different twists, integrated together on one
// step sequence. V = 1/2 |xi_rel|^2 in the Appendix's scaled coordinates (xi_theta = rho omega).
// Between accepted steps the computed V may rise only by integration error: each copy's local
// error is at most delta = rtol (v_ref + |xi|) per component (the controller's acceptance test
// on the scaled state), so xi_rel errs by at most 2 sqrt(3) delta and V by
// bound = |xi_rel| 2 sqrt(3) delta + 6 delta^2. `worst_increase` is the largest rise divided by
// that bound: <= 1 is what Theorem 1 allows.
struct ContractionOptions {
    int cases = 100;
    std::uint64_t seed = 1;
    bool thin = true;          // thin parts (Theorem 1) or thick ones (beyond it)
    int periods = 400;         // at most; each case stops when V has fallen by 1e12 (converged)
    double rtol = 1e-10;
    int starts = 4;            // Observation 1: further initial twists whose cycles must coincide
    int threads = 0;           // 0: all cores
    // Plate motions and parts come from random_scene; override for deliberately broken cases.
    std::function<void(Scene&)> modify;
    // The dynamics the tie checks (above) hold against the paper; empty: production_dynamics().
    DynamicsUnderTest dynamics;
    int tie_samples = 10;      // per case
    std::function<void(int done, int total)> progress;   // called from workers, serialised
};

struct ContractionCase {
    std::uint64_t seed = 0;
    bool valid = false;             // stayed in the model (contact, sliding)
    std::string why_invalid;
    double V0 = 0, V_end = 0;
    double worst_increase = 0;      // largest rise of V / its error bound (<= 1 passes)
    double rate = 0;                // |xi_rel| contraction per period (geometric mean)
    double spectral_radius = 0;     // of the period map's Jacobian at the cycle (Floquet multipliers)
    bool monotone = false, converged = false;   // V never rose beyond error; V fell by 1e12
    bool unique = false;            // all `starts` initial twists reached the same cycle
    double cycle_spread = 0;        // largest distance between their cycle starts / v_ref
    int starts_left_model = 0;      // further starts whose transient stuck or lost contact (replaced)
    std::vector<double> V_periods;  // V at each period boundary
    DynamicsTie tie;                // thin parts: the dynamics tied to statics and the limit surface
};

struct ContractionSummary {
    int cases = 0, valid = 0, monotone = 0, converged = 0, floquet_below_one = 0, unique = 0;
    double seconds = 0;
    double worst_increase = 0;      // over all valid cases
    std::uint64_t worst_seed = 0;
    double median_rate = 0, max_rate = 0, max_spectral_radius = 0;
    std::vector<ContractionCase> details;
    std::vector<std::uint64_t> counterexamples;   // valid cases failing any of the checks
    DynamicsTie tie;                // over all cases (thin parts only; none for thick ones)
    bool tie_required = true;       // thin parts: the tie must have been checked and passed
    bool passed() const {
        return valid > 0 && monotone == valid && converged == valid && floquet_below_one == valid && unique == valid &&
               (!tie_required || tie.passed());
    }
};

ContractionCase contraction_case(const Scene& scene, const Vec3& q0, const Vec3& xi_a, const Vec3& xi_b,
                                 int periods, double rtol);
ContractionSummary check_contraction(const ContractionOptions& opt);
// check_contraction in pieces, for cases computed elsewhere (MPI ranks: plate proofs): case k of the
// campaign (seed opt.seed + k; opt.threads and opt.progress unused), and the summary of cases 0..n-1
// in order (what check_contraction returns for them, `seconds` its wall time).
ContractionCase contraction_random_case(const ContractionOptions& opt, int k);
ContractionSummary summarize_contraction(const ContractionOptions& opt, std::vector<ContractionCase> cases, double seconds);

// Jacobian of the period map at the cycle start (central differences) and its spectral radius.
double floquet_radius(const Scene& scene, const Vec3& q0, const Vec3& cycle_start, double rtol);

// --- B. Limit surfaces ----------------------------------------------------------------------
// A thin part's frictional wrench as a function of its relative twist (the generated kernel),
// sampled on twist directions. Checks, over all pairs (i, j):
//   maximum work  xi_i . w_j >= xi_i . w_i   (w_i minimises the power over the surface: the
//                 surface is convex and -xi_i is its outward normal at w_i),
//   (40)          (xi_i - xi_j) . (w_i - w_j) <= 0,
//   no vertices   distinct directions give distinct wrenches: the smallest |w_i - w_j| over
//                 pairs at least `separation` apart stays away from zero.
using WrenchMap = std::function<Vec3(const Vec3& xi)>;   // scaled twist -> (F_x, F_y, tau / rho)

// The two checks above hold for *any* wrench of the form -sum c_i G_i v_i/|v_i| with c_i >= 0 (by
// Cauchy-Schwarz): a wrong lever arm or mu in the kernel passes them. The friction set, built here
// independently of the kernel: contact i can push with any force f, |f| <= mu_i N_i (N_i from the
// part's statics, as in the tie above), giving the scaled wrench G_i f = (f, (r_i x f) / rho). Its
// support function h(d) is sampled on each disk's rim at `angles` points (h_s <= h <= h_s / cos(pi /
// angles)). The kernel's wrench for twist xi must be the set's support point in direction -xi
// (maximum dissipation): -xi . w(xi) >= h_s(-xi), and every wrench must lie in the set:
// -xi_i . w_j <= h_s(-xi_i) / cos(pi / angles) for all pairs.
struct FrictionSet {
    std::array<Vec2, 3> r = zeros<Vec2>();   // contacts from the centre of mass, plate frame [m]
    Vec3 cap = Vec3::Zero();   // mu_i N_i [N]
    double rho = 1;            // radius of gyration [m]
    double support_sampled(const Vec3& d, int angles) const;
};
// The thin part of `scene` at q0 and plate time t (U-dynamics, normal forces by statics).
FrictionSet thin_friction_set(const Scene& scene, const Vec3& q0, double t);

struct LimitSurfaceResult {
    int directions = 0;
    long pairs = 0;
    double max_work_violation = 0;     // max (xi_i.w_i - xi_i.w_j) / (sum mu N), <= 1e-12 passes
    double monotonicity_violation = 0; // max (xi_i - xi_j).(w_i - w_j) / (sum mu N)
    double min_separation = 0;         // min |w_i - w_j| / (sum mu N) over well-separated pairs
    double min_strict_margin = 0;      // min (xi_i.w_j - xi_i.w_i) / (sum mu N) over them: > 0, no flat faces
    // Against the independent friction set (when given): both <= 1e-12 pass.
    bool set_checked = false;
    double support_violation = 0;      // max (h_s(-xi) - (-xi . w(xi))) / (sum mu N): not the support point
    double outside_violation = 0;      // max (-xi_i . w_j - h_s(-xi_i)/cos(pi/K)) / (sum mu N): outside the set
    bool convex_and_normal() const { return max_work_violation <= 1e-12 && monotonicity_violation <= 1e-12; }
    bool strictly_convex() const { return min_strict_margin > 0 && min_separation > 0; }
    bool on_friction_set() const { return set_checked && support_violation <= 1e-12 && outside_violation <= 1e-12; }
};

LimitSurfaceResult check_limit_surface(const WrenchMap& w, double scale, int directions = 600,
                                       double separation = 0.2, const FrictionSet* set = nullptr);
// Limit surfaces of `parts` random thin parts (seeded), each at a random configuration and plate
// time, 300 directions each.
struct LimitSurfaceCampaign {
    int parts = 0, convex = 0, strict = 0, on_set = 0;
    double worst_max_work = 0, worst_monotonicity = 0, min_separation = 0, min_strict_margin = 0;
    double worst_support = 0, worst_outside = 0;   // against the independent friction set
    DynamicsTie tie;                // each part's dynamics tied to its surface (10 states each)
    bool passed() const { return parts > 0 && convex == parts && strict == parts && on_set == parts && tie.passed(); }
};
LimitSurfaceCampaign check_limit_surfaces(int parts, std::uint64_t seed, const DynamicsUnderTest& dynamics = {});

// The thin part of `scene` at configuration q0 and plate time t: its normal forces (38) and the
// generated wrench kernel.
WrenchMap thin_wrench_map(const Scene& scene, const Vec3& q0, double t, double* friction_scale = nullptr);
// The generated thin_wrench kernel on given inputs (wrench_input, dynamics.hpp) as a WrenchMap.
WrenchMap wrench_map(gen::WrenchInput in);

// --- Invertibility of A (Section III-E) -------------------------------------------------------
struct Conditioning {
    double max_condition = 0;   // of A over the sampled states
    double min_singular = 0;    // smallest singular value seen (relative to the largest)
};
Conditioning condition_of_A(const Scene& scene, int samples, std::uint64_t seed);

// A's conditioning as the third contact approaches the line of the other two: a thin part (random
// scene 3) with contacts (-L, -e L/3), (L, -e L/3), (0, 2 e L/3), L = 3 cm (centroid at s), for each
// e/L in `ratios`; 20 sampled states each. cond(A) grows like L/e.
struct CollinearScene {
    double e_over_L = 0;
    Scene scene;
};
std::vector<CollinearScene> collinear_scenes(const std::vector<double>& ratios);

}  // namespace plate::proofs
