#include "plate/limit_cycle.hpp"

#include "models.hpp"

#include <cmath>
#include <sstream>

namespace plate {

std::string LimitCycleSummary::report() const {
    std::ostringstream s;
    s.precision(6);
    s << (converged ? "converged" : "NOT converged") << " after " << periods << " periods; residual "
      << residual << ", error estimate " << error_estimate << " (x v_ref), contraction " << contraction
      << " per period\n";
    s << "twist [" << twist.transpose() << "], min normal force " << min_normal_force << " N\n";
    s << "rhs evaluations " << stats.rhs_evals << ", steps " << stats.steps << " (+" << stats.rejected
      << " rejected), slip reversals " << stats.slip_reversals << "\n";
    if (stop.reason != StopReason::None) s << "stopped: " << stop.describe() << "\n";
    if (!note.empty()) s << note << "\n";
    return s.str();
}

namespace {

LimitCycleSummary one_start(const Scene& sc, const Vec3& q0, const LimitCycleOptions& opt, const Vec3& qd0) {
    detail::ReducedModel model(sc, q0);
    detail::Engine<detail::ReducedModel> e(model, sc, opt.integration);
    const double T = sc.plate.T;
    const detail::Scales sc_(sc);
    const Vec3 scale(sc_.v, sc_.v, sc_.w);

    LimitCycleSummary out;
    const Vec3 qd_init = sc.part.point ? Vec3(qd0[0], qd0[1], 0) : qd0;
    detail::ReducedModel::State y{qd_init[0], qd_init[1], qd_init[2], 0, 0, 0};
    Vec3 prev = qd_init;
    double r_prev = std::numeric_limits<double>::quiet_NaN();
    // From rest the part rides with the plate until it breaks away (simulate.hpp).
    const double t0 = qd_init.isZero() ? breakaway_time(sc, q0, 0) : 0.0;
    if (std::isnan(t0)) {
        out.stop = StopEvent{StopReason::Sticking, 0, 0};
        return out;
    }
    if (opt.record) out.path.push_back(Sample{t0, q0, qd_init, Vec3::Zero()});
    if (e.start(t0, y)) {
        if (opt.record) out.path.back().n = e.n();
        auto record = [&](double t, const auto& z, const Vec3& n) {
            if (opt.record) out.path.push_back(Sample{t, q0, model.qd(z), n});
        };
        // Periods are the windows [kT, (k+1)T]: after a breakaway at t0 > 0, first reach the
        // next period boundary, so that every cycle state (and warm start) has phase 0.
        const double t_first = t0 > 0 ? T * std::ceil(t0 / T * (1 + 1e-12)) : 0.0;
        bool ok = t0 > 0 ? e.advance(t_first, record) : true;
        if (ok) prev = model.qd(e.y());
        for (int k = 1; ok && k <= opt.max_periods; ++k) {
            e.modify([](auto& z) { z[3] = z[4] = z[5] = 0; });
            double min_n = e.n().head(sc.part.contacts()).minCoeff();
            ok = e.advance(t_first + k * T, [&](double t, const auto& z, const Vec3& n) {
                min_n = std::min(min_n, n.head(sc.part.contacts()).minCoeff());
                record(t, z, n);
            });
            out.periods = k;
            out.min_normal_force = min_n;
            if (!ok) break;
            y = e.y();
            const Vec3 qd = model.qd(y);
            out.twist = Vec3(y[3], y[4], y[5]) / T;   // (36)
            out.qd_start = prev;
            const double r = ((qd - prev).array() / scale.array()).abs().maxCoeff();
            out.residual = r;
            if (k >= 2 && r_prev > 0) {
                out.contraction = std::min(r / r_prev, 0.99);
                out.error_estimate = r * out.contraction / (1 - out.contraction);
                if (out.error_estimate <= opt.tol) {
                    out.converged = true;
                    break;
                }
            } else if (r == 0) {
                out.converged = true;
                break;
            }
            r_prev = r;
            prev = qd;
        }
    }
    out.stop = e.stop;
    out.stats = e.stats;
    if (!out.converged && out.stop.reason == StopReason::None) out.stop = StopEvent{StopReason::NotConverged, -1, e.t()};
    if (!out.converged) out.twist.setConstant(std::numeric_limits<double>::quiet_NaN());
    return out;
}


}  // namespace

LimitCycleSummary limit_cycle(const Scene& sc, const Vec3& q0, const LimitCycleOptions& opt, const Vec3& qd0) {
    if (sc.part.mu.head(sc.part.contacts()).maxCoeff() <= 0) {
        // Without friction q'' = -(p'' + omega1' x s)_xy is periodic with zero mean: every initial
        // twist is periodic and none attracts the others, so the asymptotic twist is undefined.
        LimitCycleSummary out;
        out.stop = StopEvent{StopReason::NotConverged, -1, 0};
        out.note = "frictionless part: every initial twist repeats, so there is no unique limit cycle";
        return out;
    }
    LimitCycleSummary out = one_start(sc, q0, opt, qd0);
    const double v = sc.v_ref(), w = v / sc.part.rho();
    const Vec3 kicks[] = {Vec3(v, 0, 0), Vec3(0, v, 0), Vec3(0, 0, sc.part.point ? 0 : w)};
    std::vector<StopEvent> stops;
    Stats total = out.stats;
    for (int r = 0; r < std::min(opt.restarts, 3) && out.sticking(); ++r) {
        stops.push_back(out.stop);
        out = one_start(sc, q0, opt, r == 2 && sc.part.point ? Vec3(-v, -v, 0) : kicks[r]);
        total.rhs_evals += out.stats.rhs_evals;
        total.steps += out.stats.steps;
        total.rejected += out.stats.rejected;
        total.slip_reversals += out.stats.slip_reversals;
        out.restarts = r + 1;
    }
    out.stats = total;
    out.transient_stops = stops;
    return out;
}

bool period_map(const Scene& sc, const Vec3& q0, const Vec3& qd0, Vec3& out, const IntegrationOptions& opt,
                StopEvent* stop) {
    detail::ReducedModel model(sc, q0);
    detail::Engine<detail::ReducedModel> e(model, sc, opt);
    const Vec3 qd = sc.part.point ? Vec3(qd0[0], qd0[1], 0) : qd0;
    bool ok = e.start(0, {qd[0], qd[1], qd[2], 0, 0, 0}) &&
              e.advance(sc.plate.T, [](double, const auto&, const Vec3&) {});
    if (stop) *stop = e.stop;
    if (ok) out = model.qd(e.y());
    return ok;
}

}  // namespace plate
