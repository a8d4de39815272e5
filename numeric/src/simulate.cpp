#include "plate/simulate.hpp"

#include "models.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace plate {

const char* stop_name(StopReason r) {
    switch (r) {
        case StopReason::None: return "none";
        case StopReason::ContactLost: return "contact_lost";
        case StopReason::Sticking: return "sticking";
        case StopReason::StepCollapse: return "step_collapse";
        case StopReason::StepLimit: return "step_limit";
        case StopReason::NotConverged: return "not_converged";
    }
    return "?";
}

std::string StopEvent::describe() const {
    std::ostringstream s;
    s.precision(9);
    switch (reason) {
        case StopReason::None: return "no stop";
        case StopReason::ContactLost:
            s << "contact " << contact + 1 << " lost (normal force negative) at t = " << t << " s";
            break;
        case StopReason::Sticking:
            s << "contact " << contact + 1 << " sticks (zero slip, static friction holds) at t = " << t << " s";
            break;
        case StopReason::StepCollapse:
            s << "step size collapsed at t = " << t << " s (the method cannot resolve the motion)";
            break;
        case StopReason::StepLimit: s << "step limit reached at t = " << t << " s"; break;
        case StopReason::NotConverged: s << "limit cycle not converged within the period cap"; break;
    }
    return s.str();
}

double breakaway_time(const Scene& sc, const Vec3& q0, double t0) {
    auto holds = [&](double t) {   // friction can carry the part with the plate at time t
        return stick_test_all(sc, Dynamics::U, q0, Vec3::Zero(), plate_state(sc.plate, t, Dynamics::U)).sticks;
    };
    const double T = sc.plate.T;
    const int n = 1024;
    if (!holds(t0)) return t0;
    double ta = t0;
    for (int i = 1; i <= n; ++i) {
        double tb = t0 + T * i / n;
        if (!holds(tb)) {
            for (int it = 0; it < 200 && tb - ta > 1e-15 * T; ++it) {
                const double tm = 0.5 * (ta + tb);
                if (holds(tm)) ta = tm; else tb = tm;
            }
            return tb;
        }
        ta = tb;
    }
    return std::numeric_limits<double>::quiet_NaN();
}

namespace {

// Integrates from t_start (the part rides with the plate before it) with samples every
// sample_dt from t = 0.
template <class Model>
Trajectory run(Model& model, const Scene& sc, typename Model::State y0, double t_start, double duration,
               double sample_dt, const IntegrationOptions& opt) {
    detail::Engine<Model> e(model, sc, opt);
    Trajectory tr;
    auto push = [&](double t, const typename Model::State& y, const Vec3& n) {
        tr.samples.push_back(Sample{t, model.q(y), model.qd(y), n});
    };
    const long count = static_cast<long>(std::ceil(duration / sample_dt - 1e-9));
    long k = 0;
    if (!(t_start < duration)) {
        // Stuck for a whole period (or the whole run): the sliding model does not apply.
        push(0, y0, Vec3::Constant(std::numeric_limits<double>::quiet_NaN()));
        e.stop = StopEvent{StopReason::Sticking, 0, 0};
        tr.stop = e.stop;
        return tr;
    }
    for (; k <= count && k * sample_dt < t_start; ++k)   // riding with the plate
        push(k * sample_dt, y0, Vec3::Constant(std::numeric_limits<double>::quiet_NaN()));
    if (e.start(t_start, y0)) {
        if (k == 0 || t_start > 0) push(t_start, y0, e.n());
        for (; k <= count; ++k) {
            const double tk = std::min(k * sample_dt, duration);
            if (tk <= t_start) continue;
            if (!e.advance(tk, [](double, const auto&, const Vec3&) {})) break;
            push(e.t(), e.y(), e.n());
        }
        if (e.stop.reason != StopReason::None && tr.samples.back().t < e.t()) push(e.t(), e.y(), e.n());
    }
    tr.stop = e.stop;
    tr.stats = e.stats;
    return tr;
}

}  // namespace

Trajectory simulate(const Scene& sc, Dynamics level, const Vec3& q0, const Vec3& qd0, double duration,
                    double sample_dt, const IntegrationOptions& opt) {
    if (level == Dynamics::ReducedU)
        throw std::invalid_argument("simulate: reduced U-dynamics have no trajectory; use limit_cycle");
    if (!(duration > 0 && sample_dt > 0)) throw std::invalid_argument("simulate: duration and sample_dt must be > 0");
    double t_start = 0;
    if (qd0.isZero()) {
        t_start = breakaway_time(sc, q0, 0);
        if (std::isnan(t_start)) t_start = std::numeric_limits<double>::infinity();
    }
    if (level == Dynamics::Full) {
        detail::FullModel m(sc);
        Vec3 p, phi;
        sc.plate.displacement(std::isfinite(t_start) ? t_start : 0.0, p, phi);   // R1 at the start
        detail::FullModel::State y0{q0[0], q0[1], q0[2], qd0[0], qd0[1], qd0[2], phi[0], phi[1], phi[2]};
        return run(m, sc, y0, t_start, duration, sample_dt, opt);
    }
    detail::UModel m(sc);
    detail::UModel::State y0{q0[0], q0[1], q0[2], qd0[0], qd0[1], qd0[2]};
    return run(m, sc, y0, t_start, duration, sample_dt, opt);
}

}  // namespace plate
