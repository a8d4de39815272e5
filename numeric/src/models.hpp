// Internal: the three state layouts integrated by the engine (engine.hpp drives any of them).
//   ReducedU (35): y = [q'(3), Q(3)], Q = integral of q' (for the average (36)); q frozen.
//   U (32):        y = [q(3), q'(3)]
//   Full (31):     y = [q(3), q'(3), phi(3)], R1 = exp(phi^)
#pragma once

#include "plate/modes.hpp"
#include "so3.hpp"
#include "workspace.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace plate::detail {

// dynamics.cpp: the reduced U-dynamics' slide without creep, without the mode dispatch (false: not
// taken, call mode_accelerations).
bool reduced_U_slide(const Scene& sc, const Vec3& q, const Vec3& qd, const PlateState& ps, Workspace& ws);

// u(t) (eq. 11) and the plate's velocity regrouped by harmonic number: a sin(n w t + phi) =
// sin(n w t) a cos(phi) + cos(n w t) a sin(phi), so u(t) = sum_n sin(n w t) A_n + cos(n w t) B_n
// with one sine and cosine per distinct n where PlateMotion::acceleration calls sin once per harmonic
// (harmonics often share n). The velocity's -a/k cos(k t + phi) = -(cos(k t) A_n - sin(k t) B_n)/k
// with k = n w.
// The sine and cosine of phi = n w t: phi = j pi/8 + x with j the nearest multiple (Cody-Waite, pi/8
// split so that j times its head, 31 significant bits, is exact for |j| < 2^20) and |x| <= pi/16, then
// sin(j pi/8 + x) from a table of sixteen and Taylor polynomials in x (the first terms left out,
// x^13/13! and x^12/12!, below 1.1e-19 and 6.9e-18 = 0.03 ulp of 1 there) -- the
// same argument fl(n w t) libm's sincos takes, to a few ulp, and deterministic in t (a cache of the
// last call would make u(t) depend on the order of calls, and a field on its threads), and cheaper
// than libm's sincos; tests/test_dynamics.cpp compares it with PlateMotion. (docs/decisions.md,
// u(t) regrouped by harmonic number; u(t)'s sine and cosine from a table)
class Signal {
public:
    explicit Signal(const PlateMotion& p) : w_(p.omega()) {
        for (const auto& h : p.harmonics) {
            auto it = terms_.begin();
            while (it != terms_.end() && it->n != h.n) ++it;
            if (it == terms_.end()) it = terms_.insert(it, Term{h.n, Vec6::Zero(), Vec6::Zero()});
            it->A[static_cast<int>(h.axis)] += h.amp * std::cos(h.phase);
            it->B[static_cast<int>(h.axis)] += h.amp * std::sin(h.phase);
        }
        for (int m = 0; m < 16; ++m) {
            sin_[m] = std::sin(m * kPi / 8);
            cos_[m] = std::cos(m * kPi / 8);
        }
        sin_[0] = sin_[8] = cos_[4] = cos_[12] = 0;   // (exact zeros)
    }
    PlateState state(double t, Dynamics level, const Mat3& R1 = Mat3::Identity()) const {
        PlateState ps;
        acceleration(t, ps, level == Dynamics::Full);
        if (level == Dynamics::Full) ps.R1 = R1;
        return ps;
    }
    // u(t) into ps.pdd, ps.wd, and with `velocity` the plate's angular velocity into ps.w1; the rest of
    // ps untouched. The reduced U- and U-dynamics call it on a PlateState of their own, which saves
    // building and copying one per evaluation (docs/decisions.md, Per-evaluation cuts in the
    // right-hand side).
    void acceleration(double t, PlateState& ps, bool velocity = false) const {
        double u[6] = {0, 0, 0, 0, 0, 0}, w[3] = {0, 0, 0};
        for (const Term& term : terms_) {
            const double k = term.n * w_;
            double s, c;
            sincos_of(k * t, s, c);
            for (int i = 0; i < 6; ++i) u[i] += s * term.A[i] + c * term.B[i];
            if (velocity)
                for (int i = 0; i < 3; ++i) w[i] -= (c * term.A[3 + i] - s * term.B[3 + i]) / k;
        }
        ps.pdd = Vec3(u[0], u[1], u[2]);
        ps.wd = Vec3(u[3], u[4], u[5]);
        if (velocity) ps.w1 = Vec3(w[0], w[1], w[2]);
    }
    // sin and cos of phi (above); libm's for |phi| beyond the exact range of the reduction.
    void sincos_of(double phi, double& s, double& c) const {
        constexpr double kInvStep = 8 / kPi;
        // pi/8 = kStep1 + kStep2 + kStep3: kStep1 and kStep2 have at most 33 significant bits (j times
        // them exact for |j| < 2^20)
        constexpr double kStep1 = 0x1.921fb544p-2, kStep2 = 0x1.0b4611a6p-36, kStep3 = 0x1.3198a2e037073p-71;
        // (round to nearest by adding and taking away 1.5 * 2^52, exact for |phi kInvStep| < 2^51 in the
        // default rounding mode: std::nearbyint is a library call without SSE4.1)
        constexpr double kRound = 0x1.8p52;
        const double jd = (phi * kInvStep + kRound) - kRound;
        if (!(std::abs(jd) < 1048576.0)) {
            ::sincos(phi, &s, &c);
            return;
        }
        const double x = ((phi - jd * kStep1) - jd * kStep2) - jd * kStep3;
        const double x2 = x * x;
        // (Estrin's scheme in x^2: a shorter chain of dependent operations than Horner's)
        const double x4 = x2 * x2, x8 = x4 * x4;
        const double sx =
            x + x * x2 * ((-1.0 / 6 + x2 * (1.0 / 120)) + x4 * (-1.0 / 5040 + x2 * (1.0 / 362880)) + x8 * (-1.0 / 39916800));
        const double cx = 1 + x2 * ((-0.5 + x2 * (1.0 / 24)) + x4 * (-1.0 / 720 + x2 * (1.0 / 40320)) + x8 * (-1.0 / 3628800));
        const int m = static_cast<int>(static_cast<long long>(jd) & 15);
        s = sin_[m] * cx + cos_[m] * sx;
        c = cos_[m] * cx - sin_[m] * sx;
    }

private:
    struct Term {
        int n;
        Vec6 A, B;
    };
    double w_;
    std::vector<Term> terms_;
    double sin_[16], cos_[16];
};

