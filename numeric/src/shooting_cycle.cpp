#include "cycle_solvers.hpp"
#include "engine.hpp"
#include "models.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace plate {
namespace {

using detail::at_stuck_floor;
using detail::one_period;
using detail::PeriodResult;
using detail::record_modes;
using detail::stuck_during;
using detail::twist_scale;

// Newton shooting on G(x) = P(x) - x in the scaled twist: x+ = x + (I - M)^-1 (P(x) - x), with the
// monodromy M = dP/dx from the variational equations along the first period, then chord steps with
// that M (plain periods); a step that contracts by less than half refreshes M at its start. The
// periods run on one engine, so the step size carries over from period to period.
//
// Stopping: the twist is the average over the period from x_k plus (d xi_a/dx) delta_k, i.e. the
// average at x_{k+1} to first order, so its error is |d xi_a/dx| times the distance of x_{k+1} from
// the cycle. With theta = |delta_k| / |delta_{k-1}| the observed contraction, that distance is
// taken as 2 theta/(1 - 2 theta) |delta_k| (see the loop for the 2). Measured on fig4, where a line's
// first point starts 0.025 v_ref from its cycle: theta alone under-estimated the error 5x there.
// A step sequence that does not contract gives up (the caller falls back to Anderson).
//
// Across a change of contact mode (a period that starts held, or in which a contact sticks, pivots
// or breaks away) the sliding variational equations do not hold: the monodromy then takes a
// saltation at every switch (a projection onto the held contact's constraint where a slip reaches
// zero, a jump from the shifted break-away time where one starts), and a full stick makes it zero.
// Instead of those matrices we take their product, the derivative of the period map itself, by
// forward differences of P (one_period from x + h e_j, h = 1e-4 of the scales): the map is
// continuous and piecewise smooth, so the chord is as good as the exact monodromy for Newton, and
// its error (h |P''| + rtol/h ~ 1e-4) only slows the contraction, which the stopping rule measures.
// It costs one period per unknown; Anderson's fallback cost 9 periods per sticking cycle from a
// neighbour's warm start on fig6 (its contraction estimate drowns in noise near the cycle).
// A pivot cuts that to one period: while contact k is held the twist has one free component, so
// P(x) = g(phi(x)) through a scalar and M = a b^T has rank one (fig6's 62 difference monodromies in
// its field: second singular value below 1e-5 of the first in 55, at most 0.9 %). Its range a is the
// image curve's direction; from x on that curve (x the previous period's end) x* is on it too, so
// the residual r = P(x) - x lies along a, and r is an eigenvector: M r = lambda r, lambda = b^T a.
// One difference along u = r/|r| gives lambda and Pa u, all Newton needs: delta = r / (1 - lambda),
// and the twist's correction Pa delta = (Pa u) |delta|. It is taken when the difference confirms it
// (M u along u within 5 %; the three differences otherwise) and kept for the chord steps after it
// (a pivot-free period or a stalled contraction refreshes as before); the error estimate then uses
// Pa u, the sensitivity along the line on which the iterates stay (fig6's full differences: |Pa| at
// most 1.72 |Pa u|), and nothing is accepted while the residual leaves the line by more than tol / 10
// (see the loop). Measured on fig6's 7^3 field: right-hand sides 2.05e6 -> 1.84e6, periods 1 492 ->
// 1 410, 0.177 -> 0.157 s on two threads; its largest errors against the rtol-1e-11 reference
// unchanged (1.66e-7 v_ref sliding, 6.63e-7 sticking; median of the sticking ones 4.2e-8 -> 3.5e-8).
constexpr double kDifferenceMonodromyNear = 3e-2;   // |P(x) - x| / scale below which (see the loop)
constexpr int kPlainPeriodsMax = 20;                // plain periods toward a switching cycle, then Anderson
constexpr double kPaError = 0.02;                   // relative error allowed for Pa (and M) in the estimates

// One shooting_cycle: the engine, the iterate x and its monodromy, and what the stages of a period
// share -- its integration with the variational equations, the full stick's acceptance, the
// monodromy by differences and the Newton (or chord) step with its acceptance.
struct Shooting : detail::CycleRun {
    Workspace jws;   // the Jacobian's own workspace: the engine's holds its last evaluation
    const Vec3 S;
    const int nc;
    const bool point;
    LimitCycleSummary out;
    Vec3 x;
    bool refresh = true;
    bool reset_prev = false;                                      // the last period stuck fully (its end is the cycle's start)
    double res_floor = std::numeric_limits<double>::infinity();   // its return, if it began fresh too
    Stats fd_stats;                                               // the difference monodromies' periods
    int fd_periods = 0;
    int plain_periods = 0;
    Mat3 M = Mat3::Zero(), Pa = Mat3::Zero();
    bool loose;
    bool on_curve = false;      // x is the previous period's end (on the period map's image)
    Vec3 line = Vec3::Zero();   // with a rank-one M: its range, along which the iterates stay
    double d_prev = std::numeric_limits<double>::infinity();
    // The period just integrated (integrate): its integration options (the difference periods run
    // with them too), whether it ran tight, its mode at the start, its least normal force and the
    // variational monodromy Phi and its integral Psi.
    IntegrationOptions io;
    bool io_tight = true;
    Mode start_mode;
    double min_n = 0;
    Mat3 Phi, Psi;

