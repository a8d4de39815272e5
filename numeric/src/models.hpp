// Internal: the three state layouts integrated by the engine.
//   ReducedU (35): y = [q'(3), Q(3)], Q = integral of q' (for the average (36)); q frozen.
//   Variational:   y = [q'(3), Q(3), Phi(9), Psi(9)], (35) with its variational equations
//                  Phi' = (d q''/d q') Phi, Psi' = Phi (Phi, Psi column-major, 3x3).
//   U (32):        y = [q(3), q'(3)]
//   Full (31):     y = [q(3), q'(3), phi(3)], R1 = exp(phi^)
#pragma once

#include "engine.hpp"

namespace plate::detail {

// Scales of the state components: slip speed v_ref, angular rates v_ref / rho, lengths rho.
struct Scales {
    double v, w, L;
    explicit Scales(const Scene& sc)
        : v(sc.v_ref()), w(sc.v_ref() / sc.part.rho()), L(sc.part.point ? sc.v_ref() * sc.plate.T : sc.part.rho()) {}
};

struct ReducedModel {
    using State = std::array<double, 6>;
    const Scene& sc;
    Vec3 q0;
    Dynamics level = Dynamics::ReducedU;
    Workspace ws;
    ReducedModel(const Scene& s, const Vec3& q) : sc(s), q0(q) {}

    void rhs(double t, const State& y, State& dy) {
        const Vec3 qd(y[0], y[1], y[2]);
        accelerations(sc, level, q0, qd, plate(t, y), ws);
        for (int i = 0; i < 3; ++i) { dy[i] = ws.qdd[i]; dy[3 + i] = qd[i]; }
    }
    Vec3 q(const State&) const { return q0; }
    Vec3 qd(const State& y) const { return Vec3(y[0], y[1], y[2]); }
    PlateState plate(double t, const State&) const { return plate_state(sc.plate, t, level); }
    State scale() const {
        const Scales s(sc);
        const double T = sc.plate.T;
        return {s.v, s.v, s.w, s.v * T, s.v * T, s.w * T};
    }
};

// The reduced U-dynamics (35) with the sensitivities of the twist and of its integral to the
// twist at the start: Phi(t) = d q'(t)/d q'(0), Psi(t) = d Q(t)/d q'(0). Over one period Phi(T) is
// the monodromy of the period map (Newton shooting) and Psi(T)/T the sensitivity of the average
// (36). d q''/d q' comes with the evaluation from the generated reduced-U kernels (twist_jacobian).
// With `variational` off, Phi and Psi stay constant (a plain period).
struct VariationalModel {
    using State = std::array<double, 24>;
    static constexpr std::size_t kErrDim = 6;   // the sensitivities stay out of the error norm
    const Scene& sc;
    Vec3 q0;
    Dynamics level = Dynamics::ReducedU;
    Workspace ws;
    bool variational = true;
    VariationalModel(const Scene& s, const Vec3& q) : sc(s), q0(q) {
        const Scales k(sc);
        S = Vec3(k.v, k.v, k.w);
    }

    void rhs(double t, const State& y, State& dy) {
        const Vec3 qd(y[0], y[1], y[2]);
        const PlateState ps = plate(t, y);
        std::fill(dy.begin() + 6, dy.end(), 0.0);
        if (variational) {
            Mat3 J;
            twist_jacobian(sc, level, q0, qd, ps, ws, J);
            const Mat3 dPhi = J * Eigen::Map<const Mat3>(y.data() + 6);
            for (int i = 0; i < 9; ++i) { dy[6 + i] = dPhi.data()[i]; dy[15 + i] = y[6 + i]; }
        } else {
            accelerations(sc, level, q0, qd, ps, ws);
        }
        for (int i = 0; i < 3; ++i) { dy[i] = ws.qdd[i]; dy[3 + i] = qd[i]; }
    }
    Vec3 q(const State&) const { return q0; }
    Vec3 qd(const State& y) const { return Vec3(y[0], y[1], y[2]); }
    Mat3 Phi(const State& y) const { return Eigen::Map<const Mat3>(y.data() + 6); }
    Mat3 Psi(const State& y) const { return Eigen::Map<const Mat3>(y.data() + 15); }
    PlateState plate(double t, const State&) const { return plate_state(sc.plate, t, level); }
    // Sets the state to a period start: twist x, Q = 0, Phi = I, Psi = 0.
    void reset(State& y, const Vec3& x) const {
        y.fill(0);
        for (int i = 0; i < 3; ++i) { y[i] = x[i]; y[6 + 4 * i] = 1; }
    }
    State scale() const {
        const double T = sc.plate.T;
        State s{};
        for (int i = 0; i < 3; ++i) {
            s[i] = S[i];
            s[3 + i] = S[i] * T;
            for (int j = 0; j < 3; ++j) { s[6 + 3 * j + i] = S[i] / S[j]; s[15 + 3 * j + i] = S[i] * T / S[j]; }
        }
        return s;
    }
    Vec3 S;   // twist scales (v_ref, v_ref, v_ref / rho)
};

struct UModel {
    using State = std::array<double, 6>;
    const Scene& sc;
    Dynamics level = Dynamics::U;
    Workspace ws;
    explicit UModel(const Scene& s) : sc(s) {}

    void rhs(double t, const State& y, State& dy) {
        accelerations(sc, level, q(y), qd(y), plate(t, y), ws);
        for (int i = 0; i < 3; ++i) { dy[i] = y[3 + i]; dy[3 + i] = ws.qdd[i]; }
    }
    Vec3 q(const State& y) const { return Vec3(y[0], y[1], y[2]); }
    Vec3 qd(const State& y) const { return Vec3(y[3], y[4], y[5]); }
    PlateState plate(double t, const State&) const { return plate_state(sc.plate, t, level); }
    State scale() const {
        const Scales s(sc);
        return {s.L, s.L, 1.0, s.v, s.v, s.w};
    }
};

struct FullModel {
    using State = std::array<double, 9>;
    const Scene& sc;
    Dynamics level = Dynamics::Full;
    Workspace ws;
    explicit FullModel(const Scene& s) : sc(s) {}

    void rhs(double t, const State& y, State& dy) {
        const PlateState ps = plate(t, y);
        accelerations(sc, level, q(y), qd(y), ps, ws);
        const Vec3 phid = dexp_inv(Vec3(y[6], y[7], y[8]), ps.w1);
        for (int i = 0; i < 3; ++i) { dy[i] = y[3 + i]; dy[3 + i] = ws.qdd[i]; dy[6 + i] = phid[i]; }
    }
    Vec3 q(const State& y) const { return Vec3(y[0], y[1], y[2]); }
    Vec3 qd(const State& y) const { return Vec3(y[3], y[4], y[5]); }
    PlateState plate(double t, const State& y) const {
        return plate_state(sc.plate, t, level, exp_so3(Vec3(y[6], y[7], y[8])));
    }
    State scale() const {
        const Scales s(sc);
        const double w = sc.plate.omega();
        const double a = std::max(sc.plate.angular_amplitude() / (w * w), 1e-6);
        return {s.L, s.L, 1.0, s.v, s.v, s.w, a, a, a};
    }
};

}  // namespace plate::detail
