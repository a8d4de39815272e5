// Static friction above kinetic in the pivot mode (issue 52, point 1, outside audit): a rigid part
// turning about one held contact k, whose force is bounded by mu_sk N_k while the other two slide at
// their kinetic coefficients; its break-away, after which contact k slides at mu_kk N_k; a turn that
// stops and re-sticks only where the needed torque fits the static disks; contacts whose static and
// kinetic coefficients all differ. Expected values from Newton-Euler about the held contact, written
// here and integrated by RK4, independently of the engine.
#include "plate/simulate.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

using namespace plate;

namespace {

inline double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }
inline Vec2 perp2(const Vec2& v) { return Vec2(-v.y(), v.x()); }   // e_z x v
inline Vec2 turned(double theta, const Vec2& c) {
    const double co = std::cos(theta), si = std::sin(theta);
    return Vec2(co * c.x() - si * c.y(), si * c.x() + co * c.y());
}

// A thin part (contacts in the plane of the centre of mass, J diagonal) on a plate that translates
// horizontally by a_p(t) = (ax sin(w t), ay cos(w t)), T = 0.2 s. Friction is horizontal and acts in
// the plane of s, so it has no moment about x or y: the normal forces are the static shares
// N_i = m g lambda_i (lambda: the barycentric coordinates of s in the contacts' triangle), whatever
// the mode and the orientation.
struct Planar {
    double m = 0.05, Jz = 2e-5, g = 9.81, ax = 2, ay = 1, w = 2 * kPi / 0.2;
    std::array<Vec2, 3> c = {Vec2(0.03, 0), Vec2(-0.02, 0.025), Vec2(-0.015, -0.03)};
    Vec3 mu_k = Vec3(0.30, 0.25, 0.35), mu_s = Vec3(0.50, 0.40, 0.45);

    Scene scene() const {
        Scene sc;
        sc.name = "planar pivot";
        sc.g = g;
        sc.part.m = m;
        sc.part.J = Vec3(1e-5, 1e-5, Jz).asDiagonal();
        for (int i = 0; i < 3; ++i) sc.part.c[i] = Vec3(c[i].x(), c[i].y(), 0);
        sc.part.mu = mu_k;
        sc.part.mu_static = mu_s;
        sc.plate.T = 2 * kPi / w;
        sc.plate.harmonics = {Harmonic{Axis::x, 1, ax, 0}, Harmonic{Axis::y, 1, ay, kPi / 2}};
        return sc;
    }
    Vec2 plate_acc(double t) const { return Vec2(ax * std::sin(w * t), ay * std::cos(w * t)); }
    Vec3 normal() const {
        Mat3 M;
        for (int i = 0; i < 3; ++i) M.col(i) = Vec3(c[i].x(), c[i].y(), 1);
        return m * g * M.partialPivLu().solve(Vec3(0, 0, 1));
    }
    double d(int j, int k) const { return (c[j] - c[k]).norm(); }
    // Moment about contact k that the two other contacts' friction can give: sum_j mu_j N_j |c_j - c_k|.
    double torque_capacity(int k, const Vec3& mu) const {
        const Vec3 N = normal();
        double T = 0;
        for (int j = 0; j < 3; ++j)
            if (j != k) T += mu[j] * N[j] * d(j, k);
        return T;
    }
};

// The turn about held contact k, from Newton-Euler about the point c_k (fixed in the plate, whose
// frame accelerates by a_p: an inertial force -m a_p at s = c_k - r_k):
//   I_k theta'' = m r_k x a_p - sign(theta') sum_{j != k} mu_kj N_j |c_j - c_k|,   I_k = J_zz + m |c_k|^2
// (a sliding contact j moves on a circle about c_k; its friction -mu_kj N_j sign(theta') e_z x (r_j - r_k)/d_jk
// has the moment -mu_kj N_j d_jk sign(theta') about c_k). The held contact's force follows from
// Newton's law for s: f_k = m s'' + m a_p - sum_{j != k} f_j, with s'' = -(theta'' e_z x r_k - theta'^2 r_k).
struct PivotRef {
    Planar p;
    int k = 0;
    Vec3 mu_k = p.mu_k;   // the sliding contacts' coefficients (a wrong model changes them)
    double sense = 1;     // sign(theta') while turning