    Shooting(const Scene& sc, const Vec3& q0, const LimitCycleOptions& opt, const Vec3& qd0)
        : CycleRun(sc, q0, opt),
          S(twist_scale(sc)),
          nc(sc.part.contacts()),
          point(sc.part.point),
          x(point ? Vec3(qd0[0], qd0[1], 0) : qd0),
          loose(opt.integration.large_slip_factor != 1) {}

    bool integrate(int k);
    bool after_full_stick(int k, const State& z, const Vec3& r_now, bool accept);
    bool update_monodromy(const State& z, const Vec3& r_now, bool switched);
    bool newton_step(int k, const State& z, const Vec3& r_now, bool accept);
    void finish();
};

// Period k from x (on a fresh engine at the first and after a full stick); false if it stopped or
// spent the budget.
bool Shooting::integrate(int k) {
    const State y{x[0], x[1], x[2], 0, 0, 0};
    io = opt.integration;
    if (!loose || (k == 0 && opt.first_period_tight)) io.large_slip_factor = 1;
    io_tight = io.large_slip_factor == 1;
    e.set_large_slip_factor(io.large_slip_factor);
    bool ok = true;
    // After a full stick the next period starts on a fresh engine (its first step small again):
    // one carried over from a far start can step over a brief pivot (an outside audit found a
    // cycle 4.7e-6 v_ref off that way), and that period is the one accepted below.
    if (k == 0 || reset_prev)
        ok = e.start(k * T, y);
    else
        e.modify([&](auto& z) { z = y; });
    // The variational equations Phi' = J(t) Phi, Psi' = Phi (J = d q''/d q', generated) on the
    // engine's accepted steps by the trapezoidal rule, J at each step's end: second order,
    // within 1% of central differences of the period map on fig4, fig5 and fig3 (tests), one
    // Jacobian per step: a chord needs no more, and the error estimate allows for it.
    Phi = Mat3::Identity();
    Psi = Mat3::Zero();
    Mat3 J;
    double t_prev = e.t();
    e.reset_log();
    start_mode = e.mode();
    // The variational equations below are those of sliding; a period that starts held or
    // changes mode takes the difference monodromy instead (above).
    const bool variational = refresh && start_mode.kind == ModeKind::Slide;
    if (variational) twist_jacobian(sc, Dynamics::ReducedU, q0, x, model.plate_at(t_prev), jws, J);
    min_n = e.n().head(nc).minCoeff();
    ok = ok && e.advance((k + 1) * T, [&](double t, const auto& z, const Vec3& n) {
        min_n = std::min(min_n, n.head(nc).minCoeff());
        if (!variational) return;
        const double h = t - t_prev;
        Mat3 J1;
        twist_jacobian(sc, Dynamics::ReducedU, q0, model.qd(z), model.plate_at(t), jws, J1);
        const Mat3 Phi1 = (Mat3::Identity() - 0.5 * h * J1).inverse() * ((Mat3::Identity() + 0.5 * h * J) * Phi);
        Psi += 0.5 * h * (Phi + Phi1);
        Phi = Phi1;
        J = J1;
        t_prev = t;
    });
    out.periods = k + 1 + fd_periods;
    if (!ok) return false;
    if (e.stats.rhs_evals + fd_stats.rhs_evals + jws.evals > opt.max_rhs_evaluations) {
        e.stop = StopEvent{StopReason::StepLimit, -1, e.t()};
        return false;
    }
    return true;
}

// A period in which the part was stuck as a whole forgets its start: P is constant near x,
// so M = 0 exactly and P(x) is the cycle's start (to the integration's noise). The period
// after it, from P(x), is then the cycle: when it sticks fully too, it is converged (true).
bool Shooting::after_full_stick(int k, const State& z, const Vec3& r_now, bool accept) {
    const double res = r_now.cwiseAbs().maxCoeff();
    if (k >= 1 && reset_prev && accept && (res <= opt.tol || at_stuck_floor(res, res_floor, opt))) {
        // This period ran on a fresh engine from the previous one's end, and returns to its
        // start within tol, or within tol plus the zero band where the return has stopped
        // halving (the integration's error, which more periods do not shrink: one_start,
        // limit_cycle.cpp): the cycle.
        out.twist = Vec3(z[3], z[4], z[5]) / T;
        out.qd_start = x;
        out.residual = res;
        out.error_estimate = res;
        out.min_normal_force = min_n;
        out.has_monodromy = true;   // dP/dx = 0: every Floquet multiplier is 0
        out.monodromy.setZero();
        out.converged = true;
        return true;
    }
    res_floor = reset_prev && accept ? res : std::numeric_limits<double>::infinity();
    reset_prev = true;
    on_curve = true;
    x = model.qd(z);
    d_prev = std::numeric_limits<double>::infinity();
    refresh = true;
    return false;
}

// M and Pa at x where they are refreshed: one difference along the residual (a rank-one M), three
// differences (a period that changed mode) or the variational Phi and Psi; false if a difference
// period stopped.
bool Shooting::update_monodromy(const State& z, const Vec3& r_now, bool switched) {
    if (refresh) line.setZero();
    const double h = 1e-4;   // the differences' step, relative to the scales
    if (refresh && switched && on_curve && !point && r_now.norm() > 0 &&
        (start_mode.kind == ModeKind::Pivot ||
         std::any_of(e.events.begin(), e.events.end(), [](const ModeEvent& m) { return m.to.kind == ModeKind::Pivot; }))) {
        // The rank-one monodromy (above): one difference along the residual.
        const Vec3 u = r_now.normalized();
        const PeriodResult pu = one_period(sc, q0, x + h * u.cwiseProduct(S), io, fd_stats);
        ++fd_periods;
        ++out.periods;
        if (!pu.ok) return false;
        const Vec3 dP = (pu.end - model.qd(z)).cwiseQuotient(S) / h;
        const double lambda = dP.dot(u);
        if ((dP - lambda * u).norm() <= 0.05 * dP.norm()) {
            M = lambda * u * u.transpose();
            Pa = (pu.average - Vec3(z[3], z[4], z[5]) / T).cwiseQuotient(S) / h * u.transpose();
            line = u;
        }
    }
    if (refresh && switched && line.isZero()) {
        // Forward differences of the period map (and of its average) in the scaled twist.
        const Vec3 end = model.qd(z), avg = Vec3(z[3], z[4], z[5]) / T;
        bool fd_ok = true;
        on_curve = false;   // the Newton step below leaves the image curve
        M.setZero();
        Pa.setZero();
        for (int j = 0; j < (point ? 2 : 3) && fd_ok; ++j) {
            Vec3 xj = x;
            xj[j] += h * S[j];
            const PeriodResult pj = one_period(sc, q0, xj, io, fd_stats);
            fd_ok = pj.ok;
            M.col(j) = (pj.end - end).cwiseQuotient(S) / h;
            Pa.col(j) = (pj.average - avg).cwiseQuotient(S) / h;
        }
        fd_periods += point ? 2 : 3;
        out.periods += point ? 2 : 3;
        if (!fd_ok) return false;
    } else if (refresh && line.isZero()) {
        on_curve = false;
        M = S.asDiagonal().inverse() * Phi * S.asDiagonal();
        Pa = S.asDiagonal().inverse() * Psi * S.asDiagonal() / T;
    }
    return true;
}

// The Newton (or chord) step from x with M, and its acceptance; false when the iteration ends
// (converged, or giving up to Anderson).
bool Shooting::newton_step(int k, const State& z, const Vec3& r_now, bool accept) {
    const bool was_fresh = refresh;
    refresh = false;
    const Vec3& r = r_now;
    Mat3 A = Mat3::Identity() - M;
    if (point) {   // no rotation: the third component is not an unknown
        A.row(2).setZero();
        A.col(2).setZero();
        A(2, 2) = 1;
    }
    const Vec3 delta = A.partialPivLu().solve(r);
    const double dn = delta.cwiseAbs().maxCoeff();
    // A step beyond a quarter of the slip-speed scale means a Floquet multiplier near 1 (or a
    // start far from the cycle): Newton is no better than its linearisation there. Where the map
    // contracts strongly (every multiplier below 1/2) the step is still better than a plain period
    // (fig6's field: neighbours' warm starts 0.3-0.9 of the scale off, which sent 1 in 3 of its
    // configurations back to Anderson from the start): take it and linearise afresh at its end.
    // Otherwise give up.
    if (!(dn <= 0.25)) {
        if (!std::isfinite(dn) || !was_fresh || M.eigenvalues().cwiseAbs().maxCoeff() >= 0.5) return false;
        x += delta.cwiseProduct(S);
        refresh = true;
        d_prev = std::numeric_limits<double>::infinity();   // no contraction measured across it
        return true;
    }
    out.twist = Vec3(z[3], z[4], z[5]) / T + (Pa * delta).cwiseProduct(S);
    out.qd_start = x + delta.cwiseProduct(S);   // the Newton estimate of the cycle's start
    out.residual = r.cwiseAbs().maxCoeff();
    out.min_normal_force = min_n;
    out.has_monodromy = true;
    out.monodromy = M;
    // With a monodromy fresh at this start, dn is the linear estimate of the start's distance
    // from the cycle; the twist's error is at most |d xi_a/dx| times it (before the correction
    // Pa delta, which leaves only its second-order remainder), doubled for a difference
    // monodromy's or a nonlinearity's error. Near the cycle this ends a warm start after one
    // period (the period map's noise, ~rtol v_ref per switch, left the contraction
    // theta below unmeasurable there).
    // (And the start itself within tol of the cycle, for the warm starts it gives: dn to first
    // order, which the monodromy's error, ~2% as below, leaves.)
    // With a rank-one M the residual's part off its line, r_perp, is taken as it stands (M has no
    // component there, which is exact for the step: the true M's range is the line) but Pa u leaves
    // out the twist's sensitivity across the line (|Pa| <= 1.72 |Pa u|, with |Pa| <= 0.7, on fig6):
    // nothing is accepted before r_perp is below a tenth of tol. It falls quadratically (the map
    // puts every start on its image curve; r_perp is that curve's bend over the last step).
    const bool on_line = line.isZero() || (r - line * line.dot(r)).norm() <= 0.1 * opt.tol;
    if (accept && was_fresh && on_line && 2 * Pa.cwiseAbs().rowwise().sum().maxCoeff() * dn <= opt.tol &&
        kPaError * dn <= opt.tol) {
        out.error_estimate = 2 * Pa.cwiseAbs().rowwise().sum().maxCoeff() * dn;
        out.converged = true;
        return false;
    }
    if (k >= 1 && std::isfinite(d_prev)) {   // (not after a full stick: no previous step)
        const double theta = d_prev > 0 ? dn / d_prev : 0.0;
        out.contraction = theta;
        // The next step contracts by about theta again on a chord, by less under Newton; but a
        // chord step after a fresh monodromy at the previous start contracts by up to 2 theta
        // (the monodromy it uses is then one step stale). The twist's error is the start's
        // times |d xi_a/dx| (max-row-sum norm).
        if (2 * theta < 1) {
            // Plus the correction Pa delta's own error: the variational Pa is about 1% off
            // (trapezoidal rule on the engine's steps), which an outside audit found left a
            // chord-accepted twist 1e-6 v_ref off with an estimate of 7e-8.
            const double dist = 2 * theta / (1 - 2 * theta) * dn;
            out.error_estimate = Pa.cwiseAbs().rowwise().sum().maxCoeff() * (dist + kPaError * dn);
            if (accept && on_line && out.error_estimate <= opt.tol) {
                out.converged = true;
                return false;
            }
        }
        if (theta > 0.5) {
            if (was_fresh) return false;   // even a fresh monodromy does not contract: give up
            refresh = true;                // a stale chord: refresh M at this start
        }
    }
    x += delta.cwiseProduct(S);
    d_prev = dn;
    return true;
}

void Shooting::finish() {
    out.stop = e.stop;
    out.stats = e.stats;
    out.stats += fd_stats;              // the difference monodromies' periods
    out.stats.rhs_evals += jws.evals;   // the Jacobians' evaluations
    out.step_hint = e.next_step() / T;
    if (!out.converged && out.stop.reason == StopReason::None) out.stop = StopEvent{StopReason::NotConverged, -1, e.t()};
    if (!out.converged) out.twist.setConstant(std::numeric_limits<double>::quiet_NaN());
}

}   // namespace

