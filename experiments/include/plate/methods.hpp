// Integration methods behind one interface, for the speed-accuracy study (work-precision
// charts, failure maps). Each method integrates a general system y' = f(t, y) from t0 to t1
// and reports its cost (right-hand sides, Jacobians, steps) and, instead of throwing or
// hanging, why it failed: step-size collapse, step or evaluation budget exhausted, a
// non-finite state, or the library's own error.
//
// The simulator's own engine (Dormand-Prince 5(4) with located contact events, simulate.hpp)
// is not one of these: it is the event-located treatment the study compares them against.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace plate {

enum class Method {
    RK4,             // odeint runge_kutta4, fixed step
    Dopri5,          // odeint controlled runge_kutta_dopri5
    Dopri5Dense,     // odeint dense-output runge_kutta_dopri5 (steps past t1, interpolates)
    CashKarp54,      // odeint controlled runge_kutta_cash_karp54
    Fehlberg78,      // odeint controlled runge_kutta_fehlberg78
    BulirschStoer,   // odeint bulirsch_stoer (extrapolation)
    Rosenbrock4,     // odeint rosenbrock4 (linearly implicit, needs the Jacobian)
    GslRkf45,        // GSL odeiv2 rkf45
    GslRk8pd,        // GSL odeiv2 rk8pd (Prince-Dormand 8(9))
    GslMsadams,      // GSL odeiv2 msadams (variable-order Adams)
    GslMsbdf,        // GSL odeiv2 msbdf (variable-order BDF, needs the Jacobian)
    GslBsimp,        // GSL odeiv2 bsimp (implicit Bulirsch-Stoer, needs the Jacobian)
};

struct MethodInfo {
    Method method;
    const char* name;   // e.g. "odeint-dopri5"
    int order;          // convergence order of one fixed step on smooth problems; 0: variable order
                        // (extrapolation, multistep), no fixed-step form
    bool adaptive;
    bool needs_jacobian;
};
const std::vector<MethodInfo>& all_methods();
const MethodInfo& method_info(Method m);
// Throws std::invalid_argument listing the names on an unknown one.
Method parse_method(const std::string& name);

// y' = f(t, y), n components; jac (row-major n x n dfdy and dfdt) is required by the methods
// that need it (MethodInfo::needs_jacobian) and refused with a clear failure if missing.
struct OdeSystem {
    int n = 0;
    std::function<void(double t, const double* y, double* f)> f;
    std::function<void(double t, const double* y, double* dfdy, double* dfdt)> jac;
};

struct MethodOptions {
    double tol = 1e-8;   // adaptive: absolute and relative tolerance (scale the state to O(1))
    double h = 0;        // fixed-step methods: the step; adaptive: first step (0: (t1-t0)/1000)
    double h_min = 0;    // adaptive: a step below this is a failure (0: 1e-14 (t1 - t0))
    long max_steps = 5'000'000;
    long max_evals = 50'000'000;   // right-hand sides, then a failure (never hangs)
    bool fixed = false;            // steps of exactly h with the method's own formula, no error control
                                   // (for convergence-order tests; only methods with order > 0)
};

struct MethodRun {
    bool ok = true;
    std::string failure;   // empty when ok: "step-size collapse at t = ...", ...
    long rhs_evals = 0;
    long jac_evals = 0;
    long steps = 0;
    long rejected = 0;
};

// Integrates y (in/out, n values) from t0 to t1 exactly. `run` accumulates (several calls add up).
// Returns run.ok.
bool integrate(Method m, const OdeSystem& sys, double t0, double t1, std::vector<double>& y, const MethodOptions& opt,
               MethodRun& run);

}   // namespace plate