    double drive(double t, double theta) const { return p.m * cross2(turned(theta, p.c[k]), p.plate_acc(t)); }
    Vec2 deriv(double t, const Vec2& y) const {
        const double I = p.Jz + p.m * p.c[k].squaredNorm();
        return Vec2(y[1], (drive(t, y[0]) - sense * p.torque_capacity(k, mu_k)) / I);
    }
    Vec2 held_force(double t, const Vec2& y) const {
        const Vec3 N = p.normal();
        const Vec2 rk = turned(y[0], p.c[k]);
        const double thdd = deriv(t, y)[1];
        const Vec2 sdd = -(thdd * perp2(rk) - y[1] * y[1] * rk);
        Vec2 f = p.m * sdd + p.m * p.plate_acc(t);
        for (int j = 0; j < 3; ++j) {
            if (j == k) continue;
            const Vec2 rj = turned(y[0], p.c[j]);
            f += mu_k[j] * N[j] * sense * perp2(rj - rk) / (rj - rk).norm();
        }
        return f;
    }
    Vec2 step(double t, const Vec2& y, double h) const {
        const Vec2 k1 = deriv(t, y), k2 = deriv(t + h / 2, y + h / 2 * k1), k3 = deriv(t + h / 2, y + h / 2 * k2),
                   k4 = deriv(t + h, y + h * k3);
        return y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
};

// The part turning about contact k (mode +1 or -1: the sense of theta') or stuck (0), integrated by
// RK4 with steps of at most h, cut at the sample times `ts`; events located by bisection on a partial
// RK4 step from the last node. A turn that stops (theta' = 0) sticks if the needed moment about c_k
// fits the others' static friction, |m r_k x a_p| <= sum_j mu_sj N_j d_jk = Ts, and turns on the
// other way if not; a stuck part turns when that moment reaches Ts (contact k itself held: its static
// disk taken as unbounded). With a finite hold (mu_sk N_k) the run ends where |f_k| reaches it.
struct TurnRun {
    std::vector<Vec2> at;   // (theta, theta') at ts
    struct Event {
        double t;
        int mode;       // entered
        double drive;   // |m r_k x a_p| there
    };
    std::vector<Event> events;
    double breakaway = std::nan("");   // time |f_k| reached the hold, if it did
    Vec2 y_break = Vec2::Zero();
    double worst_hold = 0;   // largest |f_k| / N_k seen at the nodes while turning
};
TurnRun run_turn(PivotRef ref, double Ts, double hold, int mode, Vec2 y, double t_end, const std::vector<double>& ts,
                 double h = 1e-5) {
    TurnRun out;
    const double Nk = ref.p.normal()[ref.k];
    double t = 0;
    std::size_t next = 0;
    auto advance = [&](double t0, const Vec2& y0, double dt) { return mode == 0 ? y0 : ref.step(t0, y0, dt); };
    // Guards, positive while the mode holds: 0 the turn (sense theta'), 1 the hold of contact k, 2 stuck.
    auto guards = [&](double tt, const Vec2& yy) {
        std::array<double, 3> g{1, 1, 1};
        if (mode == 0) {
            g[2] = Ts - std::abs(ref.drive(tt, yy[0]));
        } else {
            g[0] = mode * yy[1];
            g[1] = hold - ref.held_force(tt, yy).norm();
        }
        return g;
    };
    while (t < t_end && next <= ts.size()) {
        const double stop = next < ts.size() ? std::min(ts[next], t_end) : t_end;
        const bool to_stop = h >= stop - t;
        const double dt = to_stop ? stop - t : h;
        ref.sense = mode;
        const Vec2 y1 = advance(t, y, dt);
        const std::array<double, 3> g0 = guards(t, y), g1 = guards(t + dt, y1);
        double tau = dt;
        int ev = -1;
        for (int i = 0; i < 3; ++i) {
            if (!(g0[i] > 0 && g1[i] <= 0)) continue;
            double lo = 0, hi = dt;
            for (int it = 0; it < 60; ++it) {
                const double mid = 0.5 * (lo + hi);
                (guards(t + mid, advance(t, y, mid))[i] > 0 ? lo : hi) = mid;
            }
            if (hi <= tau) {
                tau = hi;
                ev = i;
            }
        }
        if (ev < 0) {
            t = to_stop ? stop : t + dt;
            y = y1;
            if (mode != 0) out.worst_hold = std::max(out.worst_hold, ref.held_force(t, y).norm() / Nk);
            if (next < ts.size() && t == ts[next]) out.at.push_back(y), ++next;
            if (next == ts.size() && t >= t_end) break;
            continue;
        }
        y = advance(t, y, tau);
        t += tau;
        if (ev == 1) {
            out.breakaway = t;
            out.y_break = y;
            return out;
        }
        if (ev == 0) y[1] = 0;
        const double D = ref.drive(t, y[0]);
        mode = ev == 0 && std::abs(D) <= Ts ? 0 : (D > 0 ? 1 : -1);
        out.events.push_back({t, mode, std::abs(D)});
    }
    return out;
}

// The part sliding on all three contacts at their kinetic coefficients, (s, theta, s', theta') in the
// plate's frame: m s'' = sum_i f_i - m a_p, J_zz theta'' = sum_i r_i x f_i, f_i = -mu_ki N_i v_i/|v_i|.
// Contact k starts at zero slip (a break-away) along u0, the direction along which it then accelerates
// (a_k(u0) parallel to u0, found by Newton's method on its angle), and slides along v_k/|v_k| after.
struct SlideRef {
    Planar p;
    int k = 0;
    Vec2 u0 = Vec2::Zero();
    using State = Eigen::Matrix<double, 6, 1>;