LimitCycleSummary detail::shooting_cycle(const Scene& sc, const Vec3& q0, const LimitCycleOptions& opt, const Vec3& qd0) {
    Shooting s(sc, q0, opt, qd0);
    for (int k = 0; k < opt.max_periods; ++k) {
        if (!s.integrate(k)) break;
        const auto z = s.e.y();
        const Vec3 r_now = (s.model.qd(z) - s.x).cwiseQuotient(s.S);   // the residual P(x) - x, scaled
        record_modes(s.out, s.e, s.start_mode, k * s.T, s.T);
        const bool switched = s.start_mode.kind != ModeKind::Slide || !s.e.events.empty();
        // A period that changed mode is accepted only if it ran tight, and so are the ones after it.
        const bool accept = !(switched && !s.io_tight);
        if (switched) s.loose = false;
        const bool full_stick = s.start_mode.kind == ModeKind::Stuck || stuck_during(s.e.events);
        if (full_stick) {
            if (s.after_full_stick(k, z, r_now, accept)) break;
            continue;
        }
        s.reset_prev = false;
        // A difference monodromy pays only near enough to the cycle, where Newton then ends in a
        // step or two; further off (a poor warm start in a field) plain periods approach it first
        // (Anderson from the warm start itself once took 56 periods for one of them). The right-hand
        // sides of fig6's 78 sticking cycles in its 7^3 field, by threshold: 3e-4 1.56e6, 1e-3 1.41e6,
        // 3e-2 1.18e6, 1e-1 1.15e6, differences at every start 1.40e6 (the whole field 2.05e6 at
        // 3e-2, 2.29e6 at 1e-3).
        if (s.refresh && switched && r_now.cwiseAbs().maxCoeff() > kDifferenceMonodromyNear) {
            if (++s.plain_periods > kPlainPeriodsMax) break;   // slow or alternating: Anderson's
            s.x = s.model.qd(z);
            s.on_curve = true;
            s.d_prev = std::numeric_limits<double>::infinity();
            continue;
        }
        if (!s.update_monodromy(z, r_now, switched)) break;
        if (!s.newton_step(k, z, r_now, accept)) break;
    }
    s.finish();
    return s.out;
}

}   // namespace plate
