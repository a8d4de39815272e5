// Engine (engine.hpp), creep: a contact that has just broken away slides along its consistent
// direction (StickSlipState::creep) while the error that leaves stays within a budget. Included by
// engine.cpp only.
#pragma once

#include "engine.hpp"

namespace plate::detail {

// After an accepted step of a slide with creeping contacts. The creep leaves out the lag of the
// true slip direction behind the consistent one, lag ~ phi*' |v| / kappa (kappa = d(a x u)/d phi,
// the relaxation rate being kappa / |v|); the acceleration error is kappa times the lag,
// phi*' |v|, so over a step the velocity error is about |d phi*| |v| -- the consistent
// direction's turn over the step times the slip. Summed over the creep, it must stay below
// creep_budget_; the next step is limited so that it should (the increment grows about as the
// step squared: the turn with the step, the slip with it), and a contact whose budget is spent
// or whose slip exceeds creep_speed slides on along v/|v|. Returns true if a contact stopped
// creeping (the state is then evaluated again).
template <class Model>
bool Engine<Model>::creep_step(const std::array<Vec2, 3>& slip) {
    StickSlipState& ss = stick_slip();
    if (model_.mode.kind != ModeKind::Slide) return false;
    bool changed = false;
    const double h = t_ - creep_t_;
    creep_t_ = t_;
    const double h_cap = creep_h_ == std::numeric_limits<double>::infinity() ? kCreepFirst * scene_.plate.T : 5 * h;
    creep_h_ = std::numeric_limits<double>::infinity();
    // Every contact creeping (a rigid part's twist direction solved, modes.cpp): its turn too.
    if ((ss.creep & 7u) == 7u && !scene_.part.point && !ss.creep_twist.isZero()) {
        // (as an angular velocity, the turn about the normal of the last and the new direction,
        // so that within a step it turns the direction where the Newton puts it)
        const Vec3 axis = creep_xi_.cross(ss.creep_twist);
        const double sn = axis.norm();
        ss.creep_twist_rate = creep_xi_.isZero() || !(h > 0) || sn == 0
                                  ? Vec3::Zero()
                                  : Vec3(axis / sn * (std::atan2(sn, creep_xi_.dot(ss.creep_twist)) / h));
        creep_xi_ = ss.creep_twist;
    } else {
        forget_twist_turn();
    }
    for (int i = 0; i < scene_.part.contacts(); ++i) {
        if (!(ss.creep >> i & 1u)) {
            // A slip falling below zero_abs_ creeps on to zero along its consistent direction
            // (where the deceleration vanishes with the slip, near a grazing stick, it need not
            // reach zero soon, and v/|v| would make the steps collapse meanwhile). Its direction
            // is solved at the next evaluation; the budget counts from there.
            const double sn = slip[i].norm();
            // A contact whose creep was spent but whose slip stays below zero_abs_ (it grows or
            // shrinks so slowly that it neither lingers nor crosses zero: a slide at the rim of
            // the disk) creeps again after recreep_need_ such steps, twice as many each time
            // (without, such a slide crawls on at the noise floor in tiny steps).
            // A slip that more than doubles while it is counted is growing away from zero (it
            // leaves the band by itself); where its restart would make every contact of a rigid
            // part creep -- a creep of the whole twist (modes.cpp), whose direction is
            // ill-conditioned next to a pivot -- the count starts again. After a stuck part's
            // break-away next to a pivot (one contact at its disk's rim, the two others growing
            // from zero) such restarts reversed the slips at once (the creep stopped as
            // inconsistent, about ten rejected tries each time), and the run could spend its work
            // budget. Only the whole twist's restart waits: at a loose tolerance the zero band is
            // wide, and a single contact's restarted creep is what carries a growing slip through
            // it cheaply. (docs/decisions.md, A spent creep restarts, doubling up to 64 steps; A
            // growing slip does not restart a creep of the whole twist)
            if (sn > 0 && sn < zero_abs_) {
                if (slow_[i] == 0) slow_from_[i] = sn;
                ++slow_[i];
                const bool whole_twist = !scene_.part.point && ((ss.creep | 1u << i) & 7u) == 7u;
                if (whole_twist && sn > 2 * slow_from_[i]) {
                    slow_[i] = 1;
                    slow_from_[i] = sn;
                }
            } else {
                slow_[i] = 0;
            }
            const bool recreep = (creep_spent_ >> i & 1u) && slow_[i] >= recreep_need_[i];
            if (recreep) {
                creep_spent_ &= ~(1u << i);
                recreep_need_[i] = std::min(2 * recreep_need_[i], kRecreepMax);
                slow_[i] = 0;
            }
            if (recreep || (sn > 0 && sn < zero_abs_ && sn < std::abs(g0_[3 + i]) && !(creep_spent_ >> i & 1u))) {
                ss.creep |= 1u << i;
                ss.hint[i] = slip[i] / sn;
                new_creep(i);
                creep_h_ = std::min(creep_h_, kCreepFirst * scene_.plate.T);
                changed = true;
            }
            continue;
        }
        const Vec2& u = ss.hint[i];
        // The direction's signed turn over the step: its rate is followed in the next steps
        // (StickSlipState::creep_rate), so what the creep leaves out is the rate's change over a step
        // (the turn less the last rate's), times the slip.
        const double turn = creep_dir_[i].isZero()
                                ? 0.0
                                : std::atan2(creep_dir_[i].x() * u.y() - creep_dir_[i].y() * u.x(), creep_dir_[i].dot(u));
        const double sn = slip[i].norm(), inc = std::abs(turn - ss.creep_rate[i] * h) * sn;
        // Rigid parts carry the turn too (with the twist creep's turn, modes.cpp; docs/decisions.md,
        // Creeps carry the slip's turn).
        ss.creep_rate[i] = creep_dir_[i].isZero() || !(h > 0) ? 0.0 : turn / h;
        creep_err_[i] += inc;
        creep_dir_[i] = u;
        // The step the rest of the budget affords; where that is not even the last step's size,
        // the creep ends (a budget shrinking the steps towards zero would never be spent).
        const double afford = inc > 0 && h > 0 ? h * std::sqrt(std::max(creep_budget_ - creep_err_[i], 0.0) / inc)
                                               : std::numeric_limits<double>::infinity();
        if (creep_err_[i] > creep_budget_ || sn > ss.creep_speed || afford < h) {
            stop_creep(i, sn <= ss.creep_speed);
            changed = true;
        } else {
            creep_h_ = std::min({creep_h_, h_cap, afford});
        }
    }
    creep_h_ = std::max(creep_h_, h_min_);
    return changed;
}

// Does a creeping contact's slip at the end of the step point away from its consistent direction
// (more than ~25 degrees)? Then the creep's premise fails (the slip does not move along the
// direction solved, e.g. a root on which it would decelerate while it grows): that contact
// stops creeping until its next event, and true is returned (the step is retried).
template <class Model>
bool Engine<Model>::creep_inconsistent(const std::array<Vec2, 3>& slip) {
    StickSlipState& ss = stick_slip();
    if (!ss.creep || model_.mode.kind != ModeKind::Slide) return false;
    bool off = false;
    for (int i = 0; i < scene_.part.contacts(); ++i) {
        const double sn = slip[i].norm();
        if ((ss.creep >> i & 1u) && sn > kCreepJudged * ss.hint_speed && slip[i].dot(ss.hint[i]) < 0.9 * sn) {
            stop_creep(i, true);
            off = true;
        }
    }
    return off;
}

// A creep of contact i begins: its budget, last direction and turning rate start afresh.
template <class Model>
void Engine<Model>::new_creep(int i) {
    creep_err_[i] = 0;
    creep_dir_[i] = Vec2::Zero();
    stick_slip().creep_rate[i] = 0;
    forget_twist_turn();
}

// The twist creep's turn is measured afresh (a creep started or stopped, or a new mode).
template <class Model>
void Engine<Model>::forget_twist_turn() {
    stick_slip().creep_twist_rate.setZero();
    creep_xi_.setZero();
}

// Contact i slides on along v/|v| (spent: not to creep again before its next event); the twist's
// direction no longer describes every contact.
template <class Model>
void Engine<Model>::stop_creep(int i, bool spent) {
    stick_slip().creep &= ~(1u << i);
    stick_slip().creep_rate[i] = 0;
    stick_slip().creep_twist.setZero();
    forget_twist_turn();
    if (spent) creep_spent_ |= 1u << i;
}

// Entering a mode at state y: in a slide, the contacts at zero slip (just broken away) creep.
template <class Model>
void Engine<Model>::start_creep(const State& y) {
    StickSlipState& ss = stick_slip();
    fresh_ = 0;
    ss.creep = 0;
    ss.creep_rate = {};
    forget_twist_turn();
    creep_spent_ = 0;
    linger_need_ = {kLinger, kLinger, kLinger};
    recreep_need_ = {kRecreep, kRecreep, kRecreep};
    slow_ = {0, 0, 0};
    creep_h_ = std::numeric_limits<double>::infinity();
    creep_t_ = t_;
    if (model_.mode.kind != ModeKind::Slide) return;
    std::array<Vec2, 3> v;
    slip_velocities(scene_.part, model_.q(y), model_.qd(y), v);
    for (int i = 0; i < scene_.part.contacts(); ++i)
        if (v[i].norm() <= ss.hint_speed && ss.hint[i].norm() > 0) {
            ss.creep |= 1u << i;
            new_creep(i);   // (the direction is solved at the first evaluation)
            creep_h_ = kCreepFirst * scene_.plate.T;
        }
}

}   // namespace plate::detail
