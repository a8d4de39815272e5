// Internal: the adaptive stepping loop shared by trajectories and limit cycles.
// Dormand-Prince 5(4) (Boost.Odeint's FSAL stepper) on a scaled state, so that one scalar
// tolerance is relative for every component, with a PI step-size controller (try_step). After
// each accepted step the normal forces and contact slips are checked (simulate.hpp lists the stops).
#pragma once

#include "plate/simulate.hpp"

#include <boost/numeric/odeint.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>

namespace plate::detail {

namespace odeint = boost::numeric::odeint;

// Model concept: State, kDim, rhs(t, y, dy) (physical units, fills ws), q(y), qd(y),
// plate(t, y) -> PlateState, scale() -> State of characteristic magnitudes.
template <class Model>
class Engine {
public:
    using State = typename Model::State;

    Engine(Model& model, const Scene& scene, const IntegrationOptions& opt)
        : model_(model), scene_(scene), opt_(opt) {
        scale_ = model_.scale();
        for (std::size_t i = 0; i < scale_.size(); ++i) inv_scale_[i] = 1 / scale_[i];
        eps_slip_ = opt_.slip_eps * scene_.v_ref();
        eps_arm_ = 1e-3 * scene_.v_ref();
        h_min_ = opt_.h_min * scene_.plate.T;
    }

    // Starts at (t0, y0) in physical units. Returns false with stop set if contact is lost at t0.
    bool start(double t0, const State& y0) {
        t_ = t0;
        for (std::size_t i = 0; i < y_.size(); ++i) ys_[i] = y0[i] / scale_[i];
        sys(ys_, fs_, t_);
        n_ = model_.ws.n;
        slip_ = model_.ws.slip;
        for (int i = 0; i < 3; ++i) armed_[i] = slip_[i].norm() > eps_arm_;
        dt_ = (opt_.h0 > 0 ? opt_.h0 : std::min(1e-3, 1e-2 * std::cbrt(opt_.rtol))) * scene_.plate.T;
        stats.min_normal_force = min_n();
        stop = StopEvent{};
        if (stats.min_normal_force < 0) {
            stop = StopEvent{StopReason::ContactLost, argmin_n(), t_};
            return false;
        }
        return true;
    }

    double t() const { return t_; }
    double next_step() const { return dt_; }   // the step the controller proposes next [s]
    State y() const {
        State y;
        for (std::size_t i = 0; i < y.size(); ++i) y[i] = ys_[i] * scale_[i];
        return y;
    }
    const Vec3& n() const { return n_; }
    // Overwrites components of the state (e.g. to reset an integral), keeping the time.
    template <class F> void modify(F&& f) {
        State y = this->y();
        f(y);
        for (std::size_t i = 0; i < y.size(); ++i) ys_[i] = y[i] / scale_[i];
        sys(ys_, fs_, t_);
    }

    // Advances to t_end exactly. on_step(t, y, n) is called after each accepted step.
    // Returns false if a stop occurred (see `stop`).
    template <class OnStep>
    bool advance(double t_end, OnStep&& on_step) {
        while (t_ < t_end) {
            if (stats.steps >= opt_.max_steps) {
                stop = StopEvent{StopReason::StepLimit, -1, t_};
                return false;
            }
            const bool clamp = t_ + dt_ >= t_end;
            double dt = clamp ? t_end - t_ : dt_;
            double t1 = t_;
            if (!try_step(t1, dt)) {
                ++stats.rejected;
                dt_ = dt;
                if (dt_ < h_min_) {
                    stop = StopEvent{StopReason::StepCollapse, -1, t_};
                    return false;
                }
                continue;
            }
            if (clamp) t1 = t_end;   // land on t_end exactly despite rounding
            ++stats.steps;
            dt_ = clamp ? std::max(dt_, dt) : dt;
            // Diagnostics at the new point: the FSAL stage evaluated it last.
            if (!(last_t_ == t1 && std::memcmp(last_y_.data(), ys1_.data(), sizeof(ys1_)) == 0))
                sys(ys1_, fs1_, t1);
            n1_ = model_.ws.n;
            slip1_ = model_.ws.slip;
            if (!check(t1)) return false;
            t_ = t1;
            ys_ = ys1_;
            fs_ = fs1_;
            n_ = n1_;
            slip_ = slip1_;
            on_step(t_, y(), n_);
        }
        return true;
    }

    StopEvent stop;
    Stats stats;

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
    }

