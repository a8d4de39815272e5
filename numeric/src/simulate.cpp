#include "plate/simulate.hpp"

#include "engine.hpp"
#include "models.hpp"

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace plate {

const char* stop_name(StopReason r) {
    switch (r) {
        case StopReason::None:
            return "none";
        case StopReason::ContactLost:
            return "contact_lost";
        case StopReason::Sticking:
            return "sticking";
        case StopReason::StepCollapse:
            return "step_collapse";
        case StopReason::StepLimit:
            return "step_limit";
        case StopReason::NotConverged:
            return "not_converged";
        case StopReason::EventAccumulation:
            return "event_accumulation";
    }
    return "?";
}

std::string StopEvent::describe() const {
    std::ostringstream s;
    s.precision(9);
    switch (reason) {
        case StopReason::None:
            return "no stop";
        case StopReason::ContactLost:
            s << "contact " << contact + 1 << " lost (normal force reaches zero: the part would fly) at t = " << t << " s";
            break;
        case StopReason::Sticking:
            s << "contact " << contact + 1 << " sticks (zero slip, static friction holds) at t = " << t << " s";
            break;
        case StopReason::StepCollapse:
            s << "step size collapsed at t = " << t << " s (the method cannot resolve the motion)";
            break;
        case StopReason::StepLimit:
            s << "work budget (steps or right-hand sides) spent at t = " << t << " s";
            break;
        case StopReason::NotConverged:
            s << "limit cycle not converged within the period cap";
            break;
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

}   // namespace

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

// Runs the engine from y0 at t = 0 and samples it at time_at(k), k = first..last (increasing, the
// engine stepping to each exactly); k = 0 at time 0 is the start itself.
template <class Model, class TimeAt>
Trajectory run(Model& model, const Scene& sc, const typename Model::State& y0, long first, long last, TimeAt time_at,
               const IntegrationOptions& opt) {
    detail::Engine<Model> e(model, sc, opt);
    Trajectory tr;
    auto push = [&](double t, const typename Model::State& y, const Vec3& n) {
        tr.samples.push_back(Sample{t, model.q(y), model.qd(y), n, e.mode()});
    };
    if (e.start(0, y0)) {
        for (long k = first; k <= last; ++k) {
            if (k > 0 && !e.advance(time_at(k), [](double, const auto&, const Vec3&) {})) break;
            push(e.t(), e.y(), e.n());
        }
    }
    if (e.stop.reason != StopReason::None && (tr.samples.empty() || tr.samples.back().t < e.t())) push(e.t(), e.y(), e.n());
    tr.stop = e.stop;
    tr.stats = e.stats;
    tr.events = e.events;
    tr.held_time = e.held_time;
    return tr;
}

// run() of the model of `level` started at (q0, qd0); full dynamics with the plate on its zero-mean motion.
template <class TimeAt>
Trajectory run_level(const Scene& sc, Dynamics level, const Vec3& q0, const Vec3& qd0, long first, long last, TimeAt time_at,
                     const IntegrationOptions& opt) {
    if (level == Dynamics::ReducedU)
        throw std::invalid_argument("simulate: reduced U-dynamics have no trajectory; use limit_cycle");
    if (level == Dynamics::Full) {
        detail::FullModel m(sc);
        Vec3 p, phi;
        sc.plate.displacement(0.0, p, phi);   // R1 at the start
        return run(m, sc, {q0[0], q0[1], q0[2], qd0[0], qd0[1], qd0[2], phi[0], phi[1], phi[2]}, first, last, time_at, opt);
    }
    detail::UModel m(sc);
    return run(m, sc, {q0[0], q0[1], q0[2], qd0[0], qd0[1], qd0[2]}, first, last, time_at, opt);
}

}   // namespace

Trajectory simulate(const Scene& sc, Dynamics level, const Vec3& q0, const Vec3& qd0, double duration, double sample_dt,
                    const IntegrationOptions& opt) {
    if (!(duration > 0 && sample_dt > 0)) throw std::invalid_argument("simulate: duration and sample_dt must be > 0");
    const long count = static_cast<long>(std::ceil(duration / sample_dt - 1e-9));
    return run_level(
        sc, level, q0, qd0, 0, count, [&](long k) { return std::min(k * sample_dt, duration); }, opt);
}

Trajectory simulate_at(const Scene& sc, Dynamics level, const Vec3& q0, const Vec3& qd0, const std::vector<double>& times,
                       const IntegrationOptions& opt) {
    if (times.empty()) throw std::invalid_argument("simulate_at: no times");
    for (std::size_t k = 0; k < times.size(); ++k)
        if (!(std::isfinite(times[k]) && times[k] >= 0 && (k == 0 || times[k] > times[k - 1])))
            throw std::invalid_argument("simulate_at: expected finite increasing times >= 0");
    // (sample k is at times[k - first]: with times[0] = 0 the start itself is the first sample)
    const long first = times[0] == 0 ? 0 : 1, n = static_cast<long>(times.size());
    return run_level(
        sc, level, q0, qd0, first, n - 1 + first, [&](long k) { return times[k - first]; }, opt);
}

namespace {

using FullState = detail::FullModel::State;
constexpr int kSlow[6] = {0, 1, 2, 6, 7, 8};   // q and phi; the twist (3..5) is fast

// Macro points (t, q, dq/dt) for the samples.
struct Knot {
    double t;
    Vec3 q, v;
};

// One simulate_averaged: the trajectory it fills, the state and the macro points its stages share --
// the start (direct periods), the macro steps (bursts of full dynamics), the samples and the rest.
struct Averaging {
    const Scene& sc;
    const IntegrationOptions& opt;
    const AveragingOptions& avg;
    const double T;
    const double nan = std::numeric_limits<double>::quiet_NaN();
    Trajectory tr;
    FullState y{};
    std::vector<Knot> knots;
    long N = 0;         // whole periods in the duration
    long n = 0;         // periods done
    double t = 0;       // their end, n T (after the start)
    FullState last{};   // the last slope of (q, phi)
    bool ok = true;

    Averaging(const Scene& sc, const IntegrationOptions& opt, const AveragingOptions& avg)
        : sc(sc), opt(opt), avg(avg), T(sc.plate.T) {}
    bool run_to(double t0, FullState& y, double t1);
    bool slope(double t, FullState& y, const FullState& back, FullState& k);
    void run_start(double sample_dt);
    void run_macro_steps();
    void finish(double duration, double sample_dt);
};

// Runs the full dynamics from (t0, y) to t1; false (tr.stop set) if it stopped.
bool Averaging::run_to(double t0, FullState& y, double t1) {
    detail::FullModel m(sc);
    detail::Engine<detail::FullModel> e(m, sc, opt);
    const bool ok = e.start(t0, y) && e.advance(t1, [](double, const auto&, const Vec3&) {});
    tr.stats += e.stats;
    tr.stats.min_normal_force = std::min(tr.stats.min_normal_force, e.stats.min_normal_force);
    if (!ok) tr.stop = e.stop;
    y = e.y();
    return ok;
}

// A stage's slope of (q, phi) at y (time t = a whole number of periods), along `back` (the last
// slope); y's twist becomes the burst's end twist.
bool Averaging::slope(double t, FullState& y, const FullState& back, FullState& k) {
    FullState b = y;
    const double lead = (avg.relax_periods + 0.5) * T;
    for (int i : kSlow) b[i] -= lead * back[i];
    const double t0 = t - lead + 0.5 * T;   // (a whole number of periods before t)
    if (!run_to(t0, b, t0 + avg.relax_periods * T)) return false;
    const FullState a = b;
    if (!run_to(t0 + avg.relax_periods * T, b, t0 + (avg.relax_periods + 1) * T)) return false;
    for (int i = 0; i < 9; ++i) k[i] = (b[i] - a[i]) / T;
    for (int i : {3, 4, 5}) y[i] = b[i];
    return true;
}

// The start, directly, period by period: at least start_periods, and on until the twist at the
// periods' starts changes by at most macro_tol (of v_ref, v_ref, v_ref / rho) over a period --
// the fast variable settled, which the bursts' relax periods assume (fig4 from rest at (0.04,
// -0.04, 1): averaging from the fifth period put the run 2.4e-2 rho off at 0.8 s, whatever the
// macro tolerance). Its samples are the dynamics' own; its last period's change is the first
// slope's guess (the burst's lead).
void Averaging::run_start(double sample_dt) {
    detail::FullModel m(sc);
    detail::Engine<detail::FullModel> e(m, sc, opt);
    ok = e.start(0, y);
    if (ok) tr.samples.push_back(Sample{0, m.q(e.y()), m.qd(e.y()), e.n(), e.mode()});
    const detail::Scales scale(sc);
    const Vec3 S(scale.v, scale.v, scale.w);
    FullState begin = y;   // the state at the current period's start
    long s = 1;
    while (ok && avg.start_periods > 0 && n < N) {
        const double tn = (n + 1) * T;
        for (; ok && s * sample_dt < tn - 1e-12 * T; ++s)
            if ((ok = e.advance(s * sample_dt, [](double, const auto&, const Vec3&) {})))
                tr.samples.push_back(Sample{e.t(), m.q(e.y()), m.qd(e.y()), e.n(), e.mode()});
        if (!ok || !(ok = e.advance(tn, [](double, const auto&, const Vec3&) {}))) break;
        ++n;
        const FullState yn = e.y();
        double change = 0;
        for (int i = 0; i < 3; ++i) change = std::max(change, std::abs(yn[3 + i] - begin[3 + i]) / S[i]);
        for (int i = 0; i < 9; ++i) last[i] = (yn[i] - begin[i]) / T;
        begin = yn;
        if (n >= avg.start_periods && change <= avg.macro_tol) break;
    }
    tr.stats += e.stats;
    tr.stats.min_normal_force = std::min(tr.stats.min_normal_force, e.stats.min_normal_force);
    if (!ok) tr.stop = e.stop;
    y = e.y();
}

// Macro steps of K periods, K chosen from Heun's local error estimate, H/2 |k2 - k1| in (rho, rho,
// 1 rad) against macro_tol (the usual controller, exponent 1/2; a rejected step keeps k1).
void Averaging::run_macro_steps() {
    const double rho = sc.part.rho();
    FullState k1{}, k2{};
    long K = std::min<long>(avg.start_periods > 0 ? avg.start_periods : 1, avg.max_macro_periods);
    bool have_k1 = false;
    while (ok && n < N) {
        K = std::clamp<long>(K, 1, std::min<long>(avg.max_macro_periods, N - n));
        const double H = K * T;
        // A burst that stops (contact lost, a budget spent) ends the averaging: the rest is integrated
        // directly from the last accepted point, where a real stop is found with its real time --
        // except a predictor's at K > 1 (its point is Heun's guess): a rejected step.
        if (!have_k1 && !slope(t, y, last, k1)) break;
        have_k1 = true;
        FullState ye = y;
        for (int i : kSlow) ye[i] += H * k1[i];
        const bool k2_ok = slope(t + H, ye, k1, k2);
        if (!k2_ok && K == 1) break;
        const double err =
            k2_ok ? 0.5 * H * std::max({std::abs(k2[0] - k1[0]) / rho, std::abs(k2[1] - k1[1]) / rho, std::abs(k2[2] - k1[2])})
                  : std::numeric_limits<double>::infinity();
        const double grow = err > 0 ? 0.9 * std::sqrt(avg.macro_tol / err) : 2.0;
        if (!(err <= avg.macro_tol) && K > 1) {   // (also a NaN or a stopped predictor)
            ++tr.stats.rejected;
            tr.stop = StopEvent{};
            K = std::clamp<long>(std::lround(K * std::clamp(grow, 0.3, 1.0)), 1, K - 1);
            continue;
        }
        ++tr.stats.steps;   // (at K = 1 the step is taken whatever the estimate)
        knots.back().v = Vec3(k1[0], k1[1], k1[2]);
        for (int i : kSlow) y[i] += 0.5 * H * (k1[i] + k2[i]);
        for (int i : {3, 4, 5}) y[i] = ye[i];
        last = k2;
        have_k1 = false;
        n += K;
        t = n * T;
        knots.push_back({t, Vec3(y[0], y[1], y[2]), Vec3(k2[0], k2[1], k2[2])});
        K = std::max<long>(1, std::lround(K * std::clamp(grow, 0.3, 2.0)));
    }
}

// The samples of the macro phase, then the rest of the run directly.
void Averaging::finish(double duration, double sample_dt) {
    // Samples of the macro phase: cubic Hermite between knots with both slopes known, else linear.
    const long count = static_cast<long>(std::ceil(duration / sample_dt - 1e-9));
    long s = static_cast<long>(tr.samples.size());
    std::size_t j = 0;
    for (; ok && s <= count && std::min(s * sample_dt, duration) <= t; ++s) {
        const double ts = std::min(s * sample_dt, duration);
        while (j + 2 < knots.size() && knots[j + 1].t < ts) ++j;
        const Knot& a = knots[j];
        const Knot& b = knots[std::min(j + 1, knots.size() - 1)];
        const double h = b.t - a.t, u = h > 0 ? (ts - a.t) / h : 1.0;
        Vec3 q = (1 - u) * a.q + u * b.q;
        if (a.v.allFinite() && b.v.allFinite())
            q = (2 * u * u * u - 3 * u * u + 1) * a.q + (u * u * u - 2 * u * u + u) * h * a.v +
                (-2 * u * u * u + 3 * u * u) * b.q + (u * u * u - u * u) * h * b.v;
        tr.samples.push_back(Sample{ts, q, Vec3::Constant(nan), Vec3::Constant(nan), Mode{}});
    }
    // The rest -- the last partial period, or all of it after a burst stopped -- directly, with the
    // dynamics' own samples (and stop).
    if (ok && duration > t) {
        detail::FullModel m(sc);
        detail::Engine<detail::FullModel> e(m, sc, opt);
        ok = e.start(t, y);
        for (; ok && s <= count; ++s)
            if ((ok = e.advance(std::min(s * sample_dt, duration), [](double, const auto&, const Vec3&) {})))
                tr.samples.push_back(Sample{e.t(), m.q(e.y()), m.qd(e.y()), e.n(), e.mode()});
        tr.stats += e.stats;
        tr.stats.min_normal_force = std::min(tr.stats.min_normal_force, e.stats.min_normal_force);
        if (!ok) {
            tr.stop = e.stop;
            tr.samples.push_back(Sample{e.t(), m.q(e.y()), m.qd(e.y()), e.n(), e.mode()});
        }
    } else if (!ok && !tr.samples.empty() && tr.samples.back().t < tr.stop.t) {   // (stopped in the start)
        tr.samples.push_back(Sample{tr.stop.t, Vec3(y[0], y[1], y[2]), Vec3(y[3], y[4], y[5]), Vec3::Constant(nan), Mode{}});
    }
    if (ok && !tr.samples.empty() && !tr.samples.back().qd.allFinite() && tr.samples.back().t == t)
        tr.samples.back().qd = Vec3(y[3], y[4], y[5]);
}

}   // namespace

Trajectory simulate_averaged(const Scene& sc, const Vec3& q0, const Vec3& qd0, double duration, double sample_dt,
                             const IntegrationOptions& opt, const AveragingOptions& avg) {
    if (!(duration > 0 && sample_dt > 0)) throw std::invalid_argument("simulate_averaged: duration and sample_dt must be > 0");
    if (avg.max_macro_periods < 1 || !(avg.macro_tol > 0) || avg.relax_periods < 0 || avg.start_periods < 0)
        throw std::invalid_argument(
            "simulate_averaged: macro_tol > 0, max_macro_periods >= 1, relax_periods and start_periods >= 0");
    Averaging run(sc, opt, avg);
    Vec3 p, phi;
    sc.plate.displacement(0.0, p, phi);
    run.y = {q0[0], q0[1], q0[2], qd0[0], qd0[1], qd0[2], phi[0], phi[1], phi[2]};
    run.tr.stats.min_normal_force = std::numeric_limits<double>::infinity();
    run.N = static_cast<long>(std::floor(duration / run.T + 1e-9));
    run.run_start(sample_dt);
    run.t = run.n * run.T;
    run.knots.push_back({run.t, Vec3(run.y[0], run.y[1], run.y[2]), Vec3::Constant(run.nan)});
    run.run_macro_steps();
    if (run.ok) run.tr.stop = StopEvent{};   // (a burst's stop: the direct run below finds the real one)
    run.finish(duration, sample_dt);
    return run.tr;
}

}   // namespace plate