// Scales of the state components: slip speed v_ref, angular rates v_ref / rho, lengths rho.
struct Scales {
    double v, w, L;
    explicit Scales(const Scene& sc)
        : v(sc.v_ref()), w(sc.v_ref() / sc.part.rho()), L(sc.part.point ? sc.v_ref() * sc.plate.T : sc.part.rho()) {}
};

struct ReducedModel {
    using State = std::array<double, 6>;
    static constexpr bool kStuckFrozen = true;
    const Scene& sc;
    Signal u{sc.plate};
    Vec3 q0;
    Dynamics level = Dynamics::ReducedU;
    Workspace ws;
    Mode mode;
    ReducedModel(const Scene& s, const Vec3& q) : sc(s), q0(q) {}

    // u(t) of the last evaluation (shooting's Jacobian on an accepted step reuses it).
    double t_last = std::numeric_limits<double>::quiet_NaN();
    PlateState ps_last;

    void rhs(double t, const State& y, State& dy) {
        const Vec3 qd(y[0], y[1], y[2]);
        u.acceleration(t, ps_last);   // (R1 and w1 stay identity and zero: unused at this level)
        t_last = t;
        if (!(mode.kind == ModeKind::Slide && !stick_slip(ws).creep && reduced_U_slide(sc, q0, qd, ps_last, ws)))
            mode_accelerations(sc, level, q0, qd, ps_last, mode, ws);
        for (int i = 0; i < 3; ++i) {
            dy[i] = ws.qdd[i];
            dy[3 + i] = qd[i];
        }
    }
    Vec3 q(const State&) const { return q0; }
    Vec3 qd(const State& y) const { return Vec3(y[0], y[1], y[2]); }
    void set_qd(State& y, const Vec3& v) const {
        y[0] = v[0];
        y[1] = v[1];
        y[2] = v[2];
    }
    PlateState plate(double t, const State&) const { return u.state(t, level); }
    PlateState plate_at(double t) const { return t == t_last ? ps_last : u.state(t, level); }
    State scale() const {
        const Scales s(sc);
        const double T = sc.plate.T;
        return {s.v, s.v, s.w, s.v * T, s.v * T, s.w * T};
    }
};

struct UModel {
    using State = std::array<double, 6>;
    static constexpr bool kStuckFrozen = true;
    const Scene& sc;
    Signal u{sc.plate};
    Dynamics level = Dynamics::U;
    Workspace ws;
    Mode mode;
    explicit UModel(const Scene& s) : sc(s) {}

    void rhs(double t, const State& y, State& dy) {
        u.acceleration(t, ps_);   // (R1 and w1 stay identity and zero: unused at this level)
        mode_accelerations(sc, level, q(y), qd(y), ps_, mode, ws);
        for (int i = 0; i < 3; ++i) {
            dy[i] = y[3 + i];
            dy[3 + i] = ws.qdd[i];
        }
    }
    PlateState ps_;
    Vec3 q(const State& y) const { return Vec3(y[0], y[1], y[2]); }
    Vec3 qd(const State& y) const { return Vec3(y[3], y[4], y[5]); }
    void set_qd(State& y, const Vec3& v) const {
        y[3] = v[0];
        y[4] = v[1];
        y[5] = v[2];
    }
    PlateState plate(double t, const State&) const { return u.state(t, level); }
    State scale() const {
        const Scales s(sc);
        return {s.L, s.L, 1.0, s.v, s.v, s.w};
    }
};

struct FullModel {
    using State = std::array<double, 9>;
    static constexpr bool kStuckFrozen = false;   // the plate's orientation phi moves
    const Scene& sc;
    Signal u{sc.plate};
    Dynamics level = Dynamics::Full;
    Workspace ws;
    Mode mode;
    explicit FullModel(const Scene& s) : sc(s) {}

    void rhs(double t, const State& y, State& dy) {
        const So3Angle g(Vec3(y[6], y[7], y[8]));
        const PlateState ps = u.state(t, level, exp_so3(g));
        mode_accelerations(sc, level, q(y), qd(y), ps, mode, ws);
        const Vec3 phid = dexp_inv(g, ps.w1);
        for (int i = 0; i < 3; ++i) {
            dy[i] = y[3 + i];
            dy[3 + i] = ws.qdd[i];
            dy[6 + i] = phid[i];
        }
    }
    Vec3 q(const State& y) const { return Vec3(y[0], y[1], y[2]); }
    Vec3 qd(const State& y) const { return Vec3(y[3], y[4], y[5]); }
    void set_qd(State& y, const Vec3& v) const {
        y[3] = v[0];
        y[4] = v[1];
        y[5] = v[2];
    }
    PlateState plate(double t, const State& y) const { return u.state(t, level, exp_so3(Vec3(y[6], y[7], y[8]))); }
    State scale() const {
        const Scales s(sc);
        const double w = sc.plate.omega();
        const double a = std::max(sc.plate.angular_amplitude() / (w * w), 1e-6);
        return {s.L, s.L, 1.0, s.v, s.v, s.w, a, a, a};
    }
};

}   // namespace plate::detail