    State deriv(double t, const State& y) const {
        const Vec3 N = p.normal();
        Vec2 F = -p.m * p.plate_acc(t);
        double tau = 0;
        for (int i = 0; i < 3; ++i) {
            const Vec2 r = turned(y[2], p.c[i]);
            const Vec2 v = y.segment<2>(3) + y[5] * perp2(r);
            const Vec2 u = v.norm() > 1e-14 ? Vec2(v / v.norm()) : u0;
            const Vec2 f = -p.mu_k[i] * N[i] * u;
            F += f;
            tau += cross2(r, f);
        }
        State d;
        d << y.segment<3>(3), F / p.m, tau / p.Jz;
        return d;
    }
    // Contact k's acceleration relative to the plate, s'' + theta'' e_z x r_k - theta'^2 r_k.
    Vec2 contact_acc(double t, const State& y) const {
        const State d = deriv(t, y);
        const Vec2 r = turned(y[2], p.c[k]);
        return d.segment<2>(3) + d[5] * perp2(r) - y[5] * y[5] * r;
    }
    // u0 from the guess u (the direction opposite the held force at the break-away).
    void consistent_direction(double t, const State& y, Vec2 u) {
        double phi = std::atan2(u.y(), u.x());
        auto residual = [&](double a) {
            u0 = Vec2(std::cos(a), std::sin(a));
            return cross2(contact_acc(t, y), u0);
        };
        for (int it = 0; it < 50; ++it) {
            const double r = residual(phi), dr = (residual(phi + 1e-7) - r) / 1e-7;
            phi -= r / dr;
            if (std::abs(r) < 1e-15) break;
        }
        residual(phi);
    }
    State step(double t, const State& y, double h) const {
        const State k1 = deriv(t, y), k2 = deriv(t + h / 2, y + h / 2 * k1), k3 = deriv(t + h / 2, y + h / 2 * k2),
                    k4 = deriv(t + h, y + h * k3);
        return y + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    }
    State run(double t, State y, double t1, double h = 1e-6) const {
        const int n = static_cast<int>(std::ceil((t1 - t) / h));
        const double dt = (t1 - t) / n;
        for (int i = 0; i < n; ++i, t += dt) y = step(t, y, dt);
        return y;
    }
};

}   // namespace

