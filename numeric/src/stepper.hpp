// Internal: the engine's stepping -- one Dormand-Prince 5(4) step (Boost.Odeint's FSAL stepper) on
// a scaled state under a PI step-size controller, and the step's dense output. Knows nothing of
// contacts, modes or events (engine.hpp drives it).
#pragma once

#include <boost/numeric/odeint.hpp>

#include <algorithm>
#include <cmath>

namespace plate::detail {

template <class State>
class Dopri5Controller {
public:
    // One step of size dt from (t, y, f = y'(t)) into (y1, f1 = y'(t + dt)); sys(y, dy, t) is the
    // right-hand side. The error norm is max_i |err_i| / (rtol (1 + max(|y_i|, |y1_i|))). odeint's
    // default checker divides by rtol (1 + |y_i| + dt |y'_i|) instead: a tolerance that grows with
    // the step, so the error no longer scales as dt^5 and its controller overshoots (29% of fig4's
    // field steps rejected). The step size follows the PI controller of Hairer & Wanner's DOPRI5
    // (Solving ODEs I, II.4; beta = 0.04, safety 0.9, factors in [0.2, 10]); with set_predictive,
    // capped after an accepted step by Gustafsson's predictive factor (Solving ODEs II, IV.8, as
    // RADAU5 does): where the accepted steps' errors grow from step to step, the next step shrinks by
    // that trend in advance. The PI controller alone lags wherever the steps must keep shrinking --
    // the approach of a slip to zero, where the step falls about as the slip, and the periodic
    // motion's own shrinking phases: it rejected 21 % of fig6's field's step tries (22 % of its
    // right-hand sides), mostly single rejections just above the tolerance; with the cap 7 %, and the
    // field 1.20e6 -> 1.05e6 right-hand sides (1.06e6 with the hold threshold of engine.hpp). On
    // success t1 += dt and dt becomes the next step; on failure dt becomes the step to retry with.
    template <class Sys>
    bool try_step(Sys&& sys, const State& y, const State& f, double& t1, State& y1, State& f1, double& dt, double rtol) {
        stepper_.do_step(sys, y, f, t1, y1, f1, dt, err_);
        double err = 0;
        for (std::size_t i = 0; i < err_.size(); ++i)
            err = std::max(err, std::abs(err_[i]) / (rtol * (1 + std::max(std::abs(y[i]), std::abs(y1[i])))));
        if (!std::isfinite(err)) {
            dt *= 0.2;
            return false;
        }
        // err^expo / err_old^beta through logarithms: one log and one exp per step, not two pows.
        constexpr double beta = 0.04, expo = 0.2 - 0.75 * beta;
        const double log_err = std::log(std::max(err, 1e-16));
        if (err > 1) {
            dt /= std::min(5.0, std::exp(expo * log_err) / 0.9);
            return false;
        }
        double fac = std::clamp(std::exp(expo * log_err - beta * log_err_old_) / 0.9, 0.1, 5.0);
        if (predictive_ && h_acc_ > 0) {
            // Gustafsson: (h_acc / h) (err^2 / err_acc)^(1/5) / 0.9, err_acc the last accepted step's
            // (at least 1e-2), h_acc its size; the smaller of the two steps proposed.
            const double gus = std::exp(0.2 * (2 * log_err - log_err_acc_)) * (h_acc_ / dt) / 0.9;
            fac = std::max(fac, std::clamp(gus, 0.1, 5.0));
        }
        h_acc_ = dt;
        log_err_acc_ = std::max(log_err, std::log(1e-2));
        log_err_old_ = std::max(log_err, std::log(1e-4));
        t1 += dt;
        dt /= fac;
        return true;
    }

    void set_predictive(bool on) { predictive_ = on; }   // IntegrationOptions::predictive_steps

    // The state at t in the step from (t0, y0, f0) to (t1, y1, f1): Dormand-Prince's fourth-order
    // interpolant (no re-stepping).
    void dense(double t, const State& y0, const State& f0, double t0, const State& y1, const State& f1, double t1,
               State& out) {
        stepper_.calc_state(t, out, y0, f0, t0, y1, f1, t1);
    }

private:
    boost::numeric::odeint::runge_kutta_dopri5<State> stepper_;
    State err_{};
    double log_err_old_ = std::log(1e-4);
    double h_acc_ = 0, log_err_acc_ = 0;   // the last accepted step and its log error (Gustafsson)
    bool predictive_ = false;
};

}  // namespace plate::detail
