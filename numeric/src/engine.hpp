// Internal: the integration loop shared by trajectories and limit cycles, with stick-slip: the
// mode logic (which guards a mode has, what an event means, which mode comes next, creep and
// lingering slips) driving two parts that know nothing of contacts:
//   stepper.hpp  one Dormand-Prince 5(4) step on a scaled state (one scalar tolerance relative for
//                every component) under a PI step-size controller, and its dense output;
//   events.hpp   the first root of a guard on a step's dense output (Illinois).
//
// The contact mode (modes.hpp: slide, pivot about a contact, stuck) is part of the state. Each mode
// has guards that stay positive while it holds: the normal forces; in slide, each contact's slip
// along its direction at the step's start; in pivot k, mu_k N_k - |f_k| and theta' times the
// turning sense; in stuck, 1 - gauge. After each accepted step the guards are evaluated at its end;
// a guard that changed sign is located by the Illinois root finder on the step's dense output
// (Dormand-Prince's fourth-order interpolant: no re-stepping, one right-hand side per iterate), the
// step is cut there, and the new mode is chosen (choose_mode) -- the integration goes on from the
// event in that mode. Only a normal force reaching zero stops the run (the part would fly).
//
// Accumulating events (Zeno): a guard is tested only for a sign change from strictly positive (a
// slip) or from non-negative (a hold), so an event at t* cannot fire again before one step past t*;
// a burst of more than kBurst events within 1e-9 T ends the run as EventAccumulation with a
// message, instead of hanging. A slip that merely swings past zero (its component along the step's
// starting direction changes sign while the slip stays away from zero) is not an event.
#pragma once

#include "events.hpp"
#include "plate/modes.hpp"
#include "plate/simulate.hpp"
#include "so3.hpp"
#include "stepper.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

namespace plate::detail {

// The zero band, relative to v_ref: a slip below it counts as zero (a lingering slip is offered to
// static friction), so it bounds the engine's error in a slip -- and in a cycle's start after a stick.
inline double zero_band(double rtol) { return std::clamp(3e2 * rtol, 1e-9, 3e-3); }

// Model concept: State, level, ws, mode; rhs(t, y, dy) in physical units, in the model's mode (fills
// ws); q(y), qd(y), set_qd(y, qd); plate(t, y) -> PlateState; scale() -> State of characteristic
// magnitudes; kStuckFrozen: nothing in the state moves while the part is stuck.
template <class Model>
class Engine {
public:
    using State = typename Model::State;
    static constexpr int kGuards = 6;   // N_1..N_3, then the mode's own (up to 3)
    using Guards = std::array<double, kGuards>;

    Engine(Model& model, const Scene& scene, const IntegrationOptions& opt)
        : model_(model), scene_(scene), opt_(opt) {
        scale_ = model_.scale();
        for (std::size_t i = 0; i < scale_.size(); ++i) inv_scale_[i] = 1 / scale_[i];
        v_ref_ = scene_.v_ref();
        h_min_ = opt_.h_min * scene_.plate.T;
        // Below hint_speed (ten times the integration error of a slip) a sliding contact's friction
        // keeps its last direction: v/|v| of a slip that small is rounding noise (just after a
        // break-away its direction is the hint choose_mode set).
        model_.ws.use_hints = true;
        // Both grow with rtol only up to rtol 1e-5's values, so that hint_speed < zero_abs_ < the
        // creep speed (1e-2 v_ref) at any tolerance: uncapped, at rtol 1e-2 every slip below 3 v_ref
        // counted as zero and fig4's never-sticking part stuck 797 times in 20 s (3 rad off).
        model_.ws.hint_speed = std::clamp(10 * opt_.rtol, 1e-12, 1e-4) * v_ref_;
        zero_abs_ = zero_band(opt_.rtol) * v_ref_;
        // A contact that breaks away creeps (Workspace::creep: its friction along the consistent
        // direction, the direction's fast relaxation left out) while its slip is below 1e-2 v_ref and
        // the error that leaves stays below creep_budget_ (creep_step), 100 rtol v_ref: about the
        // integration's own error over the stretch the creep replaces (the local error's allowance,
        // ~rtol v_ref a step, over the ~100 stiff steps a decade of slip takes without it). fig6's field
        // against 10 rtol v_ref: 7 % fewer right-hand sides, the same largest error against the rtol-1e-11
        // field (2.4e-7 v_ref sliding, 6.5e-7 sticking), the sticking median 4.1e-8 -> 5.1e-8;
        // heave_yaw's 15 % fewer, its largest 3.4e-7 -> 2.6e-7.
        model_.ws.creep_speed = 1e-2 * v_ref_;
        creep_budget_ = 100 * opt_.rtol * v_ref_;
    }