TEST_CASE("a part turning about a held contact: theta(t) and the break-away at |f_k| = mu_sk N_k against Newton-Euler",
          "[stick][static_friction]") {
    // Two starts turning clockwise about contact 1 (mu_s1 = 0.5, mu_k1 = 0.3): at theta = 3.5 its
    // needed force starts inside the kinetic disk; at theta = 2.5 beyond it (0.37 N_1), so only static
    // friction takes the start as a pivot. (The plate does not turn, so full dynamics are U-dynamics
    // here: both are run, and give the same numbers.)
    const Planar P;
    const Scene sc = P.scene();
    const int k = 0;
    const double om0 = -4, duration = 0.055, h = 1e-3;
    const Vec3 N = P.normal();
    const PivotRef ref{P, k};
    for (double th0 : {3.5, 2.5})
        for (Dynamics level : {Dynamics::U, Dynamics::Full}) {
            // Contact k at rest relative to the plate: s' = -theta' e_z x r_k.
            const Vec2 rk0 = turned(th0, P.c[k]);
            const Vec3 qd0(-om0 * perp2(rk0).x(), -om0 * perp2(rk0).y(), om0);
            const Trajectory tr = simulate(sc, level, Vec3(0, 0, th0), qd0, duration, h);
            REQUIRE(tr.stop.reason == StopReason::None);
            std::vector<double> ts;
            for (const Sample& s : tr.samples) ts.push_back(s.t);
            const TurnRun r = run_turn(ref, P.torque_capacity(k, P.mu_s), P.mu_s[k] * N[k], -1, Vec2(th0, om0), duration, ts);
            REQUIRE(std::isfinite(r.breakaway));
            REQUIRE(r.events.empty());   // (the turn does not stop before)
            REQUIRE(tr.events.size() >= 2);
            double worst_theta = 0, worst_rate = 0, worst_contact = 0;
            for (std::size_t i = 0; i < r.at.size(); ++i) {
                const Sample& s = tr.samples[i];
                worst_theta = std::max(worst_theta, std::abs(s.q[2] - r.at[i][0]));
                worst_rate = std::max(worst_rate, std::abs(s.qd[2] - r.at[i][1]));
                const Vec2 ck = s.q.head<2>() + turned(s.q[2], P.c[k]);
                worst_contact = std::max(worst_contact, (ck - rk0).norm());
            }
            INFO("theta0 = " << th0 << ", " << dynamics_name(level) << ": reference break-away at " << r.breakaway
                             << " s, engine " << tr.events[1].t << "; samples " << r.at.size() << ", theta off by " << worst_theta
                             << " rad, theta' by " << worst_rate << " rad/s, contact k moved " << worst_contact << " m");
            CHECK(tr.events[0].t == 0);
            CHECK(tr.events[0].to == Mode{ModeKind::Pivot, k, -1});
            CHECK(tr.events[1].from == Mode{ModeKind::Pivot, k, -1});
            CHECK(tr.events[1].to.kind == ModeKind::Slide);
            // Measured (both starts, U and full dynamics alike, rtol 1e-9): the break-away within 1.2e-14 s
            // of the reference's root, theta within 1.1e-14 rad and theta' within 1.8e-13 rad/s at the
            // samples before it, contact k within 1e-16 m of where it started; the bounds leave about two
            // orders for rounding (the wrong models below are 5e-3 s to 2e-2 s away).
            CHECK(tr.events[1].t == Approx(r.breakaway).margin(1e-12));
            CHECK(worst_theta < 1e-12);
            CHECK(worst_rate < 1e-11);
            CHECK(worst_contact < 1e-14);
            // After the break-away contact k slides at mu_kk N_k (all three kinetic): the slide from the
            // reference's state at the break-away, against the engine's samples over the next 5 ms.
            SlideRef slide{P, k};
            const Vec2 rk = turned(r.y_break[0], P.c[k]);
            SlideRef::State y0;
            y0 << rk0 - rk, r.y_break[0], -r.y_break[1] * perp2(rk), r.y_break[1];
            PivotRef at = ref;
            at.sense = -1;
            const Vec2 f = at.held_force(r.breakaway, r.y_break);
            slide.consistent_direction(r.breakaway, y0, -f / f.norm());
            double worst_slide = 0;
            int slid = 0;
            for (const Sample& s : tr.samples) {
                if (s.t <= r.breakaway || s.t > r.breakaway + 5e-3) continue;
                const SlideRef::State y = slide.run(r.breakaway, y0, s.t);
                worst_slide =
                    std::max({worst_slide, (s.q.head<2>() - y.head<2>()).norm() / P.c[k].norm(), std::abs(s.q[2] - y[2])});
                ++slid;
            }
            INFO("slide: " << slid << " samples, off by " << worst_slide << " (m / |c_k|, rad)");
            // Measured 8.6e-12 (theta0 = 3.5) and 2.9e-10 (2.5), the engine's creep after a break-away (its
            // slip direction solved, engine.hpp); the reference's RK4 changes by 3e-14 when its step is
            // halved. The bound is the integrator's rtol.
            CHECK(slid >= 4);
            CHECK(worst_slide < 1e-9);
            CHECK((tr.events.size() == 2 || tr.events[2].t > r.breakaway + 5e-3));   // (nothing else in those 5 ms)
        }
    // The wrong models. From theta = 3.5 one coefficient (mu_k) for holding too breaks away at 6.5 ms
    // instead of 27 ms, the sliding contacts at their static coefficients at 21 ms; from theta = 2.5
    // the needed force starts at 0.37 N_1, outside the kinetic disk (0.3 N_1), inside the static one.
    const double mu_k1 = P.mu_k[k], mu_s1 = P.mu_s[k];
    const TurnRun one = run_turn(ref, P.torque_capacity(k, P.mu_k), mu_k1 * N[k], -1, Vec2(3.5, om0), duration, {});
    const TurnRun right = run_turn(ref, P.torque_capacity(k, P.mu_s), mu_s1 * N[k], -1, Vec2(3.5, om0), duration, {});
    PivotRef sliding_static = ref;
    sliding_static.mu_k = P.mu_s;
    const TurnRun st = run_turn(sliding_static, P.torque_capacity(k, P.mu_s), mu_s1 * N[k], -1, Vec2(3.5, om0), duration, {});
    CHECK(right.breakaway - one.breakaway > 1e-2);
    CHECK(std::abs(right.breakaway - st.breakaway) > 1e-3);
    PivotRef start = ref;
    start.sense = -1;
    const double need = start.held_force(0, Vec2(2.5, om0)).norm() / N[k];
    CHECK(need > mu_k1 + 0.02);
    CHECK(need < mu_s1);
}

