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
//
// The class is declared here; its definitions are in four parts, compiled once per model in
// engine.cpp (the three models of models.hpp):
//   engine_step.hxx    the loop: a step, its acceptance, the slide guards' reference directions
//   engine_events.hxx  the guards of each mode, and the location of the first one crossed in a step
//   engine_modes.hxx   what an event means and which mode comes next: starts, restarts, holds
//   engine_creep.hxx   creep: a contact that breaks away slides along its consistent direction
#pragma once

#include "events.hpp"
#include "plate/modes.hpp"
#include "plate/simulate.hpp"
#include "stepper.hpp"
#include "workspace.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <type_traits>
#include <utility>
#include <vector>

namespace plate::detail {

// The zero band, relative to v_ref: a slip below it counts as zero (a lingering slip is offered to
// static friction), so it bounds the engine's error in a slip -- and in a cycle's start after a stick.
// Ten times narrower where some contact's static friction exceeds its kinetic friction (`hysteresis`):
// there a slip taken as zero is held by the static disk where the slip itself would have gone on at the
// kinetic one, so the band's error is not a small slip but another motion (docs/decisions/engine.md,
// "The zero band under static friction").
inline double zero_band(double rtol, bool hysteresis = false) { return std::clamp((hysteresis ? 3e1 : 3e2) * rtol, 1e-9, 3e-3); }

// A non-owning reference to a callable with signature R(A...): Engine::advance's step observer,
// so that the loop is compiled once per model and not once per observer. It must not outlive the
// callable (a lambda passed to advance lives until advance returns).
template <class Sig>
class FunctionRef;
template <class R, class... A>
class FunctionRef<R(A...)> {
public:
    template <class F, class = std::enable_if_t<!std::is_same_v<std::decay_t<F>, FunctionRef>>>
    FunctionRef(F&& f)
        : obj_(const_cast<void*>(static_cast<const void*>(std::addressof(f)))),
          call_([](void* o, A... a) -> R { return (*static_cast<std::add_pointer_t<F>>(o))(std::forward<A>(a)...); }) {}
    R operator()(A... a) const { return call_(obj_, std::forward<A>(a)...); }

private:
    void* obj_;
    R (*call_)(void*, A...);
};

// Model concept: State, level, ws, mode; rhs(t, y, dy) in physical units, in the model's mode (fills
// ws); q(y), qd(y), set_qd(y, qd); plate(t, y) -> PlateState; scale() -> State of characteristic
// magnitudes; kStuckFrozen: nothing in the state moves while the part is stuck.
template <class Model>
class Engine {
public:
    using State = typename Model::State;
    static constexpr int kGuards = 6;   // N_1..N_3, then the mode's own (up to 3)
    using Guards = std::array<double, kGuards>;
    using OnStep = FunctionRef<void(double, const State&, const Vec3&)>;

    Engine(Model& model, const Scene& scene, const IntegrationOptions& opt);

    // Starts at (t0, y0) in physical units; the mode follows from the state (a contact with zero slip
    // is held or breaks away, choose_mode). Returns false with stop set if contact is lost at t0.
    bool start(double t0, const State& y0);

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
    template <class F>
    void modify(F&& f) {
        State y = this->y();
        const Vec3 qd_old = model_.qd(y);
        f(y);
        restart(y, qd_old);
    }
    // Restarts the bookkeeping of held time and mode changes (e.g. at a period's start).
    void reset_log() {
        held_time = {0, 0, 0};
        events.clear();
    }

    // Advances to t_end exactly. on_step(t, y, n) is called after each accepted step and at each
    // event. Returns false if a stop occurred (see `stop`).
    bool advance(double t_end, OnStep on_step);

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
    // The stick-slip state the engine keeps in the model's workspace (hints, creep; workspace.hpp).
    StickSlipState& stick_slip() { return detail::stick_slip(model_.ws); }