    // Starts at (t0, y0) in physical units; the mode follows from the state (a contact with zero slip
    // is held or breaks away, choose_mode). Returns false with stop set if contact is lost at t0.
    bool start(double t0, const State& y0) {
        t_ = t0;
        stop = StopEvent{};
        dt_ = (opt_.h0 > 0 ? opt_.h0 : std::min(1e-3, 1e-2 * std::cbrt(opt_.rtol))) * scene_.plate.T;
        State y = y0;
        if (!classify(y)) return false;
        stats.min_normal_force = min_n();
        return true;
    }

    double t() const { return t_; }
    double next_step() const { return dt_; }   // the step the controller proposes next [s]
    const Mode& mode() const { return model_.mode; }
    // The large-slip steps' factor from the next step on (IntegrationOptions::large_slip_factor).
    void set_large_slip_factor(double f) { opt_.large_slip_factor = f; }
    State y() const {
        State y;
        for (std::size_t i = 0; i < y.size(); ++i) y[i] = ys_[i] * scale_[i];
        return y;
    }
    const Vec3& n() const { return n_; }
    // Overwrites components of the state (e.g. to reset an integral, or a new start twist), keeping
    // the time; a changed twist chooses its mode again.
    template <class F> void modify(F&& f) {
        State y = this->y();
        const Vec3 qd_old = model_.qd(y);
        f(y);
        if (model_.qd(y) != qd_old) {
            if (!classify(y)) return;
        } else {
            set(y);
        }
    }
    // Restarts the bookkeeping of held time and mode changes (e.g. at a period's start).
    void reset_log() {
        held_time = {0, 0, 0};
        events.clear();
    }

