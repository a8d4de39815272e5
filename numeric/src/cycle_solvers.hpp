// Internal: what the limit-cycle solvers share -- one period of the period map, the stick tests and
// the stick bookkeeping of a period, the twist's scales -- and the shooting solver (shooting_cycle.cpp),
// which limit_cycle() calls (limit_cycle.cpp: plain periods and Anderson; newton_cycle.cpp: Newton).
#pragma once

#include "engine.hpp"
#include "models.hpp"
#include "plate/limit_cycle.hpp"

#include <vector>

namespace plate::detail {

// Did the part stick as a whole during the period (a mode change into Stuck)? It then forgets the
// period's start.
bool stuck_during(const std::vector<ModeEvent>& events);

// After two periods in a row that stuck as a whole, the second on a fresh engine: is its return r at
// the integration's floor -- within tol plus the zero band, and no smaller than half the previous such
// return r_floor (one that still halves is a transient)? More periods do not shrink it (one_start).
bool at_stuck_floor(double r, double r_floor, const LimitCycleOptions& opt);

// The stick bookkeeping of the period that just ended: per-contact stick fractions, the mode at
// its start and its mode changes (times from the period's start).
template <class E>
void record_modes(LimitCycleSummary& out, const E& e, const Mode& start_mode, double t_start, double T) {
    for (int i = 0; i < 3; ++i) out.stick_fraction[i] = e.held_time[i] / T;
    out.start_mode = start_mode;
    out.mode_events = e.events;
    for (ModeEvent& ev : out.mode_events) ev.t -= t_start;
}

// The twist's scales (v_ref, v_ref, v_ref / rho).
Vec3 twist_scale(const Scene& sc);

// One period of (35) from twist x at t = 0: the twist at T and the period average (36).
struct PeriodResult {
    bool ok = false;
    Vec3 end = Vec3::Zero(), average = Vec3::Zero();
    double min_n = 0;
    StopEvent stop;
};
PeriodResult one_period(const Scene& sc, const Vec3& q0, const Vec3& x, const IntegrationOptions& io, Stats& total);

// A solver's run at q0 (PeriodIteration, Shooting): the scene, the options and the engine over the
// reduced model it integrates the periods on.
struct CycleRun {
    using State = ReducedModel::State;
    const Scene& sc;
    const Vec3& q0;
    const LimitCycleOptions& opt;
    ReducedModel model;
    Engine<ReducedModel> e;
    const double T;

    CycleRun(const Scene& sc, const Vec3& q0, const LimitCycleOptions& opt)
        : sc(sc), q0(q0), opt(opt), model(sc, q0), e(model, sc, opt.integration), T(sc.plate.T) {}
};

// Newton's method on the period map from qd0 with a finite-difference monodromy (newton_cycle.cpp,
// GSL's gnewton; the web build, without GSL, refuses it: newton_cycle_web.cpp).
LimitCycleSummary newton_cycle(const Scene& sc, const Vec3& q0, const LimitCycleOptions& opt, const Vec3& qd0);

// Newton shooting from the warm start qd0 (shooting_cycle.cpp).
LimitCycleSummary shooting_cycle(const Scene& sc, const Vec3& q0, const LimitCycleOptions& opt, const Vec3& qd0);

}   // namespace plate::detail
