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
        case StopReason::EventAccumulation: return "event_accumulation";
    }
    return "?";
}

std::string StopEvent::describe() const {
    std::ostringstream s;
    s.precision(9);
    switch (reason) {
        case StopReason::None: return "no stop";
        case StopReason::ContactLost:
            s << "contact " << contact + 1 << " lost (normal force reaches zero: the part would fly) at t = " << t << " s";
            break;
        case StopReason::Sticking:
            s << "contact " << contact + 1 << " sticks (zero slip, static friction holds) at t = " << t << " s";
            break;
        case StopReason::StepCollapse:
            s << "step size collapsed at t = " << t << " s (the method cannot resolve the motion)";
            break;
        case StopReason::StepLimit: s << "work budget (steps or right-hand sides) spent at t = " << t << " s"; break;
        case StopReason::NotConverged: s << "limit cycle not converged within the period cap"; break;
        case StopReason::EventAccumulation:
            s << "contact modes change without end at t = " << t << " s (an accumulation point of events)";
            break;
    }
    return s.str();
}

namespace {

// The first time the engine, started at rest at t0, leaves the stuck mode (t0 if it is not stuck
// there; NaN if it stays stuck for a period or contact is lost).
template <class Model>
double first_release(Model& model, const Scene& sc, const typename Model::State& y0, double t0) {
    IntegrationOptions o;
    o.rtol = 1e-10;
    detail::Engine<Model> e(model, sc, o);
    if (!e.start(t0, y0)) return std::numeric_limits<double>::quiet_NaN();
    if (e.mode().kind != ModeKind::Stuck) return t0;
    double tb = std::numeric_limits<double>::quiet_NaN();
    e.advance(t0 + sc.plate.T, [&](double t, const auto&, const Vec3&) {
        if (std::isnan(tb) && e.mode().kind != ModeKind::Stuck) tb = t;
    });
    return tb;
}

}  // namespace

double breakaway_time(const Scene& sc, const Vec3& q0, double t0, Dynamics level) {
    if (level == Dynamics::Full) {
        detail::FullModel m(sc);
        Vec3 p, phi;
        sc.plate.displacement(t0, p, phi);
        return first_release(m, sc, {q0[0], q0[1], q0[2], 0, 0, 0, phi[0], phi[1], phi[2]}, t0);
    }
    if (level == Dynamics::ReducedU) {
        detail::ReducedModel m(sc, q0);
        return first_release(m, sc, {0, 0, 0, 0, 0, 0}, t0);
    }
    detail::UModel m(sc);
    return first_release(m, sc, {q0[0], q0[1], q0[2], 0, 0, 0}, t0);
}

namespace {

template <class Model>
Trajectory run(Model& model, const Scene& sc, const typename Model::State& y0, double duration, double sample_dt,
               const IntegrationOptions& opt) {
    detail::Engine<Model> e(model, sc, opt);
    Trajectory tr;
    auto push = [&](double t, const typename Model::State& y, const Vec3& n) {
        tr.samples.push_back(Sample{t, model.q(y), model.qd(y), n, e.mode()});
    };
    const long count = static_cast<long>(std::ceil(duration / sample_dt - 1e-9));
    if (e.start(0, y0)) {
        push(0, e.y(), e.n());
        for (long k = 1; k <= count; ++k) {
            if (!e.advance(std::min(k * sample_dt, duration), [](double, const auto&, const Vec3&) {})) break;
            push(e.t(), e.y(), e.n());
        }
    }
    if (e.stop.reason != StopReason::None && (tr.samples.empty() || tr.samples.back().t < e.t()))
        push(e.t(), e.y(), e.n());
    tr.stop = e.stop;
    tr.stats = e.stats;
    tr.events = e.events;
    tr.held_time = e.held_time;
    return tr;
}

}  // namespace

Trajectory simulate(const Scene& sc, Dynamics level, const Vec3& q0, const Vec3& qd0, double duration,
                    double sample_dt, const IntegrationOptions& opt) {
    if (level == Dynamics::ReducedU)
        throw std::invalid_argument("simulate: reduced U-dynamics have no trajectory; use limit_cycle");
    if (!(duration > 0 && sample_dt > 0)) throw std::invalid_argument("simulate: duration and sample_dt must be > 0");
    if (level == Dynamics::Full) {
        detail::FullModel m(sc);
        Vec3 p, phi;
        sc.plate.displacement(0.0, p, phi);   // R1 at the start
        return run(m, sc, {q0[0], q0[1], q0[2], qd0[0], qd0[1], qd0[2], phi[0], phi[1], phi[2]}, duration, sample_dt,
                   opt);
    }
    detail::UModel m(sc);
    return run(m, sc, {q0[0], q0[1], q0[2], qd0[0], qd0[1], qd0[2]}, duration, sample_dt, opt);
}

}  // namespace plate
