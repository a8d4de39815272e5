// Engine (engine.hpp), guards and events: each mode's guards, and the location of the first one
// crossed in a step on its dense output -- at the step's end, at a stage inside it, or at the bottom
// of a pivot's turn. Included by engine.cpp only.
#pragma once

#include "engine.hpp"

namespace plate::detail {

// Guards at scaled state ys (evaluated: ws already holds the evaluation there).
template <class Model>
void Engine<Model>::guards(const State& ys, Guards& g) {
    const int nc = scene_.part.contacts();
    const Workspace& ws = model_.ws;
    for (int i = 0; i < 3; ++i) g[i] = i < nc ? ws.n[i] : 1.0;
    g[3] = g[4] = g[5] = 1.0;
    const Mode& m = model_.mode;
    switch (m.kind) {
        case ModeKind::Slide:
            for (int i = 0; i < nc; ++i) g[3 + i] = ws.slip[i].dot(ref_[i]);
            break;
        case ModeKind::Pivot: {
            State y;
            for (std::size_t i = 0; i < y.size(); ++i) y[i] = ys[i] * scale_[i];
            g[3] = scene_.part.friction().hold_margin(m.k, ws.n[m.k], ws.f_held[m.k]);
            g[4] = model_.qd(y)[2] * m.sense;
            break;
        }
        case ModeKind::Stuck: {
            State y;
            for (std::size_t i = 0; i < y.size(); ++i) y[i] = ys[i] * scale_[i];
            g[3] = 1 - friction_gauge(scene_.part, model_.q(y)[2], ws.n, ws.F_needed, ws.tau_needed).gamma;
            break;
        }
    }
}

// Has guard i changed sign over the step? Slips must leave a strictly positive value; holds
// (normal forces, the static friction margin, the pivot's turning) are violated below zero.
template <class Model>
bool Engine<Model>::crossed(int i, double g0, double g1) const {
    const bool slip = i >= 3 && model_.mode.kind == ModeKind::Slide;
    if (slip && (fresh_ >> (i - 3) & 1u)) return false;   // (inside the zero band after a reversal)
    return slip ? (g0 > 0 && g1 <= 0) : (g0 >= 0 && g1 < 0);
}

// First root of guard i in (t_, tb] (tb <= t1, the step's end; gb, yb the guard and the scaled
// state at tb, where it is crossed) on the step's dense output (events.hpp) to 1e-13 T; yr
// receives the scaled state at the returned time, where the guard is already violated.
template <class Model>
double Engine<Model>::locate(int i, double t1, double tb, double gb, const State& yb, State& yr) {
    yr = yb;
    State ym;
    return illinois_first_root(
        t_, tb, g0_[i], gb, 1e-13 * scene_.plate.T, [&](double m) { return guard_at(i, m, t1, ym); },
        [&](double ga, double gm_i) { return crossed(i, ga, gm_i); }, [&] { yr = ym; });
}

// The hold guards at the step's stages (its right-hand sides, evaluated anyway): a normal force or
// a pivot's static-friction margin that goes negative between two positive ends of a step shows
// at a stage, the candidate right end of the root's bracket: the guards' signs at the step's ends
// alone would miss such a dip, and with it a break-away. (docs/decisions.md, Guards read at the
// step's stages; a pivot's turn searched for its minimum)
template <class Model>
void Engine<Model>::note_stage(double t, const State& y) {
    const Workspace& ws = model_.ws;
    for (int i = 0; i < scene_.part.contacts(); ++i) note_stage_guard(i, t, ws.n[i]);
    if (model_.mode.kind == ModeKind::Pivot) {
        const int k = model_.mode.k;
        note_stage_guard(3, t, scene_.part.friction().hold_margin(k, ws.n[k], ws.f_held[k]));
        note_stage_guard(4, t, model_.qd(y)[2] * model_.mode.sense);
    }
}

template <class Model>
void Engine<Model>::note_stage_guard(int i, double t, double g) {
    if (g < stage_min_[i]) {
        stage_min_[i] = g;
        stage_t_[i] = t;
    }
}

// A hold guard i that is positive at both ends of the step but was negative at a stage inside it:
// if the dense output is crossed there too, that time is the root's bracket end (tb, gb, yb).
template <class Model>
bool Engine<Model>::stage_dip(int i, double t1, double g1, double& tb, double& gb, State& yb) {
    if (i > 4 || frozen_ || !(stage_min_[i] < 0) || !(g0_[i] >= 0 && g1 >= 0)) return false;
    const double ts = stage_t_[i];
    if (!(ts > t_ && ts < t1)) return false;
    State ym;
    const double gm = guard_at(i, ts, t1, ym);
    if (!crossed(i, g0_[i], gm)) return false;
    tb = ts;
    gb = gm;
    yb = ym;
    return true;
}

// Guard i at time t of the step ending at t1, on its dense output (ym: the scaled state there).
template <class Model>
double Engine<Model>::guard_at(int i, double t, double t1, State& ym) {
    State dym;
    Guards g;
    dense(t, t1, ym);
    sys(ym, dym, t);
    guards(ym, g);
    return g[i];
}

// A pivot's turn (theta' times its sense, guard 4) that dips through zero and back within one
// step: the part comes to rest for a moment and turns on the same way, and both ends of the step
// are positive, so their signs miss it (and with it a short stuck phase). theta'' at the step's
// ends (its derivatives, already evaluated) says whether the turn has a minimum inside --
// decelerating at the start, accelerating at the end; then that minimum of the dense output is
// found by golden section (the guard is a state component: no right-hand sides), and where it is
// crossed it becomes the root's bracket (tb, gb, yb). (docs/decisions.md, Guards read at the
// step's stages; a pivot's turn searched for its minimum)
template <class Model>
bool Engine<Model>::turn_dip(double t1, double g1, double& tb, double& gb, State& yb) {
    if (model_.mode.kind != ModeKind::Pivot || frozen_ || !(g0_[4] > 0 && g1 > 0)) return false;
    State d0, d1, ym;
    for (std::size_t i = 0; i < d0.size(); ++i) {
        d0[i] = fs_[i] * scale_[i];
        d1[i] = fs1_[i] * scale_[i];
    }
    const double sense = model_.mode.sense;
    if (!(model_.qd(d0)[2] * sense < 0 && model_.qd(d1)[2] * sense > 0)) return false;
    auto turn = [&](double t) {
        dense(t, t1, ym);
        State y;
        for (std::size_t i = 0; i < y.size(); ++i) y[i] = ym[i] * scale_[i];
        return model_.qd(y)[2] * sense;
    };
    constexpr double r = 0.6180339887498949;
    double a = t_, b = t1, c = b - r * (b - a), d = a + r * (b - a), gc = turn(c), gd = turn(d);
    for (int it = 0; it < 40 && b - a > 1e-13 * scene_.plate.T; ++it) {
        if (gc < gd) {
            b = d;
            d = c;
            gd = gc;
            c = b - r * (b - a);
            gc = turn(c);
        } else {
            a = c;
            c = d;
            gc = gd;
            d = a + r * (b - a);
            gd = turn(d);
        }
    }
    const double tm = gc < gd ? c : d;
    const double gm = turn(tm);
    if (!crossed(4, g0_[4], gm)) return false;
    // The bracket's end, evaluated like the step's (the guard there is the turn itself).
    tb = tm;
    gb = gm;
    yb = ym;
    return true;
}

// Did contact k's slip really reach zero at the root of its guard (rather than swing past zero)?
template <class Model>
bool Engine<Model>::slip_zero(int k, double t, const State& yr) {
    State dy;
    sys(yr, dy, t);
    return model_.ws.slip[k].norm() <= slip_bound(k);
}

}   // namespace plate::detail
