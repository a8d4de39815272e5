// Engine (engine.hpp), the loop: a step under the controller, the event search over its guards, its
// acceptance (lingering slips offered to static friction), and the slide guards' reference
// directions. Included by engine.cpp only, which compiles the engine once per model.
#pragma once

#include "engine.hpp"
#include "plate/progress.hpp"

#include <cstring>

namespace plate::detail {

template <class Model>
Engine<Model>::Engine(Model& model, const Scene& scene, const IntegrationOptions& opt) : model_(model), scene_(scene), opt_(opt) {
    scale_ = model_.scale();
    for (std::size_t i = 0; i < scale_.size(); ++i) inv_scale_[i] = 1 / scale_[i];
    v_ref_ = scene_.v_ref();
    h_min_ = opt_.h_min * scene_.plate.T;
    // Below hint_speed (ten times the integration error of a slip) a sliding contact's friction
    // keeps its last direction: v/|v| of a slip that small is rounding noise (just after a
    // break-away its direction is the hint choose_mode set).
    stick_slip().use_hints = true;
    // Both grow with rtol only up to rtol 1e-5's values (the zero band under static friction: 1e-4's),
    // so that hint_speed < zero_abs_ < the creep speed (1e-2 v_ref) at any tolerance: uncapped, at rtol
    // 1e-2 every slip below 3 v_ref would count as zero and a part that never sticks would stick
    // (docs/decisions.md, Slip thresholds: the hint speed, the linger test and their cap).
    stick_slip().hint_speed = std::clamp(10 * opt_.rtol, 1e-12, 1e-4) * v_ref_;
    zero_abs_ = zero_band(opt_.rtol, !scene_.part.friction().single()) * v_ref_;
    // A contact that breaks away creeps (StickSlipState::creep: its friction along the consistent
    // direction, the direction's fast relaxation left out) while its slip is below 1e-2 v_ref and
    // the error that leaves stays below creep_budget_ (creep_step), 100 rtol v_ref: about the
    // integration's own error over the stretch the creep replaces (the local error's allowance,
    // ~rtol v_ref a step, over the ~100 stiff steps a decade of slip takes without it).
    // (docs/decisions.md, Creep: the consistent direction for a slip growing from zero)
    stick_slip().creep_speed = 1e-2 * v_ref_;
    creep_budget_ = 100 * opt_.rtol * v_ref_;
}

// Advances to t_end exactly; after each accepted step and at each event, on_step(t, y, n).
template <class Model>
bool Engine<Model>::advance(double t_end, OnStep on_step) {
    if (stop.reason != StopReason::None) return false;
    const double T = scene_.plate.T;
    while (t_ < t_end) {
        throw_if_stopped();   // (progress.hpp: a request to stop is seen within a step)
        if (stats.steps >= opt_.max_steps || stats.rhs_evals >= 10 * opt_.max_steps) {
            stop = StopEvent{StopReason::StepLimit, -1, t_};
            return false;
        }
        // While stuck, the guard (the gauge) is sampled at least 200 times a period.
        const bool stuck = model_.mode.kind == ModeKind::Stuck;
        frozen_ = stuck && Model::kStuckFrozen;
        const double cap = stuck ? T / 200 : std::numeric_limits<double>::infinity();
        double want = frozen_ ? cap : std::min({dt_, cap, creep_h_});
        if (!frozen_ && model_.mode.kind == ModeKind::Slide) want = std::min(want, std::max(zero_cap(), h_min_));
        const bool clamp = t_ + want >= t_end;
        double dt = clamp ? t_end - t_ : want;
        double t1 = t_;
        if (frozen_) {
            t1 = t_ + dt;   // nothing moves: the step is on the guards alone
            ys1_ = ys_;
            fs1_ = fs_;
        } else if (!try_step(t1, dt)) {
            ++stats.rejected;
            dt_ = dt;
            if (dt_ < h_min_) {
                stop = StopEvent{StopReason::StepCollapse, -1, t_};
                return false;
            }
            continue;
        } else {
            dt_ = clamp ? std::max(dt_, dt) : dt;
        }
        if (clamp) t1 = t_end;   // land on t_end exactly despite rounding
        ++stats.steps;
        // Diagnostics at the new point: the FSAL stage evaluated it last.
        if (frozen_ || !(last_t_ == t1 && std::memcmp(last_y_.data(), ys1_.data(), sizeof(ys1_)) == 0)) sys(ys1_, fs1_, t1);
        Guards g1;
        guards(ys1_, g1);
        const Vec3 n1 = model_.ws.n;
        const std::array<Vec2, 3> slip1 = model_.ws.slip;
        const int nc = scene_.part.contacts();
        for (int i = 0; i < nc; ++i) stats.min_normal_force = std::min(stats.min_normal_force, n1[i]);
        // The earliest located event in the step, if any.
        double t_ev;
        State y_ev{};
        bool swing = false;
        const int ev = first_event(t1, g1, t_ev, y_ev, swing);
        if (creep_inconsistent(slip1)) {
            // A creeping contact's slip left its consistent direction within the step (the
            // direction solved is not the one it moves along): retry the step sliding along v/|v|.
            ++stats.rejected;
            sys(ys_, fs_, t_);
            --stats.steps;
            continue;
        }
        if (swing && ev < 0) {
            // A swing within one step: the step kept the start's friction direction past the
            // turn (StickSlipState::hint_from), so retry it shorter until the turn is resolved.
            ++stats.rejected;
            dt_ = 0.5 * (t1 - t_);
            if (dt_ < h_min_) {
                stop = StopEvent{StopReason::StepCollapse, -1, t_};
                return false;
            }
            sys(ys_, fs_, t_);   // the workspace back at the step's start
            --stats.steps;
            continue;
        }
        if (ev < 0) {
            if (!accept_step(t1, g1, n1, slip1)) return false;
            on_step(t_, y(), n_);
            continue;
        }
        account(t_ev);
        t_ = t_ev;
        ys_ = y_ev;
        if (!event(ev)) return false;
        on_step(t_, y(), n_);
    }
    return true;
}

// The earliest located event in the step ending at t1 (guards g1 there): its guard (-1: none), time
// t_ev and scaled state y_ev; swing is set where a slip swung past zero without reaching it.
template <class Model>
int Engine<Model>::first_event(double t1, const Guards& g1, double& t_ev, State& y_ev, bool& swing) {
    int ev = -1;
    t_ev = std::numeric_limits<double>::infinity();
    for (int i = 0; i < kGuards; ++i) {
        double tb = t1, gb = g1[i];   // the bracket's right end: the step's end, or a dip's bottom
        State yd;                     // (a dip's state; the step's end is not copied for each guard)
        bool dip = false;
        if (!crossed(i, g0_[i], gb)) {
            dip = (i == 4 && turn_dip(t1, g1[i], tb, gb, yd)) ||
                  ((i < 3 || model_.mode.kind == ModeKind::Pivot) && stage_dip(i, t1, g1[i], tb, gb, yd));
            if (!dip) continue;
        }
        State yr;
        const double tr = locate(i, t1, tb, gb, dip ? yd : ys1_, yr);
        if (i >= 3 && model_.mode.kind == ModeKind::Slide && !slip_zero(i - 3, tr, yr)) {
            swing = true;   // the slip swung past zero without reaching it
            continue;
        }
        if (tr < t_ev || (tr == t_ev && i < 3)) {
            t_ev = tr;
            ev = i;
            y_ev = yr;
        }
    }
    return ev;
}

// Moves to the end (t1, ys1_, fs1_) of an accepted step without an event, with its guards g1,
// normal forces n1 and slips slip1. False if a stop occurred.
template <class Model>
bool Engine<Model>::accept_step(double t1, const Guards& g1, const Vec3& n1, const std::array<Vec2, 3>& slip1) {
    const int nc = scene_.part.contacts();
    // A creep's directions are read from the workspace (creep_step): if the event search
    // evaluated inside the step since, evaluate the step's end again so that they are its.
    if (stick_slip().creep && !(last_t_ == t1 && std::memcmp(last_y_.data(), ys1_.data(), sizeof(ys1_)) == 0))
        sys(ys1_, fs1_, t1);
    account(t1);
    t_ = t1;
    ys_ = ys1_;
    fs_ = fs1_;
    n_ = n1;
    rebase(g1, slip1);
    // A slip that lingers just above zero (near a grazing stick, where the deceleration
    // vanishes with the slip, it need not cross zero) makes v/|v| stiff and the steps tiny:
    // after kLinger steps below zero_abs_ it is taken as zero (the error is below zero_abs_,
    // i.e. 3e2 rtol v_ref, and in practice about a fifth of it; docs/decisions.md, Slip
    // thresholds: the hint speed, the linger test and their cap).
    unsigned linger = 0;
    if (model_.mode.kind == ModeKind::Slide)
        for (int i = 0; i < nc; ++i) {
            // (a slip growing away from zero, as after a break-away, does not linger; one
            // that alternates between two values -- an explicit step unstable on the
            // direction's relaxation -- does: it is compared with the larger of the last two)
            const double sn = slip1[i].norm();
            low_[i] = sn < zero_abs_ && sn <= 1.01 * std::max(slip_prev_[i], slip_prev2_[i]) ? low_[i] + 1 : 0;
            slip_prev2_[i] = slip_prev_[i];
            slip_prev_[i] = sn;
            if (low_[i] >= linger_need_[i]) linger |= 1u << i;
        }
    if (linger) {
        for (int i = 0; i < nc; ++i)
            if (slip1[i].norm() < zero_abs_) linger |= 1u << i;
        if (!try_hold(linger)) return false;
    }
    return true;
}

template <class Model>
void Engine<Model>::sys(const State& ys, State& dys, double t) {
    State y, dy;
    for (std::size_t i = 0; i < y.size(); ++i) y[i] = ys[i] * scale_[i];
    model_.rhs(t, y, dy);
    for (std::size_t i = 0; i < y.size(); ++i) dys[i] = dy[i] * inv_scale_[i];
    ++stats.rhs_evals;
    last_t_ = t;
    last_y_ = ys;
    if (collect_) note_stage(t, y);
}

// One step of size dt from (t_, ys_) into ys1_, fs1_ (stepper.hpp); t1 and dt as there.
template <class Model>
bool Engine<Model>::try_step(double& t1, double& dt) {
    stage_min_.fill(std::numeric_limits<double>::infinity());
    collect_ = true;
    // Where every contact slides faster than kLargeSlip v_ref the step's tolerance is
    // large_slip_factor rtol (IntegrationOptions); the slips' speeds at the step's start.
    double r = opt_.rtol;
    if (opt_.large_slip_factor != 1 && model_.mode.kind == ModeKind::Slide && !stick_slip().creep) {
        double slowest = std::numeric_limits<double>::infinity();
        for (int i = 0; i < scene_.part.contacts(); ++i) slowest = std::min(slowest, stick_slip().hint_from[i]);
        if (slowest > kLargeSlip * v_ref_) r = std::max(r, std::min(r * opt_.large_slip_factor, kLargeSlipRtolCap));
    }
    const bool ok = stepper_.try_step(sysref(), ys_, fs_, t1, ys1_, fs1_, dt, r);
    collect_ = false;
    return ok;
}

// The step that ends just past the first zero of a slip heading for it: kZeroOvershoot times the
// time at which a slip's component along its reference direction (the slide guard, g0_ at the
// step's start) reaches zero at its present rate (from the state's derivative: slips are linear in
// the twist, so a difference over any small time gives it). Without it a slip that crosses zero
// along a line -- a point part's reversal, or a contact of a part sliding straight -- is overrun:
// stages far past zero take the reversed friction, the error estimate jumps by 10^3-10^5 and the
// step is rejected, and so on down to the zero, where a step accepted at an error near 1 straddles
// the reversed friction (dynamics.cpp keeps the start's direction only for stage slips below a
// tenth of the start's). Ending 5 % past the predicted zero keeps the stages past it inside that
// tenth. (docs/decisions.md, Steps end just past a slip's predicted zero (`zero_cap`))
template <class Model>
double Engine<Model>::zero_cap() {
    const int nc = scene_.part.contacts();
    const double d = 1e-6 * scene_.plate.T;
    State yd;
    for (std::size_t i = 0; i < yd.size(); ++i) yd[i] = (ys_[i] + d * fs_[i]) * scale_[i];
    // (the offsets R2 c_i kept while theta stays: it does all period in the reduced U-dynamics)
    const double theta = model_.q(yd)[2];
    if (!(theta == cap_theta_)) {
        if (!scene_.part.point) contact_offsets(scene_.part, theta, cap_r_);
        cap_theta_ = theta;
    }
    std::array<Vec2, 3> v;
    slip_velocities_at(scene_.part, cap_r_, model_.qd(yd), v);
    double c = std::numeric_limits<double>::infinity();
    for (int i = 0; i < nc; ++i) {
        // Only a slip outside the zero band (inside it the lingering and creeping rules decide; and
        // a slip sliding on from a reversal, or creeping, has no zero event) ...
        const double s0 = stick_slip().hint_from[i];
        if ((fresh_ >> i & 1u) || (stick_slip().creep >> i & 1u) || !(g0_[3 + i] > 0) || s0 <= zero_abs_) continue;
        const Vec2 a = (v[i] - slip0_[i]) / d;
        const double rate = a.dot(ref_[i]);
        if (!(rate < 0)) continue;
        // ... heading for zero, not turning past it: at the predicted time the slip itself is within
        // a tenth of its start (a swing's component along ref vanishes while the slip stays large).
        const double tc = g0_[3 + i] / -rate;
        if ((slip0_[i] + tc * a).norm() <= 0.1 * s0) c = std::min(c, kZeroOvershoot * tc);
    }
    return c;
}

// The unit slip directions at the step's start, against which the slide guards are measured.
template <class Model>
void Engine<Model>::reference_directions(const std::array<Vec2, 3>& slip) {
    slip0_ = slip;
    for (int i = 0; i < 3; ++i) {
        const double s = slip[i].norm();
        const bool creeping = stick_slip().creep >> i & 1u;
        ref_[i] = s > stick_slip().hint_speed && !creeping ? Vec2(slip[i] / s) : stick_slip().hint[i];
        // The friction direction a slip keeps near zero within the next step (StickSlipState, workspace.hpp).
        if (model_.mode.kind == ModeKind::Slide) {
            stick_slip().hint[i] = ref_[i];
            stick_slip().hint_from[i] = s;
        }
    }
}

// The guards' baseline at a new step start: g, with the slide guards measured along the new
// reference directions.
template <class Model>
void Engine<Model>::rebase(const Guards& g, const std::array<Vec2, 3>& slip) {
    // The derivative at the new start was evaluated with the last step's directions: where a slip
    // fell below a tenth of its speed at that step's start, evaluate it again with the new ones.
    bool again = false;
    if (model_.mode.kind == ModeKind::Slide)
        for (int i = 0; i < scene_.part.contacts(); ++i) again |= slip[i].norm() < 0.1 * stick_slip().hint_from[i];
    again |= creep_step(slip);
    reference_directions(slip);
    if (again) sys(ys_, fs_, t_);
    g0_ = g;
    if (model_.mode.kind == ModeKind::Slide)
        for (int i = 0; i < scene_.part.contacts(); ++i) {
            g0_[3 + i] = slip[i].dot(ref_[i]);
            if (slip[i].norm() > zero_abs_) fresh_ &= ~(1u << i);   // out of the zero band
        }
}

// The state at time t in the last step, scaled (dense output; constant while frozen).
template <class Model>
void Engine<Model>::dense(double t, double t1, State& out) {
    if (frozen_) {
        out = ys_;
        return;
    }
    stepper_.dense(t, ys_, fs_, t_, ys1_, fs1_, t1, out);
}

template <class Model>
void Engine<Model>::account(double t1) {
    for (int i = 0; i < 3; ++i)
        if (model_.mode.holds(i)) held_time[i] += t1 - t_;
}

}   // namespace plate::detail
