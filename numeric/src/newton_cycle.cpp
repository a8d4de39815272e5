// The Newton cycle solver (limit_cycle.hpp, CycleSolver::Newton) with GSL's multiroot solver. The
// web build (web/CMakeLists.txt) leaves GSL out and compiles newton_cycle_web.cpp instead
// (docs/decisions/web.md).
#include "cycle_solvers.hpp"
#include "models.hpp"
#include "plate/progress.hpp"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_multiroots.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace plate::detail {
namespace {

// Newton shooting on G(x) = (P(x) - x)/scale = 0 with GSL's gnewton (a Newton step with a
// backtracking guard) and a finite-difference monodromy.
struct NewtonData {
    const Scene* sc;
    Vec3 q0, scale;
    IntegrationOptions io;
    Stats stats;
    StopEvent stop;
    bool failed = false;
    bool interrupted = false;
    int periods = 0;
};

int newton_f(const gsl_vector* xs, void* p, gsl_vector* f) {
    auto* d = static_cast<NewtonData*>(p);
    const Vec3 x = Vec3(gsl_vector_get(xs, 0), gsl_vector_get(xs, 1), gsl_vector_get(xs, 2)).cwiseProduct(d->scale);
    PeriodResult r;
    try {   // (no C++ exception through GSL's C: a request to stop ends the solve, rethrown after it)
        r = one_period(*d->sc, d->q0, x, d->io, d->stats);
    } catch (const Interrupted&) {
        d->interrupted = true;
        return GSL_EBADFUNC;
    }
    ++d->periods;
    if (!r.ok) {
        d->failed = true;
        d->stop = r.stop;
        return GSL_EBADFUNC;
    }
    const Vec3 g = (r.end - x).cwiseQuotient(d->scale);
    for (int i = 0; i < 3; ++i) gsl_vector_set(f, i, g[i]);
    return GSL_SUCCESS;
}

int newton_df(const gsl_vector* xs, void* p, gsl_matrix* J) {
    auto* d = static_cast<NewtonData*>(p);
    gsl_vector* f0 = gsl_vector_alloc(3);
    gsl_vector* f1 = gsl_vector_alloc(3);
    gsl_vector* x1 = gsl_vector_alloc(3);
    int status = newton_f(xs, p, f0);
    // The difference step must stand far above the period map's own integration error (~rtol):
    // 1e-5 of the scale at rtol 1e-8, larger for looser tolerances.
    const double h = std::max(1e-5, 1e3 * d->io.rtol);
    for (int j = 0; j < 3 && status == GSL_SUCCESS; ++j) {
        gsl_vector_memcpy(x1, xs);
        gsl_vector_set(x1, j, gsl_vector_get(xs, j) + h);
        status = newton_f(x1, p, f1);
        for (int i = 0; i < 3 && status == GSL_SUCCESS; ++i)
            gsl_matrix_set(J, i, j, (gsl_vector_get(f1, i) - gsl_vector_get(f0, i)) / h);
    }
    if (d->sc->part.point && status == GSL_SUCCESS) {   // no rotation: keep the matrix regular
        for (int i = 0; i < 3; ++i) gsl_matrix_set(J, 2, i, i == 2 ? -1.0 : 0.0);
    }
    gsl_vector_free(f0);
    gsl_vector_free(f1);
    gsl_vector_free(x1);
    return status;
}

int newton_fdf(const gsl_vector* x, void* p, gsl_vector* f, gsl_matrix* J) {
    const int s = newton_f(x, p, f);
    return s == GSL_SUCCESS ? newton_df(x, p, J) : s;
}

}   // namespace

LimitCycleSummary newton_cycle(const Scene& sc, const Vec3& q0, const LimitCycleOptions& opt, const Vec3& qd0) {
    gsl_set_error_handler_off();
    const Scales sc_(sc);
    NewtonData d{&sc, q0, Vec3(sc_.v, sc_.v, sc_.w), opt.integration, {}, {}, false, false, 0};
    gsl_multiroot_function_fdf fdf{newton_f, newton_df, newton_fdf, 3, &d};
    gsl_vector* x = gsl_vector_alloc(3);
    const Vec3 x0 = qd0.cwiseQuotient(d.scale);
    for (int i = 0; i < 3; ++i) gsl_vector_set(x, i, x0[i]);
    gsl_multiroot_fdfsolver* s = gsl_multiroot_fdfsolver_alloc(gsl_multiroot_fdfsolver_gnewton, 3);
    LimitCycleSummary out;
    int status = gsl_multiroot_fdfsolver_set(s, &fdf, x);
    double step = std::numeric_limits<double>::infinity();
    for (int it = 0; status == GSL_SUCCESS && d.periods < opt.max_periods; ++it) {
        status = gsl_multiroot_fdfsolver_iterate(s);
        if (status != GSL_SUCCESS) break;
        step = 0;
        for (int i = 0; i < 3; ++i) step = std::max(step, std::abs(gsl_vector_get(s->dx, i)));
        // The Newton step estimates the distance to the fixed point (quadratic convergence).
        if (step <= opt.tol) break;
    }
    const Vec3 xs = Vec3(gsl_vector_get(s->x, 0), gsl_vector_get(s->x, 1), gsl_vector_get(s->x, 2)).cwiseProduct(d.scale);
    gsl_multiroot_fdfsolver_free(s);
    gsl_vector_free(x);
    if (d.interrupted) throw Interrupted();
    out.periods = d.periods;
    if (!d.failed && step <= opt.tol) {
        const PeriodResult r = one_period(sc, q0, xs, opt.integration, d.stats);
        ++out.periods;
        // A Newton step below tol is not enough when the map is noisy (loose rtol): the residual
        // |P(x) - x| must be small too (it is (1 - lambda) times the distance at a true fixed point).
        const double res = ((r.end - xs).array() / d.scale.array()).abs().maxCoeff();
        if (r.ok && res > 10 * opt.tol) {
            out.stop = StopEvent{StopReason::NotConverged, -1, 0};
            out.residual = res;
        } else if (r.ok) {
            out.converged = true;
            out.twist = r.average;
            out.qd_start = xs;
            out.residual = ((r.end - xs).array() / d.scale.array()).abs().maxCoeff();
            out.error_estimate = step;
            out.min_normal_force = r.min_n;
        } else {
            out.stop = r.stop;
        }
    } else if (d.failed) {
        out.stop = d.stop;
    }
    out.stats = d.stats;
    if (!out.converged && out.stop.reason == StopReason::None) out.stop = StopEvent{StopReason::NotConverged, -1, 0};
    return out;
}

}   // namespace plate::detail