    // Advances to t_end exactly. on_step(t, y, n) is called after each accepted step and at each
    // event. Returns false if a stop occurred (see `stop`).
    template <class OnStep>
    bool advance(double t_end, OnStep&& on_step) {
        if (stop.reason != StopReason::None) return false;
        const double T = scene_.plate.T;
        while (t_ < t_end) {
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
            if (frozen_ || !(last_t_ == t1 && std::memcmp(last_y_.data(), ys1_.data(), sizeof(ys1_)) == 0))
                sys(ys1_, fs1_, t1);
            Guards g1;
            guards(ys1_, g1);
            const Vec3 n1 = model_.ws.n;
            const std::array<Vec2, 3> slip1 = model_.ws.slip;
            const int nc = scene_.part.contacts();
            for (int i = 0; i < nc; ++i) stats.min_normal_force = std::min(stats.min_normal_force, n1[i]);
            // The earliest located event in the step, if any.
            int ev = -1;
            double t_ev = std::numeric_limits<double>::infinity();
            State y_ev{};
            bool swing = false;
            for (int i = 0; i < kGuards; ++i) {
                double tb = t1, gb = g1[i];   // the bracket's right end: the step's end, or a dip's bottom
                State yb = ys1_;
                if (!crossed(i, g0_[i], gb) && !(i == 4 && turn_dip(t1, g1[i], tb, gb, yb)) &&
                    !((i < 3 || model_.mode.kind == ModeKind::Pivot) && stage_dip(i, t1, g1[i], tb, gb, yb)))
                    continue;
                State yr;
                const double tr = locate(i, t1, tb, gb, yb, yr);
                if (i >= 3 && model_.mode.kind == ModeKind::Slide && !slip_zero(i - 3, tr, yr)) {
                    swing = true;   // the slip swung past zero without reaching it
                    continue;
                }
                if (tr < t_ev || (tr == t_ev && i < 3)) { t_ev = tr; ev = i; y_ev = yr; }
            }
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
                // turn (ws.hint_from), so retry it shorter until the turn is resolved.
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
                // A creep's directions are read from the workspace (creep_step): if the event search
                // evaluated inside the step since, evaluate the step's end again so that they are its.
                if (model_.ws.creep && !(last_t_ == t1 && std::memcmp(last_y_.data(), ys1_.data(), sizeof(ys1_)) == 0))
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
                // i.e. 3e2 rtol v_ref; measured on fig6's sticking cycles, about a fifth of it: 1e3 rtol
                // v_ref left 4 of 78 at 1.4-2.1e-6 v_ref from the regularised limit at rtol 1e-8).
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

    StopEvent stop;
    Stats stats;
    std::array<double, 3> held_time{};   // time each contact had zero slip since reset_log() [s]
    std::vector<ModeEvent> events;       // mode changes since reset_log()

private:
    struct Sys {
        Engine* e;
        void operator()(const State& ys, State& dys, double t) const { e->sys(ys, dys, t); }
    };
    Sys sysref() { return Sys{this}; }

    void sys(const State& ys, State& dys, double t) {
        State y, dy;
        for (std::size_t i = 0; i < y.size(); ++i) y[i] = ys[i] * scale_[i];
        model_.rhs(t, y, dy);
        for (std::size_t i = 0; i < y.size(); ++i) dys[i] = dy[i] * inv_scale_[i];
        ++stats.rhs_evals;
        last_t_ = t;
        last_y_ = ys;
        if (collect_) note_stage(t, y);
    }

    // The hold guards at the step's stages (its right-hand sides, evaluated anyway): a normal force or
    // a pivot's static-friction margin that goes negative between two positive ends of a step shows
    // at a stage, the candidate right end of the root's bracket (an outside review found a pivot's
    // break-away missed that way: seed 132 of the random stick-slip scenes at rtol 1e-5, the margin
    // 7.7e-4 -> -3.6e-3 -> 1.9e-3 within one step of 0.075 T, the cycle then held 0.82 of the period
    // instead of 0.72).
    void note_stage(double t, const State& y) {
        const Workspace& ws = model_.ws;
        for (int i = 0; i < scene_.part.contacts(); ++i) note_stage_guard(i, t, ws.n[i]);
        if (model_.mode.kind == ModeKind::Pivot) {
            const int k = model_.mode.k;
            note_stage_guard(3, t, scene_.part.friction().hold_margin(k, ws.n[k], ws.f_held[k]));
            note_stage_guard(4, t, model_.qd(y)[2] * model_.mode.sense);
        }
    }
    void note_stage_guard(int i, double t, double g) {
        if (g < stage_min_[i]) {
            stage_min_[i] = g;
            stage_t_[i] = t;
        }
    }

    // One step of size dt from (t_, ys_) into ys1_, fs1_ (stepper.hpp); t1 and dt as there.
    bool try_step(double& t1, double& dt) {
        stage_min_.fill(std::numeric_limits<double>::infinity());
        collect_ = true;
        // Where every contact slides faster than kLargeSlip v_ref the step's tolerance is
        // large_slip_factor rtol (IntegrationOptions); the slips' speeds at the step's start.
        double r = opt_.rtol;
        if (opt_.large_slip_factor != 1 && model_.mode.kind == ModeKind::Slide && !model_.ws.creep) {
            double slowest = std::numeric_limits<double>::infinity();
            for (int i = 0; i < scene_.part.contacts(); ++i) slowest = std::min(slowest, model_.ws.hint_from[i]);
            if (slowest > kLargeSlip * v_ref_) r = std::max(r, std::min(r * opt_.large_slip_factor, kLargeSlipRtolCap));
        }
        const bool ok = stepper_.try_step(sysref(), ys_, fs_, t1, ys1_, fs1_, dt, r);
        collect_ = false;
        return ok;
    }

    // A hold guard i that is positive at both ends of the step but was negative at a stage inside it:
    // if the dense output is crossed there too, that time is the root's bracket end (tb, gb, yb).
    bool stage_dip(int i, double t1, double g1, double& tb, double& gb, State& yb) {
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
    double guard_at(int i, double t, double t1, State& ym) {
        State dym;
        Guards g;
        dense(t, t1, ym);
        sys(ym, dym, t);
        guards(ym, g);
        return g[i];
    }

    // The step that ends just past the first zero of a slip heading for it: kZeroOvershoot times the
    // time at which a slip's component along its reference direction (the slide guard, g0_ at the
    // step's start) reaches zero at its present rate (from the state's derivative: slips are linear in
    // the twist, so a difference over any small time gives it). Without it a slip that crosses zero
    // along a line -- a point part's reversal, or a contact of a part sliding straight -- is overrun:
    // stages far past zero take the reversed friction, the error estimate jumps by 10^3-10^5 and the
    // step is rejected, and so on down to the zero, where a step accepted at an error near 1 straddles
    // the reversed friction (dynamics.cpp keeps the start's direction only for stage slips below a
    // tenth of the start's). fig1_point's cycle at (0, -0.05), one period from the cycle's start at rtol
    // 1e-8 against 1e-11: 3e-7 to 5e-7 v_ref off depending on the first step, 2e-9 with the cap; its
    // field 277 520 -> 64 469 right-hand sides, the largest error 1.07e-6 -> 8.4e-9 v_ref (docs/speed.md).
    // Ending 5 % past the predicted zero keeps the stages past it inside that tenth.
    double zero_cap() {
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
            const double s0 = model_.ws.hint_from[i];
            if ((fresh_ >> i & 1u) || (model_.ws.creep >> i & 1u) || !(g0_[3 + i] > 0) || s0 <= zero_abs_) continue;
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
    static constexpr double kZeroOvershoot = 1.05;
    std::array<Vec2, 3> slip0_ = zeros<Vec2>();   // the slips at the step's start (reference_directions)
    double cap_theta_ = std::numeric_limits<double>::quiet_NaN();
    std::array<Vec2, 3> cap_r_ = zeros<Vec2>();

    double min_n() const { return model_.ws.n.head(scene_.part.contacts()).minCoeff(); }

    // Sets the state (physical units) and evaluates there; the guards' baseline follows.
    void set(const State& y) {
        for (std::size_t i = 0; i < y.size(); ++i) ys_[i] = y[i] / scale_[i];
        std::array<Vec2, 3> v;
        slip_velocities(scene_.part, model_.q(y), model_.qd(y), v);
        reference_directions(v);
        sys(ys_, fs_, t_);
        n_ = model_.ws.n;
        guards(ys_, g0_);
    }

    // Chooses the mode of state y at t_ (contacts with zero slip are held or break away) and sets it.
    bool classify(State& y) {
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

    void log_event(const Mode& from) {
        events.push_back(ModeEvent{t_, from, model_.mode});
        ++stats.mode_switches;
        burst_ = t_ - last_event_t_ <= 1e-9 * scene_.plate.T ? burst_ + 1 : 0;
        last_event_t_ = t_;
    }

    // The unit slip directions at the step's start, against which the slide guards are measured.
    void reference_directions(const std::array<Vec2, 3>& slip) {
        slip0_ = slip;
        for (int i = 0; i < 3; ++i) {
            const double s = slip[i].norm();
            const bool creeping = model_.ws.creep >> i & 1u;
            ref_[i] = s > model_.ws.hint_speed && !creeping ? Vec2(slip[i] / s) : model_.ws.hint[i];
            // The friction direction a slip keeps near zero within the next step (dynamics.hpp).
            if (model_.mode.kind == ModeKind::Slide) {
                model_.ws.hint[i] = ref_[i];
                model_.ws.hint_from[i] = s;
            }
        }
    }
    // The guards' baseline at a new step start: g, with the slide guards measured along the new
    // reference directions.
    void rebase(const Guards& g, const std::array<Vec2, 3>& slip) {
        // The derivative at the new start was evaluated with the last step's directions: where a slip
        // fell below a tenth of its speed at that step's start, evaluate it again with the new ones.
        bool again = false;
        if (model_.mode.kind == ModeKind::Slide)
            for (int i = 0; i < scene_.part.contacts(); ++i) again |= slip[i].norm() < 0.1 * model_.ws.hint_from[i];
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

    // After an accepted step of a slide with creeping contacts. The creep leaves out the lag of the
    // true slip direction behind the consistent one, lag ~ phi*' |v| / kappa (kappa = d(a x u)/d phi,
    // the relaxation rate being kappa / |v|); the acceleration error is kappa times the lag,
    // phi*' |v|, so over a step the velocity error is about |d phi*| |v| -- the consistent
    // direction's turn over the step times the slip. Summed over the creep, it must stay below
    // creep_budget_; the next step is limited so that it should (the increment grows about as the
    // step squared: the turn with the step, the slip with it), and a contact whose budget is spent
    // or whose slip exceeds creep_speed slides on along v/|v|. Returns true if a contact stopped
    // creeping (the state is then evaluated again).
    bool creep_step(const std::array<Vec2, 3>& slip) {
        Workspace& ws = model_.ws;
        if (model_.mode.kind != ModeKind::Slide) return false;
        bool changed = false;
        const double h = t_ - creep_t_;
        creep_t_ = t_;
        const double h_cap = creep_h_ == std::numeric_limits<double>::infinity() ? kCreepFirst * scene_.plate.T : 5 * h;
        creep_h_ = std::numeric_limits<double>::infinity();
        // Every contact creeping (a rigid part's twist direction solved, modes.cpp): its turn too.
        if ((ws.creep & 7u) == 7u && !scene_.part.point && !ws.creep_twist.isZero()) {
            // (as an angular velocity, the turn about the normal of the last and the new direction,
            // so that within a step it turns the direction where the Newton puts it)
            const Vec3 axis = creep_xi_.cross(ws.creep_twist);
            const double sn = axis.norm();
            ws.creep_twist_rate = creep_xi_.isZero() || !(h > 0) || sn == 0
                                      ? Vec3::Zero()
                                      : Vec3(axis / sn * (std::atan2(sn, creep_xi_.dot(ws.creep_twist)) / h));
            creep_xi_ = ws.creep_twist;
        } else {
            forget_twist_turn();
        }
        for (int i = 0; i < scene_.part.contacts(); ++i) {
            if (!(ws.creep >> i & 1u)) {
                // A slip falling below zero_abs_ creeps on to zero along its consistent direction
                // (where the deceleration vanishes with the slip, near a grazing stick, it need not
                // reach zero soon, and v/|v| would make the steps collapse meanwhile). Its direction
                // is solved at the next evaluation; the budget counts from there.
                const double sn = slip[i].norm();
                // A contact whose creep was spent but whose slip stays below zero_abs_ (it grows or
                // shrinks so slowly that it neither lingers nor crosses zero: a slide at the rim of
                // the disk) creeps again after recreep_need_ such steps, twice as many each time:
                // heave_yaw (z 2, rz 60) at (0, 0.02, 0) had a contact slide at ~2e-9 m/s for 15 ms
                // in steps of 3e-9 s, 3.2e6 right-hand sides a period.
                // A slip that more than doubles while it is counted is growing away from zero (it
                // leaves the band by itself); where its restart would make every contact of a rigid
                // part creep -- a creep of the whole twist (modes.cpp), whose direction is
                // ill-conditioned next to a pivot -- the count starts again. After a stuck part's
                // break-away next to a pivot (one contact at its disk's rim, the two others growing
                // from zero) such restarts reversed the slips at once (the creep stopped as
                // inconsistent, about ten rejected tries each time): sticking_random_scene(3121)
                // spent the 2e7 budget at the default rtol 1e-8 and 2512 at 1e-9; now 1.8e4 and 1.3e4
                // right-hand sides. (Not counting any growing slip's steps also fixed 2512 at 5e-9
                // and 1e-10, but cost up to 25x on other seeds at rtol 1e-6: docs/speed.md.)
                if (sn > 0 && sn < zero_abs_) {
                    if (slow_[i] == 0) slow_from_[i] = sn;
                    ++slow_[i];
                    const bool whole_twist = !scene_.part.point && ((ws.creep | 1u << i) & 7u) == 7u;
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
                    ws.creep |= 1u << i;
                    ws.hint[i] = slip[i] / sn;
                    new_creep(i);
                    creep_h_ = std::min(creep_h_, kCreepFirst * scene_.plate.T);
                    changed = true;
                }
                continue;
            }
            const Vec2& u = ws.hint[i];
            // The direction's signed turn over the step: its rate is followed in the next steps
            // (Workspace::creep_rate), so what the creep leaves out is the rate's change over a step
            // (the turn less the last rate's), times the slip.
            const double turn = creep_dir_[i].isZero() ? 0.0 : std::atan2(creep_dir_[i].x() * u.y() - creep_dir_[i].y() * u.x(), creep_dir_[i].dot(u));
            const double sn = slip[i].norm(), inc = std::abs(turn - ws.creep_rate[i] * h) * sn;
            // Rigid parts too: fig6's field 1.86e6 -> 1.69e6 right-hand sides, heave_yaw's 1.90e6 ->
            // 1.56e6 (with the twist creep's turn, modes.cpp). (heave_yaw's cycle at (0, 0.02, 0) then
            // shows no reversal 1e-6 T after contact 3's pivot breaks away at rtol 1e-9, where rtol
            // 1e-8 and 1e-10 show one: that contact slides on at the noise floor, 2e-10 and 2e-11 m/s,
            // and whether it touches zero is noise; the mode-sequence test ties reversals to
            // break-aways instead of matching each.)
            ws.creep_rate[i] = creep_dir_[i].isZero() || !(h > 0) ? 0.0 : turn / h;
            creep_err_[i] += inc;
            creep_dir_[i] = u;
            // The step the rest of the budget affords; where that is not even the last step's size,
            // the creep ends (a budget shrinking the steps towards zero would never be spent).
            const double afford = inc > 0 && h > 0 ? h * std::sqrt(std::max(creep_budget_ - creep_err_[i], 0.0) / inc)
                                                   : std::numeric_limits<double>::infinity();
            if (creep_err_[i] > creep_budget_ || sn > ws.creep_speed || afford < h) {
                stop_creep(i, sn <= ws.creep_speed);
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
    bool creep_inconsistent(const std::array<Vec2, 3>& slip) {
        Workspace& ws = model_.ws;
        if (!ws.creep || model_.mode.kind != ModeKind::Slide) return false;
        bool off = false;
        for (int i = 0; i < scene_.part.contacts(); ++i) {
            const double sn = slip[i].norm();
            if ((ws.creep >> i & 1u) && sn > kCreepJudged * ws.hint_speed && slip[i].dot(ws.hint[i]) < 0.9 * sn) {
                stop_creep(i, true);
                off = true;
            }
        }
        return off;
    }
    // A creep of contact i begins: its budget, last direction and turning rate start afresh.
    void new_creep(int i) {
        creep_err_[i] = 0;
        creep_dir_[i] = Vec2::Zero();
        model_.ws.creep_rate[i] = 0;
        forget_twist_turn();
    }
    // The twist creep's turn is measured afresh (a creep started or stopped, or a new mode).
    void forget_twist_turn() {
        model_.ws.creep_twist_rate.setZero();
        creep_xi_.setZero();
    }
    // Contact i slides on along v/|v| (spent: not to creep again before its next event); the twist's
    // direction no longer describes every contact.
    void stop_creep(int i, bool spent) {
        model_.ws.creep &= ~(1u << i);
        model_.ws.creep_rate[i] = 0;
        model_.ws.creep_twist.setZero();
        forget_twist_turn();
        if (spent) creep_spent_ |= 1u << i;
    }
    // Entering a mode at state y: in a slide, the contacts at zero slip (just broken away) creep.
    void start_creep(const State& y) {
        Workspace& ws = model_.ws;
        fresh_ = 0;
        ws.creep = 0;
        ws.creep_rate = {};
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
            if (v[i].norm() <= ws.hint_speed && ws.hint[i].norm() > 0) {
                ws.creep |= 1u << i;
                new_creep(i);   // (the direction is solved at the first evaluation)
                creep_h_ = kCreepFirst * scene_.plate.T;
            }
    }

    // Guards at scaled state ys (evaluated: ws already holds the evaluation there).
    void guards(const State& ys, Guards& g) {
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
    bool crossed(int i, double g0, double g1) const {
        const bool slip = i >= 3 && model_.mode.kind == ModeKind::Slide;
        if (slip && (fresh_ >> (i - 3) & 1u)) return false;   // (inside the zero band after a reversal)
        return slip ? (g0 > 0 && g1 <= 0) : (g0 >= 0 && g1 < 0);
    }

    // The state at time t in the last step, scaled (dense output; constant while frozen).
    void dense(double t, double t1, State& out) {
        if (frozen_) { out = ys_; return; }
        stepper_.dense(t, ys_, fs_, t_, ys1_, fs1_, t1, out);
    }

    // First root of guard i in (t_, tb] (tb <= t1, the step's end; gb, yb the guard and the scaled
    // state at tb, where it is crossed) on the step's dense output (events.hpp) to 1e-13 T; yr
    // receives the scaled state at the returned time, where the guard is already violated.
    double locate(int i, double t1, double tb, double gb, const State& yb, State& yr) {
        yr = yb;
        State ym;
        return illinois_first_root(
            t_, tb, g0_[i], gb, 1e-13 * scene_.plate.T, [&](double m) { return guard_at(i, m, t1, ym); },
            [&](double ga, double gm_i) { return crossed(i, ga, gm_i); }, [&] { yr = ym; });
    }

    // A pivot's turn (theta' times its sense, guard 4) that dips through zero and back within one
    // step: the part comes to rest for a moment and turns on the same way, and both ends of the step
    // are positive, so their signs miss it (a thin part of the random stick-slip scenes, seed 562:
    // a 3 ms stuck phase missed by a step of 0.011 T, its cycle 1.9e-5 v_ref off the regularised
    // limit). theta'' at the step's ends (its derivatives, already evaluated) says whether the turn
    // has a minimum inside -- decelerating at the start, accelerating at the end; then that minimum
    // of the dense output is found by golden section (the guard is a state component: no
    // right-hand sides), and where it is crossed it becomes the root's bracket (tb, gb, yb).
    bool turn_dip(double t1, double g1, double& tb, double& gb, State& yb) {
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
            if (gc < gd) { b = d; d = c; gd = gc; c = b - r * (b - a); gc = turn(c); }
            else { a = c; c = d; gc = gd; d = a + r * (b - a); gd = turn(d); }
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
    bool slip_zero(int k, double t, const State& yr) {
        State dy;
        sys(yr, dy, t);
        return model_.ws.slip[k].norm() <= slip_bound(k);
    }
    double slip_bound(int k) const { return std::max(1e-3 * slip0_norm(k), zero_abs_); }
    double slip0_norm(int k) const { return std::abs(g0_[3 + k]); }

    void account(double t1) {
        for (int i = 0; i < 3; ++i)
            if (model_.mode.holds(i)) held_time[i] += t1 - t_;
    }

    // Handles event ev at (t_, ys_): stops (contact lost) or chooses the next mode.
    bool event(int ev) {
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
                    ws.hint[from.k] = f.norm() > 0 ? Vec2(-f / f.norm()) : Vec2::Zero();
                    return enter(Mode{}, y, qd);
                }
                return switch_mode(7, true);   // theta' reached zero: every slip is zero
            case ModeKind::Stuck:
                return switch_mode(7, false);   // the gauge crossed 1: break away
        }
        return true;
    }

    // A lingering slip: held (pivot, stuck) if static friction can hold it there; else slide on.
    bool try_hold(unsigned zero) {
        low_ = {0, 0, 0};
        const State y = this->y();
        Vec3 qd = model_.qd(y);
        const unsigned creep = model_.ws.creep;
        const Vec3 creep_twist = model_.ws.creep_twist, creep_twist_rate = model_.ws.creep_twist_rate;
        const std::array<double, 3> creep_rate = model_.ws.creep_rate;
        const std::array<Vec2, 3> hint = model_.ws.hint;
        const ModeChoice c = choose_mode(scene_, model_.level, model_.q(y), qd, model_.plate(t_, y), zero, model_.ws);
        if (!c.lost && c.mode.kind != ModeKind::Slide) return enter(c.mode, y, qd);
        // Not held: wait twice as long before the next try (each costs a mode choice).
        for (int i = 0; i < 3; ++i)
            if (zero >> i & 1u) linger_need_[i] = std::min(2 * linger_need_[i], 1 << 20);
        model_.ws.creep = creep;
        model_.ws.creep_twist = creep_twist;
        model_.ws.creep_twist_rate = creep_twist_rate;
        model_.ws.creep_rate = creep_rate;
        model_.ws.hint = hint;
        set(y);   // nothing changes: restore the workspace
        return true;
    }

    // Chooses the mode at (t_, ys_) with the contacts `zero` at zero slip and goes on in it.
    bool switch_mode(unsigned zero, bool hold) {
        const State y = this->y();
        Vec3 qd = model_.qd(y);
        const ModeChoice c = choose_mode(scene_, model_.level, model_.q(y), qd, model_.plate(t_, y), zero, model_.ws, hold);
        if (c.lost) return lose(c.lost_contact);
        const bool reversal = model_.mode.kind == ModeKind::Slide && c.mode.kind == ModeKind::Slide;
        if (reversal) ++stats.slip_reversals;
        const bool ok = enter(c.mode, y, qd);
        // A slip that reached zero and slides on (static friction cannot hold it) is not tested for
        // zero again until it has left the zero band (|v| > zero_abs_): at the noise floor right
        // after a reversal its guard crosses zero over and over (heave_yaw at (0, 0.02, 0), rtol 1e-9:
        // 1 500 reversals of two contacts within 1e-5 T). A slip that stays in the band lingers and
        // is offered to static friction by try_hold, with its backoff.
        if (reversal) fresh_ |= zero;
        return ok;
    }

    // Goes on from state y (physical units) with twist qd in mode m.
    bool enter(const Mode& m, State y, const Vec3& qd) {
        const Mode from = model_.mode;
        model_.mode = m;
        model_.set_qd(y, qd);
        start_creep(y);
        set(y);
        log_event(from);
        return check_burst();
    }

    // Contact k is lost at (t_, ys_).
    bool lose(int k) {
        stop = StopEvent{StopReason::ContactLost, k, t_};
        sys(ys_, fs_, t_);
        n_ = model_.ws.n;
        return false;
    }

    bool check_burst() {
        if (burst_ > kBurst) {
            stop = StopEvent{StopReason::EventAccumulation, -1, t_};
            return false;
        }
        return true;
    }

    bool collect_ = false;                  // in a step: note the hold guards at its stages
    std::array<double, 5> stage_min_{}, stage_t_{};
    std::array<double, 3> creep_err_{};
    std::array<Vec2, 3> creep_dir_ = zeros<Vec2>();
    Vec3 creep_xi_ = Vec3::Zero();   // the twist creep's direction at the last step's end (zero: none)
    double creep_budget_ = 0, creep_t_ = 0;
    unsigned creep_spent_ = 0;
    double creep_h_ = std::numeric_limits<double>::infinity();
    static constexpr double kCreepFirst = 1e-4;   // the first step of a creep, relative to T
    // creep_inconsistent judges a creeping slip's direction only above this many hint_speeds: below, a
    // slip is within a few times the integration's noise and so is its direction (heave_yaw at
    // (0, 0.02, 0), rtol 1e-9: a rim-sliding slip at ~1.5 hint speeds stopped its creep after every
    // step, 2.2e7 right-hand sides for the cycle; now 2.5e5; 10 let a creep run on where it no longer
    // held, 1.2e-6 v_ref off the regularised reference).
    static constexpr double kCreepJudged = 4;
    static constexpr int kBurst = 1000;
    static constexpr int kLinger = 4;
    // A step whose slips all exceed this (relative to v_ref) may take IntegrationOptions::large_slip_factor
    // rtol: three times the creep speed (fig6's field, factor 10: 1e-2 and 3e-2 save alike, 1e-1 a third less).
    static constexpr double kLargeSlip = 3e-2;
    // ... but no looser than 1e-6 (and never tighter than rtol): fig4's cycle at (0.02, -0.01, 0.5),
    // shot at rtol 1e-6 from 0.05 v_ref off, 8.9 cycle tolerances off without the cap, 0.27 with it.
    static constexpr double kLargeSlipRtolCap = 1e-6;
    std::array<int, 3> low_{};
    std::array<double, 3> slip_prev_{}, slip_prev2_{};
    std::array<int, 3> linger_need_{kLinger, kLinger, kLinger};
    static constexpr int kRecreep = 16;   // steps below zero_abs_ before a spent creep restarts
    // ... doubling after each restart up to this many. A sustained slide at the rim (a circular drive
    // at mu g (1 + 3e-8): the slip under 1e-9 m/s for periods, the creep's budget spent every third
    // of a period) took 1.2e7 steps for 0.1 s with a cap of 2^20 -- stiff stretches of up to 2^20
    // steps between creeps -- and 2 061 with 64 (its slip 2e-10 m/s apart, ~rtol v_ref); measured before
    // the creeps carried the slip's turn (creep_rate: 26 steps since, point and rigid parts).
    static constexpr int kRecreepMax = 64;
    std::array<int, 3> recreep_need_{kRecreep, kRecreep, kRecreep};
    std::array<int, 3> slow_{};
    std::array<double, 3> slow_from_{};   // the slip when slow_ began counting
    Model& model_;
    const Scene& scene_;
    IntegrationOptions opt_;
    Dopri5Controller<State> stepper_;
    State scale_{}, inv_scale_{}, ys_{}, fs_{}, ys1_{}, fs1_{}, last_y_{};
    double t_ = 0, dt_ = 0, last_t_ = std::numeric_limits<double>::quiet_NaN();
    double v_ref_ = 0, h_min_ = 0, zero_abs_ = 0;
    bool frozen_ = false;
    Guards g0_{};
    unsigned fresh_ = 0;   // contacts sliding on from a reversal, still inside the zero band
    std::array<Vec2, 3> ref_ = zeros<Vec2>();
    Vec3 n_ = Vec3::Zero();
    int burst_ = 0;
    double last_event_t_ = -std::numeric_limits<double>::infinity();
};

}  // namespace plate::detail