TEST_CASE("a contact with enormous static friction never slips: the part's stick-slip about it is the 1-DoF oscillator's",
          "[stick][static_friction]") {
    // Contact 1 can hold whatever it must (mu_s1 = 20; the reference needs |f_1| <= 1.2 N_1); contacts 2
    // and 3 have static and kinetic coefficients that all differ. The part then turns about c_1 or
    // rides the plate, a 1-DoF stick-slip oscillator in theta (run_turn):
    //   turning:  I_1 theta'' = m r_1 x a_p - sign(theta') Tk,   Tk = sum_j mu_kj N_j d_j1
    //   stuck:    while |m r_1 x a_p| <= Ts = sum_j mu_sj N_j d_j1 (a turn that stops re-sticks there)
    // Two drives: a_p = (7 sin, 3 cos) m/s^2, whose turns stop and re-stick where only the static
    // coefficients can hold them (Tk < |m r_1 x a_p| <= Ts); (8 sin, 2 cos), whose turns stop and turn on
    // the other way (|m r_1 x a_p| > Ts there).
    for (const Vec2& drive : {Vec2(7, 3), Vec2(8, 2)}) {
        const bool resticks = drive.x() == 7;
        Planar P;
        P.ax = drive.x();
        P.ay = drive.y();
        P.mu_s = Vec3(20, 0.40, 0.45);
        const Scene sc = P.scene();
        const int k = 0;
        const double th0 = 1.5, duration = 0.4, h = 2e-3;
        const PivotRef ref{P, k};
        const double Ts = P.torque_capacity(k, P.mu_s), Tk = P.torque_capacity(k, P.mu_k);
        const Trajectory tr = simulate(sc, Dynamics::U, Vec3(0, 0, th0), Vec3::Zero(), duration, h);
        REQUIRE(tr.stop.reason == StopReason::None);
        std::vector<double> ts;
        for (const Sample& s : tr.samples) ts.push_back(s.t);
        const double inf = std::numeric_limits<double>::infinity();
        const TurnRun r = run_turn(ref, Ts, inf, 0, Vec2(th0, 0), duration, ts);
        REQUIRE(r.at.size() == ts.size());
        CHECK(r.worst_hold < 1.5);   // (measured 1.10 and 1.30: mu_s1 = 20 is enormous)
        int firm = 0, reverse = 0, left = 0, right = 0;
        for (std::size_t i = 0; i < r.events.size(); ++i) {
            const TurnRun::Event& e = r.events[i];
            firm += e.mode == 0 && e.drive > Tk;
            reverse += i > 0 && e.mode != 0 && r.events[i - 1].mode == -e.mode;
            left += e.mode == 1;
            right += e.mode == -1;
        }
        CHECK((resticks ? firm : reverse) >= 2);
        CHECK(left >= 1);
        CHECK(right >= 1);
        // The engine: stuck from the start, then the reference's events (7 and 4) in order, each within
        // 5e-12 s (measured 1.7e-12 s), theta within 1e-10 rad at the 201 samples (measured 2.2e-11 rad),
        // contact 1 within 1e-12 m of where it started (measured 5.5e-13 m), held all along.
        REQUIRE(tr.events.size() == r.events.size() + 1);
        CHECK(tr.events[0].t == 0);
        CHECK(tr.events[0].to.kind == ModeKind::Stuck);
        double worst_t = 0;
        for (std::size_t i = 0; i < r.events.size(); ++i) {
            const Mode& m = tr.events[i + 1].to;
            INFO("event " << i + 1 << ": engine " << mode_name(m) << " at " << tr.events[i + 1].t << " s, reference mode "
                          << r.events[i].mode << " at " << r.events[i].t << " s");
            if (r.events[i].mode == 0)
                CHECK(m.kind == ModeKind::Stuck);
            else
                CHECK(m == Mode{ModeKind::Pivot, k, double(r.events[i].mode)});
            CHECK((m.kind != ModeKind::Pivot || m.sense == r.events[i].mode));
            worst_t = std::max(worst_t, std::abs(tr.events[i + 1].t - r.events[i].t));
        }
        const Vec2 ck0 = turned(th0, P.c[k]);
        double worst_theta = 0, worst_contact = 0;
        for (std::size_t i = 0; i < ts.size(); ++i) {
            const Sample& s = tr.samples[i];
            worst_theta = std::max(worst_theta, std::abs(s.q[2] - r.at[i][0]));
            worst_contact = std::max(worst_contact, (s.q.head<2>() + turned(s.q[2], P.c[k]) - ck0).norm());
        }
        INFO("a_p = (" << P.ax << " sin, " << P.ay << " cos): events off by " << worst_t << " s, theta by " << worst_theta
                       << " rad; contact 1 moved " << worst_contact << " m");
        CHECK(worst_t < 5e-12);
        CHECK(worst_theta < 1e-10);
        CHECK(worst_contact < 1e-12);
        CHECK(tr.held_time[k] == Approx(duration).margin(1e-12));
        // One coefficient per contact (Ts = Tk, the wrong model) breaks loose 8 ms and 6.7 ms earlier.
        const TurnRun one = run_turn(ref, Tk, inf, 0, Vec2(th0, 0), duration, {});
        REQUIRE(!one.events.empty());
        CHECK(r.events[0].t - one.events[0].t > 1e-3);
    }
}

