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
    // right-hand side. The error norm is max_i |err_i| / (rtol (1 + max(|y_i|, |y1_i|))), not odeint's
    // default rtol (1 + |y_i| + dt |y'_i|): a tolerance that grows with the step would stop the error
    // scaling as dt^5, and the controller would overshoot. The step size follows the PI controller of
    // Hairer & Wanner's DOPRI5 (Solving ODEs I, II.4; beta = 0.04, safety 0.9, factors in [0.2, 10]).
    // On success t1 += dt and dt becomes the next step; on failure dt becomes the step to retry with.
    // (docs/decisions.md, Our own Dormand-Prince 5(4) stepper, with a step-independent error norm)
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
        const double fac = std::clamp(std::exp(expo * log_err - beta * log_err_old_) / 0.9, 0.1, 5.0);
        log_err_old_ = std::max(log_err, std::log(1e-4));
        t1 += dt;
        dt /= fac;
        return true;
    }

    // The state at t in the step from (t0, y0, f0) to (t1, y1, f1): Dormand-Prince's fourth-order
    // interpolant (no re-stepping).
    void dense(double t, const State& y0, const State& f0, double t0, const State& y1, const State& f1, double t1, State& out) {
        stepper_.calc_state(t, out, y0, f0, t0, y1, f1, t1);
    }

private:
    boost::numeric::odeint::runge_kutta_dopri5<State> stepper_;
    State err_{};
    double log_err_old_ = std::log(1e-4);
};

}   // namespace plate::detail
