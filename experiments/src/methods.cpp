#include "plate/methods.hpp"
#include "plate/progress.hpp"

#include <boost/numeric/odeint.hpp>
#include <boost/numeric/odeint/stepper/rosenbrock4.hpp>
#include <boost/numeric/odeint/stepper/rosenbrock4_controller.hpp>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace plate {

namespace odeint = boost::numeric::odeint;
namespace ublas = boost::numeric::ublas;

const std::vector<MethodInfo>& all_methods() {
    static const std::vector<MethodInfo> m = {
        {Method::RK4, "odeint-rk4", 4, false, false},
        {Method::Dopri5, "odeint-dopri5", 5, true, false},
        {Method::Dopri5Dense, "odeint-dopri5-dense", 5, true, false},
        {Method::CashKarp54, "odeint-cash-karp54", 5, true, false},
        {Method::Fehlberg78, "odeint-fehlberg78", 8, true, false},
        {Method::BulirschStoer, "odeint-bulirsch-stoer", 0, true, false},
        {Method::Rosenbrock4, "odeint-rosenbrock4", 4, true, true},
        {Method::GslRkf45, "gsl-rkf45", 5, true, false},
        {Method::GslRk8pd, "gsl-rk8pd", 8, true, false},
        {Method::GslMsadams, "gsl-msadams", 0, true, false},
        {Method::GslMsbdf, "gsl-msbdf", 0, true, true},
        {Method::GslBsimp, "gsl-bsimp", 0, true, true},
    };
    return m;
}

const MethodInfo& method_info(Method m) {
    for (const auto& i : all_methods())
        if (i.method == m) return i;
    throw std::logic_error("method_info: unknown method");
}

Method parse_method(const std::string& name) {
    std::string known;
    for (const auto& i : all_methods()) {
        if (name == i.name) return i.method;
        known += (known.empty() ? "" : ", ") + std::string(i.name);
    }
    throw std::invalid_argument("unknown method '" + name + "' (expected one of: " + known + ")");
}