TEST_CASE(
    "a stuck part breaks away when |a_p| = g sum_i mu_si lambda_i, its contacts' static coefficients weighted by "
    "their normal shares",
    "[stick][static_friction]") {
    // The thin part of the pivot test (three different static coefficients) on a plate shaken along x,
    // a_p = 6 sin(w t) m/s^2, turned so that V = sum_i mu_si lambda_i r_i points along x. Stuck, it needs
    // the friction total F = m a_p and no moment about s. Any distribution has sum_i |f_i| >= |F| and
    // sum_i |f_i| <= gamma sum_i mu_si N_i, so the gauge is at least |F| / (m g sum_i mu_si lambda_i); the
    // distribution f_i = -gamma mu_si N_i e_x attains it and has the moment -gamma m g V x e_x = 0. So
    // the gauge is exactly |a_p| / (g sum_i mu_si lambda_i), and the part breaks away at the first t with
    // 6 sin(w t) = g sum_i mu_si lambda_i. (The contacts' coefficients exchanged, V turns off the x axis
    // and the moment binds; one coefficient per contact puts the break-away at g sum_i mu_ki lambda_i.)
    Planar P;
    P.ax = 6;
    P.ay = 0;
    const Scene sc = P.scene();
    const Vec3 lambda = P.normal() / (P.m * P.g);
    Vec2 V = Vec2::Zero();
    for (int i = 0; i < 3; ++i) V += P.mu_s[i] * lambda[i] * P.c[i];
    const double th0 = -std::atan2(V.y(), V.x());
    const double a_s = P.g * P.mu_s.dot(lambda), a_k = P.g * P.mu_k.dot(lambda);
    const double t_s = std::asin(a_s / P.ax) / P.w, t_k = std::asin(a_k / P.ax) / P.w;
    const Trajectory tr = simulate(sc, Dynamics::U, Vec3(0, 0, th0), Vec3::Zero(), t_s + 0.01, 1e-3);
    REQUIRE(tr.stop.reason == StopReason::None);
    REQUIRE(tr.events.size() >= 2);
    INFO("closed form: break-away at " << t_s << " s (" << a_s << " m/s^2); engine at " << tr.events[1].t << " s");
    CHECK(tr.events[0].t == 0);
    CHECK(tr.events[0].to.kind == ModeKind::Stuck);
    CHECK(tr.events[1].from.kind == ModeKind::Stuck);
    CHECK(tr.events[1].to.kind == ModeKind::Slide);
    // (measured 3.5e-18 s off the closed form; 1e-12 s leaves room for rounding, the wrong model is 10 ms early)
    CHECK(tr.events[1].t == Approx(t_s).margin(1e-12));
    CHECK(t_s - t_k > 5e-3);
}

