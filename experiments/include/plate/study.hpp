// The speed-accuracy study: the plate's questions answered by every integration method and
// friction treatment, against reference solutions, so that cost can be charted against error
// (work-precision), failures located (failure maps), and the limit-cycle solvers compared.
// `plate bench` runs it and writes the charts into the verification report.
#pragma once

#include "plate/dynamics.hpp"
#include "plate/limit_cycle.hpp"
#include "plate/methods.hpp"

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace plate {

// One way of integrating: the project's engine (Dormand-Prince 5(4) with contact events located
// by bisection on re-stepped steps, simulate.hpp) or a general method with a friction law.
struct Solver {
    bool engine = false;
    Method method = Method::Dopri5;
    FrictionLaw law = FrictionLaw::Coulomb;
    double law_eps = 1e-3;       // regularisation width, relative to Scene::v_ref()
    std::string label() const;   // e.g. "engine: dopri5 + events", "gsl-rk8pd / tanh 1e-3"
};

// The solvers of the study: every method with exact Coulomb friction, the engine, and
// regularised laws on dopri5 (quick) or on several methods (full).
std::vector<Solver> study_solvers(bool full);
// Accuracy settings swept per solver: tolerances (adaptive) or steps per period (RK4).
std::vector<double> study_knobs(const Solver& s, bool full);

struct RunResult {
    bool ok = false;
    std::string failure;   // why not ok: the method's own failure, a model stop, "wrong answer"
    double knob = 0;       // tolerance, or steps per period
    long rhs_evals = 0;
    long jac_evals = 0;
    double seconds = 0;
    std::vector<double> value;   // the answer: a twist (3) or samples of q (3 per sample)
    double error = 0;            // against the reference (filled by the caller)
    double error_max = 0;        // trajectories: largest error along the path
};

// (a), (c): the asymptotic twist (36) at q0, reduced U-dynamics, period by period from rest until
// the cycle's error estimate is below cycle_tol (relative to v_ref).
RunResult twist_run(const Scene& scene, const Vec3& q0, const Solver& s, double knob, double cycle_tol,
                    long max_evals = 20'000'000);

// (b): a full-dynamics trajectory from rest at q0 for `duration` s, q sampled every sample_dt
// from the breakaway time (all solvers start there, from the same state).
RunResult trajectory_run(const Scene& scene, const Vec3& q0, double duration, double sample_dt, const Solver& s, double knob,
                         long max_evals = 50'000'000);

// Errors: twists relative to (v_ref, v_ref, v_ref / rho); configurations relative to (rho, rho, 1 rad).
double twist_error(const Scene& scene, const std::vector<double>& a, const std::vector<double>& b);
// Largest twist error of a field against a reference field on the same grid, over the points where
// the reference converged; `missing` (if given) counts those where `f` did not.
struct Field;
double field_max_error(const Scene& scene, const Field& f, const Field& ref, int* missing = nullptr);
// Final-sample and largest-over-samples configuration error.
void path_error(const Scene& scene, const std::vector<double>& a, const std::vector<double>& b, double& final_error,
                double& max_error);

// THE REGULARISED-FRICTION REFERENCE for stick-slip: the asymptotic twist with Coulomb's law
// replaced by f = -mu N v / sqrt(|v|^2 + eps^2) (FrictionLaw::Sqrt), which has no stick, no modes
// and no events, integrated by GSL's implicit Bulirsch-Stoer (bsimp, with the generated Jacobian:
// the regularised law is stiff, rate ~ mu g / eps) to `tol`, its cycle found period by period from
// rest (each eps then from the previous eps's cycle) -- nothing of the engine is used. As eps -> 0
// the twist tends to Coulomb's; near a break-away the error shrinks more slowly than eps, so the
// order is *observed* from the last three eps (a geometric sequence of ratio r): with differences
// d1 = x(e1) - x(e2), d2 = x(e2) - x(e3), p = log(|d1| / |d2|) / log r, and the limit is
// x(e3) - d2 / (r^p - 1) (Richardson). `error` is that correction's size plus the change of the
// limit from the previous triple: what the reference itself is worth.
struct RegularisedOptions {
    std::vector<double> eps{1e-5, 1e-6, 1e-7, 1e-8};   // relative to Scene::v_ref(), decreasing geometrically
    double tol = 1e-12;                                // bsimp, on the state scaled by (v_ref, v_ref, v_ref / rho)
    double cycle_tol = 1e-11;                          // the cycle's error estimate, relative to v_ref
    int max_periods = 400;
};
struct RegularisedReference {
    bool ok = false;
    std::string failure;
    std::vector<Vec3> twists;                                                // per eps [m/s, m/s, rad/s]
    std::vector<int> periods;                                                // per eps
    double order = 0;                                                        // observed p
    Vec3 twist = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());   // extrapolated to eps = 0
    double error = 0;   // relative to (v_ref, v_ref, v_ref / rho), max over components
    long rhs_evals = 0;
    double seconds = 0;
};
RegularisedReference regularised_reference(const Scene& scene, const Vec3& q0, const RegularisedOptions& opt = {});

// STICK-SLIP ON SCENES NOBODY TUNED: seeded random scenes (random_scene's thick, thin and point parts
// and six-axis motions, seed % 3 picking the kind) made to stick -- the x and y harmonics rescaled so
// that the largest amplitude among them is `ratio` mu g, ratio uniform in [0.05, 1.2] (the tilts and
// the twist about z stay random_scene's), the heave multiplied by a factor uniform in [0.5, 2.5] --
// each at one random configuration within 3 cm of the centre (random_scene keeps contact there). The
// engine's asymptotic twist (limit_cycle with `opt`) against the regularised-friction limit there.
// (The reference shares the sliding kernels with the engine -- those are tested against the
// hand-written Newton-Euler solve -- and nothing of the modes, events, gauge or creep.)
Scene sticking_random_scene(std::uint64_t seed, Vec3& q0, double* ratio = nullptr);
struct RandomStickCase {
    std::uint64_t seed = 0;
    Scene scene;
    Vec3 q0 = Vec3::Zero();
    double ratio = 0;          // the largest x, y harmonic amplitude / (mu g)
    LimitCycleSummary cycle;   // the engine's
    bool reference_ok = false;
    std::string failure;   // why not (either)
    double held = 0;       // largest stick fraction of a contact over the engine's cycle
    Vec3 reference_twist = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
    double error = 0;             // |engine - reference|, relative to (v_ref, v_ref, v_ref / rho)
    double reference_error = 0;   // the reference's own
    bool converged() const { return cycle.converged; }
};
RandomStickCase random_stick_case(std::uint64_t seed, const LimitCycleOptions& opt = {}, const RegularisedOptions& ref = {});

// The OdeSystem of the reduced U-dynamics at q0 in scaled coordinates, y = [q'/v, Q/(v T)], with
// the generated Jacobian (twist_jacobian); exposed for tests of the methods.
OdeSystem reduced_system(const Scene& scene, const Vec3& q0, FrictionLaw law, double law_eps_abs, std::vector<double>& scale);

}   // namespace plate