namespace {

using Vec = std::vector<double>;

// Evaluation counting and the budget check shared by every method.
struct Counted {
    const OdeSystem& sys;
    MethodRun& run;
    long max_evals;
    void f(double t, const double* y, double* dy) const {
        ++run.rhs_evals;
        sys.f(t, y, dy);
    }
    // Past the evaluation budget; also where a run sees a request to stop (Ctrl-C: throws Interrupted),
    // once a step, from C++ frames (never from within GSL's C code).
    bool over_budget() const {
        throw_if_stopped();
        return run.rhs_evals > max_evals;
    }
};

bool finite(const double* y, int n) {
    for (int i = 0; i < n; ++i)
        if (!std::isfinite(y[i])) return false;
    return true;
}

std::string at(const char* what, double t) {
    std::ostringstream s;
    s.precision(6);
    s << what << " at t = " << t;
    return s.str();
}

bool fail(MethodRun& run, const std::string& why) {
    run.ok = false;
    run.failure = why;
    return false;
}

// The adaptive loop for odeint's controlled steppers: try_step until t1, clamping the last step.
template <class TryStep>
bool adaptive_loop(TryStep&& try_step, const Counted& c, double t0, double t1, Vec& y, const MethodOptions& opt, MethodRun& run) {
    double t = t0;
    double dt = opt.h > 0 ? opt.h : (t1 - t0) / 1000;
    const double h_min = opt.h_min > 0 ? opt.h_min : 1e-14 * (t1 - t0);
    while (t < t1) {
        if (run.steps >= opt.max_steps) return fail(run, at("step limit", t));
        if (c.over_budget()) return fail(run, at("evaluation budget exhausted", t));
        const bool clamp = t + dt >= t1;
        double h = clamp ? t1 - t : dt;
        const double t_before = t;
        if (try_step(y, t, h)) {
            ++run.steps;
            if (clamp) t = t1;
            if (!finite(y.data(), static_cast<int>(y.size()))) return fail(run, at("non-finite state", t));
            dt = clamp ? std::max(dt, h) : h;
        } else {
            ++run.rejected;
            t = t_before;
            dt = h;
            if (dt < h_min) return fail(run, at("step-size collapse", t));
        }
    }
    return true;
}

// n equal steps of the method's own formula (no error control).
template <class Step>
bool fixed_loop(Step&& step, double t0, double t1, Vec& y, const MethodOptions& opt, MethodRun& run, const Counted& c) {
    if (!(opt.h > 0)) throw std::invalid_argument("fixed steps need h > 0");
    const long n = std::max(1L, static_cast<long>(std::ceil((t1 - t0) / opt.h - 1e-9)));
    const double h = (t1 - t0) / n;
    for (long k = 0; k < n; ++k) {
        if (c.over_budget()) return fail(run, at("evaluation budget exhausted", t0 + k * h));
        step(y, t0 + k * h, h);
        ++run.steps;
        if (!finite(y.data(), static_cast<int>(y.size()))) return fail(run, at("non-finite state", t0 + (k + 1) * h));
    }
    return true;
}

bool run_odeint(Method m, const OdeSystem& sys, double t0, double t1, Vec& y, const MethodOptions& opt, MethodRun& run) {
    const Counted c{sys, run, opt.max_evals};
    auto rhs = [&c](const Vec& x, Vec& dx, double t) {
        dx.resize(x.size());
        c.f(t, x.data(), dx.data());
    };
    const double tol = opt.tol;
    if (opt.fixed && m != Method::RK4) {
        switch (m) {
            case Method::Dopri5:
            case Method::Dopri5Dense: {
                odeint::runge_kutta_dopri5<Vec> st;
                return fixed_loop([&](Vec& x, double t, double h) { st.do_step(rhs, x, t, h); }, t0, t1, y, opt, run, c);
            }
            case Method::CashKarp54: {
                odeint::runge_kutta_cash_karp54<Vec> st;
                return fixed_loop([&](Vec& x, double t, double h) { st.do_step(rhs, x, t, h); }, t0, t1, y, opt, run, c);
            }
            case Method::Fehlberg78: {
                odeint::runge_kutta_fehlberg78<Vec> st;
                return fixed_loop([&](Vec& x, double t, double h) { st.do_step(rhs, x, t, h); }, t0, t1, y, opt, run, c);
            }
            default:
                break;   // Rosenbrock below; variable-order methods have no fixed step
        }
        if (m != Method::Rosenbrock4) throw std::invalid_argument(std::string(method_info(m).name) + " has no fixed-step form");
    }
    switch (m) {
        case Method::RK4: {
            if (!(opt.h > 0)) throw std::invalid_argument("odeint-rk4: a fixed step h > 0 is required");
            odeint::runge_kutta4<Vec> st;
            const long n = std::max(1L, static_cast<long>(std::ceil((t1 - t0) / opt.h - 1e-9)));
            const double h = (t1 - t0) / n;
            for (long k = 0; k < n; ++k) {
                if (c.over_budget()) return fail(run, at("evaluation budget exhausted", t0 + k * h));
                st.do_step(rhs, y, t0 + k * h, h);
                ++run.steps;
                if (!finite(y.data(), static_cast<int>(y.size()))) return fail(run, at("non-finite state", t0 + (k + 1) * h));
            }
            return true;
        }
        case Method::Dopri5: {
            auto st = odeint::make_controlled(tol, tol, odeint::runge_kutta_dopri5<Vec>());
            return adaptive_loop([&](Vec& x, double& t, double& h) { return st.try_step(rhs, x, t, h) == odeint::success; }, c,
                                 t0, t1, y, opt, run);
        }
        case Method::CashKarp54: {
            auto st = odeint::make_controlled(tol, tol, odeint::runge_kutta_cash_karp54<Vec>());
            return adaptive_loop([&](Vec& x, double& t, double& h) { return st.try_step(rhs, x, t, h) == odeint::success; }, c,
                                 t0, t1, y, opt, run);
        }
        case Method::Fehlberg78: {
            auto st = odeint::make_controlled(tol, tol, odeint::runge_kutta_fehlberg78<Vec>());
            return adaptive_loop([&](Vec& x, double& t, double& h) { return st.try_step(rhs, x, t, h) == odeint::success; }, c,
                                 t0, t1, y, opt, run);
        }
        case Method::BulirschStoer: {
            odeint::bulirsch_stoer<Vec> st(tol, tol);
            return adaptive_loop([&](Vec& x, double& t, double& h) { return st.try_step(rhs, x, t, h) == odeint::success; }, c,
                                 t0, t1, y, opt, run);
        }
        case Method::Dopri5Dense: {
            auto st = odeint::make_dense_output(tol, tol, odeint::runge_kutta_dopri5<Vec>());
            st.initialize(y, t0, opt.h > 0 ? opt.h : (t1 - t0) / 1000);
            const double h_min = opt.h_min > 0 ? opt.h_min : 1e-14 * (t1 - t0);
            while (st.current_time() < t1) {
                if (run.steps >= opt.max_steps) return fail(run, at("step limit", st.current_time()));
                if (c.over_budget()) return fail(run, at("evaluation budget exhausted", st.current_time()));
                const auto span = st.do_step(rhs);
                ++run.steps;
                if (span.second - span.first < h_min && span.second < t1) return fail(run, at("step-size collapse", span.first));
                if (!finite(st.current_state().data(), static_cast<int>(y.size())))
                    return fail(run, at("non-finite state", span.second));
            }
            st.calc_state(t1, y);   // interpolated: the stepper may have stepped past t1
            return true;
        }
        case Method::Rosenbrock4: {
            if (!sys.jac) return fail(run, "needs the Jacobian, none given");
            using UVec = ublas::vector<double>;
            using UMat = ublas::matrix<double>;
            const int n = sys.n;
            auto f = [&c, n](const UVec& x, UVec& dx, double t) {
                c.f(t, &x[0], &dx[0]);
                (void)n;
            };
            Vec Jbuf(static_cast<std::size_t>(n) * n), dfdt(n);
            auto jac = [&](const UVec& x, UMat& J, const double& t, UVec& dt) {
                ++run.jac_evals;
                sys.jac(t, &x[0], Jbuf.data(), dfdt.data());
                for (int i = 0; i < n; ++i) {
                    dt[i] = dfdt[i];
                    for (int j = 0; j < n; ++j) J(i, j) = Jbuf[static_cast<std::size_t>(i) * n + j];
                }
            };
            odeint::rosenbrock4_controller<odeint::rosenbrock4<double>> st(tol, tol);
            UVec x(n);
            for (int i = 0; i < n; ++i) x[i] = y[i];
            if (opt.fixed) {
                odeint::rosenbrock4<double> rb;
                UVec err(n);
                return fixed_loop(
                    [&](Vec& yy, double t, double h) {
                        rb.do_step(std::make_pair(f, jac), x, t, h, err);
                        for (int i = 0; i < n; ++i) yy[i] = x[i];
                    },
                    t0, t1, y, opt, run, c);
            }
            const bool ok = adaptive_loop(
                [&](Vec&, double& t, double& h) {
                    const bool acc = st.try_step(std::make_pair(f, jac), x, t, h) == odeint::success;
                    for (int i = 0; i < n; ++i) y[i] = x[i];
                    return acc;
                },
                c, t0, t1, y, opt, run);
            return ok;
        }
        default:
            break;
    }
    throw std::logic_error("run_odeint: not an odeint method");
}

struct GslParams {
    const Counted* c;
    const OdeSystem* sys;
    MethodRun* run;
};

int gsl_f(double t, const double y[], double f[], void* p) {
    const auto* g = static_cast<GslParams*>(p);
    g->c->f(t, y, f);
    return finite(f, g->sys->n) ? GSL_SUCCESS : GSL_EBADFUNC;
}

int gsl_jac(double t, const double y[], double* dfdy, double dfdt[], void* p) {
    const auto* g = static_cast<GslParams*>(p);
    ++g->run->jac_evals;
    g->sys->jac(t, y, dfdy, dfdt);
    return GSL_SUCCESS;
}

bool run_gsl(Method m, const OdeSystem& sys, double t0, double t1, Vec& y, const MethodOptions& opt, MethodRun& run) {
    const gsl_odeiv2_step_type* type = nullptr;
    switch (m) {
        case Method::GslRkf45:
            type = gsl_odeiv2_step_rkf45;
            break;
        case Method::GslRk8pd:
            type = gsl_odeiv2_step_rk8pd;
            break;
        case Method::GslMsadams:
            type = gsl_odeiv2_step_msadams;
            break;
        case Method::GslMsbdf:
            type = gsl_odeiv2_step_msbdf;
            break;
        case Method::GslBsimp:
            type = gsl_odeiv2_step_bsimp;
            break;
        default:
            throw std::logic_error("run_gsl: not a GSL method");
    }
    // GSL's implicit steppers call the Jacobian unconditionally (a null pointer crashes): guard it.
    if (method_info(m).needs_jacobian && !sys.jac) return fail(run, "needs the Jacobian, none given");
    gsl_set_error_handler_off();   // errors come back as status codes, never abort()
    const Counted c{sys, run, opt.max_evals};
    GslParams p{&c, &sys, &run};
    gsl_odeiv2_system s{gsl_f, sys.jac ? gsl_jac : nullptr, static_cast<size_t>(sys.n), &p};
    double t = t0, h = opt.h > 0 ? opt.h : (t1 - t0) / 1000;
    if (opt.fixed) {
        if (method_info(m).order == 0) throw std::invalid_argument(std::string(method_info(m).name) + " has no fixed-step form");
        gsl_odeiv2_step* st = gsl_odeiv2_step_alloc(type, sys.n);
        const std::unique_ptr<gsl_odeiv2_step, void (*)(gsl_odeiv2_step*)> own_step(st, gsl_odeiv2_step_free);
        std::vector<double> err(sys.n);
        const bool ok = fixed_loop(
            [&](Vec& x, double tt, double hh) {
                const int status = gsl_odeiv2_step_apply(st, tt, hh, x.data(), err.data(), nullptr, nullptr, &s);
                if (status != GSL_SUCCESS) x[0] = std::numeric_limits<double>::quiet_NaN();
            },
            t0, t1, y, opt, run, c);
        return ok;
    }
    // The multistep steppers (msadams, msbdf) need their driver object: allocate through it.
    gsl_odeiv2_driver* d = gsl_odeiv2_driver_alloc_y_new(&s, type, h, opt.tol, opt.tol);
    if (!d) return fail(run, "GSL could not allocate the driver");
    const std::unique_ptr<gsl_odeiv2_driver, void (*)(gsl_odeiv2_driver*)> own_driver(d, gsl_odeiv2_driver_free);
    const double h_min = opt.h_min > 0 ? opt.h_min : 1e-14 * (t1 - t0);
    bool ok = true;
    while (t < t1) {
        if (run.steps >= opt.max_steps) {
            ok = fail(run, at("step limit", t));
            break;
        }
        if (c.over_budget()) {
            ok = fail(run, at("evaluation budget exhausted", t));
            break;
        }
        const long fails_before = static_cast<long>(d->e->failed_steps);
        const int status = gsl_odeiv2_evolve_apply(d->e, d->c, d->s, &s, &t, t1, &h, y.data());
        run.rejected += static_cast<long>(d->e->failed_steps) - fails_before;
        if (status != GSL_SUCCESS) {
            ok = fail(run, at((std::string("GSL error: ") + gsl_strerror(status)).c_str(), t));
            break;
        }
        ++run.steps;
        if (!finite(y.data(), sys.n)) {
            ok = fail(run, at("non-finite state", t));
            break;
        }
        if (h < h_min && t < t1) {
            ok = fail(run, at("step-size collapse", t));
            break;
        }
    }
    return ok;
}

}   // namespace

bool integrate(Method m, const OdeSystem& sys, double t0, double t1, std::vector<double>& y, const MethodOptions& opt,
               MethodRun& run) {
    if (static_cast<int>(y.size()) != sys.n) throw std::invalid_argument("integrate: state size differs from the system's");
    if (!run.ok) return false;
    if (!(t1 > t0)) return true;
    try {
        switch (m) {
            case Method::GslRkf45:
            case Method::GslRk8pd:
            case Method::GslMsadams:
            case Method::GslMsbdf:
            case Method::GslBsimp:
                return run_gsl(m, sys, t0, t1, y, opt, run);
            default:
                return run_odeint(m, sys, t0, t1, y, opt, run);
        }
    } catch (const std::invalid_argument&) {
        throw;
    } catch (const std::exception& e) {
        return fail(run, std::string("exception: ") + e.what());
    }
}

}   // namespace plate