    // --- the loop (engine_step.hxx) ---
    // The model's right-hand side on the scaled state ys at t (counts it; in a step, notes the hold
    // guards at its stages).
    void sys(const State& ys, State& dys, double t);
    bool try_step(double& t1, double& dt);   // one step from (t_, ys_) into ys1_, fs1_
    // The earliest located event in the step ending at t1 (guards g1 there): its guard, or -1.
    int first_event(double t1, const Guards& g1, double& t_ev, State& y_ev, bool& swing);
    // Moves to the end of an accepted step without an event; lingering slips are offered to static
    // friction. False if a stop occurred.
    bool accept_step(double t1, const Guards& g1, const Vec3& n1, const std::array<Vec2, 3>& slip1);
    double zero_cap();   // the step that ends just past the first zero of a slip heading for it
    void reference_directions(const std::array<Vec2, 3>& slip);      // of the slide guards, at a step's start
    void rebase(const Guards& g, const std::array<Vec2, 3>& slip);   // the guards' baseline at a new start
    void dense(double t, double t1, State& out);                     // the scaled state at t in the last step
    void account(double t1);                                         // held time up to t1
    double min_n() const { return model_.ws.n.head(scene_.part.contacts()).minCoeff(); }

    // --- guards and events (engine_events.hxx) ---
    void guards(const State& ys, Guards& g);           // at scaled state ys, evaluated there
    bool crossed(int i, double g0, double g1) const;   // has guard i changed sign over the step?
    double locate(int i, double t1, double tb, double gb, const State& yb, State& yr);   // its first root
    void note_stage(double t, const State& y);                                           // the hold guards at a step's stages
    void note_stage_guard(int i, double t, double g);
    bool stage_dip(int i, double t1, double g1, double& tb, double& gb, State& yb);   // a hold lost inside a step
    double guard_at(int i, double t, double t1, State& ym);                           // guard i on the step's dense output
    bool turn_dip(double t1, double g1, double& tb, double& gb, State& yb);           // a pivot's turn through zero and back
    bool slip_zero(int k, double t, const State& yr);   // did contact k's slip reach zero at its root?
    double slip_bound(int k) const { return std::max(1e-3 * slip0_norm(k), zero_abs_); }
    double slip0_norm(int k) const { return std::abs(g0_[3 + k]); }

    // --- modes: starts, events, holds (engine_modes.hxx) ---
    void set(const State& y);                     // sets the state (physical units) and evaluates there
    void restart(State& y, const Vec3& qd_old);   // after modify(): the mode again if the twist changed
    bool classify(State& y);                      // chooses the mode of state y at t_ and sets it
    void log_event(const Mode& from);
    bool event(int ev);                                   // handles event ev at (t_, ys_)
    bool try_hold(unsigned zero);                         // a lingering slip: held if static friction can hold it
    bool switch_mode(unsigned zero, bool hold);           // the mode with the contacts `zero` at zero slip
    bool enter(const Mode& m, State y, const Vec3& qd);   // goes on from y with twist qd in mode m
    bool lose(int k);                                     // contact k is lost at (t_, ys_)
    bool check_burst();

    // --- creep (engine_creep.hxx) ---
    bool creep_step(const std::array<Vec2, 3>& slip);   // after an accepted step of a slide
    bool creep_inconsistent(const std::array<Vec2, 3>& slip);
    void new_creep(int i);
    void forget_twist_turn();
    void stop_creep(int i, bool spent);
    void start_creep(const State& y);   // entering a mode: contacts at zero slip in a slide creep