TEST_CASE("mirror symmetry with per-contact static and kinetic coefficients: the mirrored scene runs the mirrored path",
          "[stick][static_friction]") {
    // A part symmetric about its x axis (contact 1 on it, 2 and 3 mirror images) whose three contacts have
    // different static and kinetic coefficients, on a plate moving on all six axes (full dynamics). The
    // mirror y -> -y maps the scene to one whose contacts 2 and 3 exchange their coefficients and whose
    // y, rx and rz motions are reversed (angular velocity is an axial vector); its trajectory from the
    // mirrored start must be the mirror image: (s_x, -s_y, -theta), the same stuck phases, pivots about
    // the mirrored contact. A contact that read another's coefficient would break the symmetry (unless
    // contacts 2 and 3 exchange theirs, which commutes with the mirror: the break-away test above
    // catches that).
    const Vec3 mu_k(0.30, 0.27, 0.33), mu_s(0.45, 0.38, 0.52);
    auto make = [&](bool mirrored, bool swap_kinetic, bool swap_static) {
        Scene sc;
        sc.name = mirrored ? "mirrored" : "original";
        Part& p = sc.part;
        p.m = 0.06;
        p.J = Vec3(3e-5, 2e-5, 4e-5).asDiagonal();
        p.c = {Vec3(0.04, 0, -0.006), Vec3(-0.02, 0.03, -0.006), Vec3(-0.02, -0.03, -0.006)};
        p.mu = swap_kinetic ? Vec3(mu_k[0], mu_k[2], mu_k[1]) : mu_k;
        p.mu_static = swap_static ? Vec3(mu_s[0], mu_s[2], mu_s[1]) : mu_s;
        const double s = mirrored ? -1 : 1;
        sc.plate.T = 0.2;
        sc.plate.harmonics = {Harmonic{Axis::x, 1, 4.25, 0.3},      Harmonic{Axis::y, 1, s * 0.85, 1.1},
                              Harmonic{Axis::y, 2, s * 0.425, 0.2}, Harmonic{Axis::z, 2, 1.7, 0.4},
                              Harmonic{Axis::rx, 1, s * 4.25, 0.5}, Harmonic{Axis::ry, 1, 3.4, 1.3},
                              Harmonic{Axis::rz, 1, s * 8.5, 2.0}};
        return sc;
    };
    const double duration = 0.5, h = 1e-3;
    const Vec3 q0(0.01, 0.02, 0.3), q0m(0.01, -0.02, -0.3);
    const Scene a = make(false, false, false);
    const Trajectory ta = simulate(a, Dynamics::Full, q0, Vec3::Zero(), duration, h);
    REQUIRE(ta.stop.reason == StopReason::None);
    const Vec3 scale(1, 1, 1 / a.part.rho());
    // Largest distance of a run from the mirror image of ta, in (m, m, rho rad).
    auto distance = [&](const Trajectory& tb) {
        double worst = 0;
        for (std::size_t i = 0; i < std::min(ta.samples.size(), tb.samples.size()); ++i) {
            const Vec3 m(ta.samples[i].q[0], -ta.samples[i].q[1], -ta.samples[i].q[2]);
            worst = std::max(worst, (tb.samples[i].q - m).cwiseQuotient(scale).cwiseAbs().maxCoeff());
        }
        return worst;
    };
    int pivots = 0, stucks = 0;
    for (const ModeEvent& e : ta.events) {
        pivots += e.to.kind == ModeKind::Pivot;
        stucks += e.to.kind == ModeKind::Stuck;
    }
    INFO("the original's mode changes: " << ta.events.size() << " (pivots " << pivots << ", stuck " << stucks << ")");
    CHECK(pivots >= 2);
    CHECK(stucks >= 4);
    const Trajectory tb = simulate(make(true, true, true), Dynamics::Full, q0m, Vec3::Zero(), duration, h);
    REQUIRE(tb.stop.reason == StopReason::None);
    REQUIRE(tb.samples.size() == ta.samples.size());
    REQUIRE(tb.events.size() == ta.events.size());
    const int mirror[3] = {0, 2, 1};
    double worst_t = 0;
    for (std::size_t i = 0; i < ta.events.size(); ++i) {
        const Mode& m = ta.events[i].to;
        const Mode& n = tb.events[i].to;
        INFO("event " << i << ": " << mode_name(m) << " at " << ta.events[i].t << " s, mirrored " << mode_name(n) << " at "
                      << tb.events[i].t << " s");
        CHECK(n.kind == m.kind);
        if (m.kind == ModeKind::Pivot) {
            CHECK(n.k == mirror[m.k]);
            CHECK(n.sense == -m.sense);
        }
        worst_t = std::max(worst_t, std::abs(tb.events[i].t - ta.events[i].t));
    }
    for (int i = 0; i < 3; ++i) CHECK(tb.held_time[mirror[i]] == Approx(ta.held_time[i]).margin(1e-12));
    // The two runs differ only by rounding: measured 4e-17 (m, rho rad) at the 501 samples and 1.9e-14 s
    // at the 13 mode changes; bound 1e-12 for both (the wrong mirrors below are 1e-4 away).
    CHECK(distance(tb) < 1e-12);
    CHECK(worst_t < 1e-12);
    // Mirroring only one of the two coefficient vectors is another scene: far from the mirror image
    // (measured 6.0e-4 with the kinetic ones mirrored alone, 1.2e-4 with the static ones).
    const double dk = distance(simulate(make(true, true, false), Dynamics::Full, q0m, Vec3::Zero(), duration, h));
    const double ds = distance(simulate(make(true, false, true), Dynamics::Full, q0m, Vec3::Zero(), duration, h));
    CHECK(dk > 1e-6);
    CHECK(ds > 1e-6);
}