    // One Dormand-Prince step of size dt from (t_, ys_) into ys1_, fs1_. The error norm is
    // max_i |err_i| / (rtol (1 + max(|y_i|, |y1_i|))). odeint's default checker divides by
    // rtol (1 + |y_i| + dt |y'_i|) instead: a tolerance that grows with the step, so the error no
    // longer scales as dt^5 and its controller overshoots (29% of fig4's field steps rejected).
    // The step size follows the PI controller of Hairer & Wanner's DOPRI5 (Solving ODEs I, II.4;
    // beta = 0.04, safety 0.9, factors in [0.2, 10]). On success t1 += dt and dt becomes the next
    // step; on failure dt becomes the step to retry with.
    bool try_step(double& t1, double& dt) {
        stepper_.do_step(sysref(), ys_, fs_, t1, ys1_, fs1_, dt, err_);
        double err = 0;
        for (std::size_t i = 0; i < err_.size(); ++i)
            err = std::max(err, std::abs(err_[i]) / (opt_.rtol * (1 + std::max(std::abs(ys_[i]), std::abs(ys1_[i])))));
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

    double min_n() const { return model_.ws.n.head(scene_.part.contacts()).minCoeff(); }
    int argmin_n() const {
        int k = 0;
        model_.ws.n.head(scene_.part.contacts()).minCoeff(&k);
        return k;
    }

    // The state one Dormand-Prince step of size tau from the last accepted point; ws is left
    // evaluated there. The step is accurate up to the first event in it: the right-hand side is
    // smooth before it.
    State probe(double tau) {
        State out, dout;
        stepper_.do_step(sysref(), ys_, fs_, t_, out, dout, tau);
        for (std::size_t i = 0; i < out.size(); ++i) out[i] *= scale_[i];
        return out;
    }
    // First root of g (read from ws after a probe) in (t_, t1], with g > 0 at t_ and g <= 0 at
    // t1, by bisection to 1e-14 T. Returns the time; y_at receives the state there.
    template <class G>
    double refine(double t1, G&& g, State& y_at) {
        double a = 0, b = t1 - t_;
        y_at = probe(b);
        for (int it = 0; it < 80 && b - a > 1e-14 * scene_.plate.T; ++it) {
            const double m = 0.5 * (a + b);
            const State ym = probe(m);
            if (g() > 0) a = m;
            else { b = m; y_at = ym; }
        }
        return t_ + b;
    }

    // Event checks over the accepted step [t_, t1]; n1_ and slip1_ hold the evaluation at t1.
    bool check(double t1) {
        const int nc = scene_.part.contacts();
        const Vec3 n1 = n1_;
        // Contact loss: first contact whose N crosses zero (linear interpolation in the step).
        double t_loss = std::numeric_limits<double>::infinity();
        int k_loss = -1;
        for (int i = 0; i < nc; ++i) {
            stats.min_normal_force = std::min(stats.min_normal_force, n1[i]);
            if (n1[i] < 0) {
                const double tl = t_ + (t1 - t_) * n_[i] / (n_[i] - n1[i]);
                if (tl < t_loss) { t_loss = tl; k_loss = i; }
            }
        }
        // Zero slip: closest approach of the slip velocity to zero within the step.
        const auto slip1 = slip1_;
        double t_zero = std::numeric_limits<double>::infinity();
        double lam_zero = 0;
        int zeros = 0, k_zero = -1;
        for (int i = 0; i < nc; ++i) {
            const Vec2 v0 = slip_[i], dv = slip1[i] - slip_[i];
            const double dd = dv.squaredNorm();
            const double lam = dd > 0 ? std::clamp(-v0.dot(dv) / dd, 0.0, 1.0) : 1.0;
            // A contact is armed once its slip has exceeded eps_arm_ since the start or the last
            // event: a start at rest (all slips zero) or a reversal just passed is not a new event.
            if (slip1[i].norm() > eps_arm_) {
                armed_[i] = true;
                band_steps_[i] = 0;
            } else if (++band_steps_[i] > kChatterSteps) {
                // The slip has stayed near zero for many steps: the integrator chatters about
                // v_i = 0, i.e. the Filippov solution slides on v_i = 0 -- the contact sticks.
                stop = StopEvent{StopReason::Sticking, i, t1};
                return false;
            }
            if (armed_[i] && lam > 0 && (v0 + lam * dv).norm() < eps_slip_) {
                ++zeros;
                const double tz = t_ + lam * (t1 - t_);
                if (tz < t_zero) { t_zero = tz; lam_zero = lam; k_zero = i; }
            }
        }
        State y_ev;
        if (k_loss >= 0 && t_loss <= t_zero) {
            if (n_[k_loss] > 0) t_loss = refine(t1, [&] { return model_.ws.n[k_loss]; }, y_ev);
            stop = StopEvent{StopReason::ContactLost, k_loss, t_loss};
            return false;
        }
        if (k_zero >= 0) {
            // Locate the zero of the slip component along its direction at t_ (exact up to the
            // step's local error), unless the slip was already negligible there.
            const Vec2 v0 = slip_[k_zero];
            if (v0.norm() > eps_slip_) {
                const Vec2 dir = v0.normalized();
                const double g0 = v0.dot(dir), g1 = slip1[k_zero].dot(dir);
                if (g1 <= 0) {
                    t_zero = refine(t1, [&] { return model_.ws.slip[k_zero].dot(dir); }, y_ev);
                } else {
                    // Not yet through zero, but below eps_slip: the zero lies just ahead, where
                    // the slip extrapolates (linearly over the step) to zero.
                    t_zero = g0 > g1 ? t1 + g1 * (t1 - t_) / (g0 - g1) : t1;
                    for (std::size_t i = 0; i < y_ev.size(); ++i) y_ev[i] = ys1_[i] * scale_[i];
                }
            } else {
                const State y0 = y();
                for (std::size_t i = 0; i < y_ev.size(); ++i) y_ev[i] = y0[i] + lam_zero * (ys1_[i] * scale_[i] - y0[i]);
            }
            const Vec3 q = model_.q(y_ev), qd = model_.qd(y_ev);
            const PlateState ps = model_.plate(t_zero, y_ev);
            bool sticks;
            if (zeros >= 2 && !scene_.part.point) {
                // Several contacts at zero slip together: could the whole part ride with the plate?
                sticks = stick_test_all(scene_, model_.level, q, qd, ps).sticks;
            } else {
                sticks = stick_test(scene_, model_.level, k_zero, q, qd, ps).sticks;
            }
            if (sticks) {
                stop = StopEvent{StopReason::Sticking, k_zero, t_zero};
                return false;
            }
            ++stats.slip_reversals;
            armed_[k_zero] = false;
        }
        return true;
    }

    Model& model_;
    const Scene& scene_;
    IntegrationOptions opt_;
    odeint::runge_kutta_dopri5<State> stepper_;
    State err_{};
    double log_err_old_ = std::log(1e-4);
    State scale_{}, inv_scale_{}, ys_{}, fs_{}, ys1_{}, fs1_{}, y_{}, last_y_{};
    double t_ = 0, dt_ = 0, last_t_ = std::numeric_limits<double>::quiet_NaN();
    double eps_slip_ = 0, eps_arm_ = 0, h_min_ = 0;
    std::array<bool, 3> armed_{};
    std::array<long, 3> band_steps_{};
    // Accepted steps with a slip below eps_arm_ that count as a stuck contact. A transversal
    // reversal crosses that band in a few steps (dopri5 resolves the kink in ~10-30).
    static constexpr long kChatterSteps = 400;
    Vec3 n_ = Vec3::Zero(), n1_ = Vec3::Zero();
    std::array<Vec2, 3> slip_{}, slip1_{};
};

// Exponential coordinates of the plate orientation: R1 = exp(phi^). With the spatial angular
// velocity omega1 (R1' = omega1^ R1, eq. 7), phi' = dexp_{phi}^{-1} omega1, which keeps R1 on
// SO(3) exactly (R1 is never integrated as nine numbers). |phi| stays far below pi here.
inline Mat3 hat(const Vec3& w) {
    Mat3 W;
    W << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
    return W;
}
inline Mat3 exp_so3(const Vec3& phi) {
    return Eigen::AngleAxisd(phi.norm(), phi.norm() > 0 ? Vec3(phi.normalized()) : Vec3::UnitZ())
        .toRotationMatrix();
}
inline Vec3 dexp_inv(const Vec3& phi, const Vec3& w) {
    const double a = phi.norm();
    // 1/a^2 - (1 + cos a) / (2 a sin a), series 1/12 + a^2/720 + a^4/30240 near 0.
    const double k = a < 1e-3 ? 1.0 / 12 + a * a / 720 + a * a * a * a / 30240
                               : 1 / (a * a) - (1 + std::cos(a)) / (2 * a * std::sin(a));
    return w - 0.5 * phi.cross(w) + k * phi.cross(phi.cross(w));
}

}  // namespace plate::detail