    // --- the model, the scene and the integration: the state (scaled) and its derivative at the step's
    // start (ys_, fs_) and end (ys1_, fs1_), and the last state evaluated (last_t_, last_y_) ---
    Model& model_;
    const Scene& scene_;
    IntegrationOptions opt_;
    Dopri5Controller<State> stepper_;
    State scale_{}, inv_scale_{}, ys_{}, fs_{}, ys1_{}, fs1_{}, last_y_{};
    double t_ = 0, dt_ = 0, last_t_ = std::numeric_limits<double>::quiet_NaN();
    double v_ref_ = 0, h_min_ = 0, zero_abs_ = 0;
    bool frozen_ = false;     // stuck with nothing moving: the step is on the guards alone
    Vec3 n_ = Vec3::Zero();   // the normal forces at t_

    // --- guards and events ---
    Guards g0_{};                                     // the guards at the step's start
    unsigned fresh_ = 0;                              // contacts sliding on from a reversal, still inside the zero band
    std::array<Vec2, 3> ref_ = zeros<Vec2>();         // the slide guards' directions (reference_directions)
    bool collect_ = false;                            // in a step: note the hold guards at its stages
    std::array<double, 5> stage_min_{}, stage_t_{};   // each hold guard's least value at a stage, and when
    int burst_ = 0;                                   // mode changes in a row within 1e-9 T of each other (check_burst)
    double last_event_t_ = -std::numeric_limits<double>::infinity();
    static constexpr int kBurst = 1000;

    // --- the step that ends just past a slip's zero (zero_cap) ---
    static constexpr double kZeroOvershoot = 1.05;
    std::array<Vec2, 3> slip0_ = zeros<Vec2>();   // the slips at the step's start (reference_directions)
    double cap_theta_ = std::numeric_limits<double>::quiet_NaN();
    std::array<Vec2, 3> cap_r_ = zeros<Vec2>();

    // --- large slips (try_step) ---
    // A step whose slips all exceed this (relative to v_ref) may take IntegrationOptions::large_slip_factor
    // rtol: three times the creep speed.
    static constexpr double kLargeSlip = 3e-2;
    // ... but no looser than 1e-6 (and never tighter than rtol): looser, a shot cycle lands several
    // cycle tolerances off. (docs/decisions.md, Where every slip is large, the shooting steps coarser)
    static constexpr double kLargeSlipRtolCap = 1e-6;

    // --- lingering slips (accept_step) ---
    static constexpr int kLinger = 4;
    std::array<int, 3> low_{};
    std::array<double, 3> slip_prev_{}, slip_prev2_{};
    std::array<int, 3> linger_need_{kLinger, kLinger, kLinger};

    // --- creep (engine_creep.hxx) ---
    std::array<double, 3> creep_err_{};
    std::array<Vec2, 3> creep_dir_ = zeros<Vec2>();
    Vec3 creep_xi_ = Vec3::Zero();   // the twist creep's direction at the last step's end (zero: none)
    double creep_budget_ = 0, creep_t_ = 0;
    unsigned creep_spent_ = 0;
    double creep_h_ = std::numeric_limits<double>::infinity();
    static constexpr double kCreepFirst = 1e-4;   // the first step of a creep, relative to T
    // creep_inconsistent judges a creeping slip's direction only above this many hint_speeds: below, a
    // slip is within a few times the integration's noise and so is its direction: judged there, a
    // rim-sliding slip would stop its creep after every step; judged only far above, a creep would run
    // on where it no longer holds. (docs/decisions.md, A creep's direction judged only above four hint
    // speeds)
    static constexpr double kCreepJudged = 4;
    static constexpr int kRecreep = 16;   // steps below zero_abs_ before a spent creep restarts
    // ... doubling after each restart up to this many: a sustained slide at the rim spends a creep's
    // budget again and again, and a larger cap would leave stiff stretches of that many steps between
    // its creeps. (docs/decisions.md, A spent creep restarts, doubling up to 64 steps)
    static constexpr int kRecreepMax = 64;
    std::array<int, 3> recreep_need_{kRecreep, kRecreep, kRecreep};
    std::array<int, 3> slow_{};
    std::array<double, 3> slow_from_{};   // the slip when slow_ began counting
};

}   // namespace plate::detail
