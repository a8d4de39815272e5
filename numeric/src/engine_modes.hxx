// Engine (engine.hpp), the mode logic: a start or restart classifies the state, an event says which
// mode comes next (choose_mode), a lingering slip is offered to static friction, a burst of events
// or a lost contact stops the run. Included by engine.cpp only.
#pragma once

#include "engine.hpp"

namespace plate::detail {

// Starts at (t0, y0) in physical units; the mode follows from the state (a contact with zero slip
// is held or breaks away, choose_mode). Returns false with stop set if contact is lost at t0.
template <class Model>
bool Engine<Model>::start(double t0, const State& y0) {
    t_ = t0;
    stop = StopEvent{};
    dt_ = (opt_.h0 > 0 ? opt_.h0 : std::min(1e-3, 1e-2 * std::cbrt(opt_.rtol))) * scene_.plate.T;
    State y = y0;
    if (!classify(y)) return false;
    stats.min_normal_force = min_n();
    return true;
}

// After modify() changed the state to y (its twist was qd_old): a changed twist chooses its mode again.
template <class Model>
void Engine<Model>::restart(State& y, const Vec3& qd_old) {
    if (model_.qd(y) != qd_old)
        classify(y);   // (a contact lost there sets stop)
    else
        set(y);
}

// Sets the state (physical units) and evaluates there; the guards' baseline follows.
template <class Model>
void Engine<Model>::set(const State& y) {
    for (std::size_t i = 0; i < y.size(); ++i) ys_[i] = y[i] / scale_[i];
    std::array<Vec2, 3> v;
    slip_velocities(scene_.part, model_.q(y), model_.qd(y), v);
    reference_directions(v);
    sys(ys_, fs_, t_);
    n_ = model_.ws.n;
    guards(ys_, g0_);
}

// Chooses the mode of state y at t_ (contacts with zero slip are held or break away) and sets it.
template <class Model>
bool Engine<Model>::classify(State& y) {
    const int nc = scene_.part.contacts();
    std::array<Vec2, 3> v;
    slip_velocities(scene_.part, model_.q(y), model_.qd(y), v);
    unsigned zero = 0;
    for (int i = 0; i < nc; ++i)
        if (v[i].norm() <= 1e-14 * v_ref_) zero |= 1u << i;
    const Mode from = model_.mode;
    if (zero == 0) {
        model_.mode = Mode{};
    } else {
        Vec3 qd = model_.qd(y);
        const ModeChoice c = choose_mode(scene_, model_.level, model_.q(y), qd, model_.plate(t_, y), zero, model_.ws);
        if (c.lost) {
            stop = StopEvent{StopReason::ContactLost, c.lost_contact, t_};
            return false;
        }
        model_.mode = c.mode;
        model_.set_qd(y, qd);
    }
    start_creep(y);
    set(y);
    if (min_n() < 0) {
        int k = 0;
        model_.ws.n.head(nc).minCoeff(&k);
        stop = StopEvent{StopReason::ContactLost, k, t_};
        return false;
    }
    if (model_.mode != from) log_event(from);
    return true;
}

template <class Model>
void Engine<Model>::log_event(const Mode& from) {
    events.push_back(ModeEvent{t_, from, model_.mode});
    ++stats.mode_switches;
    burst_ = t_ - last_event_t_ <= 1e-9 * scene_.plate.T ? burst_ + 1 : 0;
    last_event_t_ = t_;
}

// Handles event ev at (t_, ys_): stops (contact lost) or chooses the next mode.
template <class Model>
bool Engine<Model>::event(int ev) {
    if (ev < 3) return lose(ev);
    const State y = this->y();
    const Vec3 q = model_.q(y);
    Vec3 qd = model_.qd(y);
    const Mode from = model_.mode;
    switch (from.kind) {
        case ModeKind::Slide: {
            std::array<Vec2, 3> v;
            slip_velocities(scene_.part, q, qd, v);
            unsigned zero = 1u << (ev - 3);
            for (int i = 0; i < scene_.part.contacts(); ++i)
                if (v[i].norm() <= slip_bound(i)) zero |= 1u << i;
            low_ = {0, 0, 0};
            return switch_mode(zero, true);
        }
        case ModeKind::Pivot:
            if (ev == 3 && std::abs(qd[2]) > 1e-14 * v_ref_ / scene_.part.rho()) {
                // Contact k breaks away, opposite the static friction it carried (the rim's force).
                Workspace& ws = model_.ws;
                mode_accelerations(scene_, model_.level, q, qd, model_.plate(t_, y), from, ws);
                const Vec2 f = ws.f_held[from.k];
                std::array<Vec2, 3> v;
                slip_velocities(scene_.part, q, qd, v);
                qd.head<2>() -= v[from.k];
                stick_slip().hint[from.k] = f.norm() > 0 ? Vec2(-f / f.norm()) : Vec2::Zero();
                return enter(Mode{}, y, qd);
            }
            return switch_mode(7, true);   // theta' reached zero: every slip is zero
        case ModeKind::Stuck:
            return switch_mode(7, false);   // the gauge crossed 1: break away
    }
    return true;
}

// A lingering slip: held (pivot, stuck) if static friction can hold it there; else slide on.
template <class Model>
bool Engine<Model>::try_hold(unsigned zero) {
    low_ = {0, 0, 0};
    const State y = this->y();
    Vec3 qd = model_.qd(y);
    const unsigned creep = stick_slip().creep;
    const Vec3 creep_twist = stick_slip().creep_twist, creep_twist_rate = stick_slip().creep_twist_rate;
    const std::array<double, 3> creep_rate = stick_slip().creep_rate;
    const std::array<Vec2, 3> hint = stick_slip().hint;
    const ModeChoice c = choose_mode(scene_, model_.level, model_.q(y), qd, model_.plate(t_, y), zero, model_.ws);
    if (!c.lost && c.mode.kind != ModeKind::Slide) return enter(c.mode, y, qd);
    // Not held: wait twice as long before the next try (each costs a mode choice).
    for (int i = 0; i < 3; ++i)
        if (zero >> i & 1u) linger_need_[i] = std::min(2 * linger_need_[i], 1 << 20);
    stick_slip().creep = creep;
    stick_slip().creep_twist = creep_twist;
    stick_slip().creep_twist_rate = creep_twist_rate;
    stick_slip().creep_rate = creep_rate;
    stick_slip().hint = hint;
    set(y);   // nothing changes: restore the workspace
    return true;
}

// Chooses the mode at (t_, ys_) with the contacts `zero` at zero slip and goes on in it.
template <class Model>
bool Engine<Model>::switch_mode(unsigned zero, bool hold) {
    const State y = this->y();
    Vec3 qd = model_.qd(y);
    const ModeChoice c = choose_mode(scene_, model_.level, model_.q(y), qd, model_.plate(t_, y), zero, model_.ws, hold);
    if (c.lost) return lose(c.lost_contact);
    const bool reversal = model_.mode.kind == ModeKind::Slide && c.mode.kind == ModeKind::Slide;
    if (reversal) ++stats.slip_reversals;
    const bool ok = enter(c.mode, y, qd);
    // A slip that reached zero and slides on (static friction cannot hold it) is not tested for
    // zero again until it has left the zero band (|v| > zero_abs_): at the noise floor right
    // after a reversal its guard crosses zero over and over, each crossing a new reversal. A slip
    // that stays in the band lingers and is offered to static friction by try_hold, with its
    // backoff. (docs/decisions.md, Reversals: no re-test inside the zero band)
    if (reversal) fresh_ |= zero;
    return ok;
}

// Goes on from state y (physical units) with twist qd in mode m.
template <class Model>
bool Engine<Model>::enter(const Mode& m, State y, const Vec3& qd) {
    const Mode from = model_.mode;
    model_.mode = m;
    model_.set_qd(y, qd);
    start_creep(y);
    set(y);
    log_event(from);
    return check_burst();
}

// Contact k is lost at (t_, ys_).
template <class Model>
bool Engine<Model>::lose(int k) {
    stop = StopEvent{StopReason::ContactLost, k, t_};
    sys(ys_, fs_, t_);
    n_ = model_.ws.n;
    return false;
}

template <class Model>
bool Engine<Model>::check_burst() {
    if (burst_ > kBurst) {
        stop = StopEvent{StopReason::EventAccumulation, -1, t_};
        return false;
    }
    return true;
}

}   // namespace plate::detail
