// Trajectories: U and full dynamics against each other and against the field's integral curve
// (Section IV-C), and the full dynamics' limit as the plate's amplitude shrinks.
#include "plate/field.hpp"
#include "plate/scene_io.hpp"
#include "shipped_scenes.hpp"

#include <Eigen/Geometry>
#include <catch2/catch.hpp>

#include <cmath>

using namespace plate;

namespace {
using plate_tests::scene;
}   // namespace

TEST_CASE("full dynamics tend to U-dynamics as the plate amplitude shrinks, at rate k^-2", "[trajectory][full]") {
    // Keep u's accelerations and divide the period by k: displacements and tilts shrink as k^-2,
    // plate angular velocity as k^-1. The U-dynamics scale exactly (velocities as 1/k, with time);
    // the terms they drop -- gravity along the tilted plate g (R1^T - I) e_z, R1^T p'' - p'',
    // centripetal w1^ w1^ s and Coriolis 2 w1^ s' (with |s'| ~ 1/k) -- are all O(k^-2) relative to
    // the accelerations kept. So over N periods the full-minus-U displacement, relative to the
    // displacement, falls as k^-2: a ratio of 4 per doubling of k once k^-2 dominates.
    const Scene base = scene("fig4");
    const Vec3 q0(0.02, -0.01, 0.5);
    std::vector<double> rel_xy, rel_th;
    for (double k : {4.0, 8.0, 16.0}) {
        Scene sc = base;
        sc.plate.T = base.plate.T / k;
        const double dur = 40 * sc.plate.T;
        IntegrationOptions io;
        io.rtol = 1e-11;
        const Vec3 qd0 = Vec3(0.05, -0.03, 1.0) / k;
        const Trajectory f = simulate(sc, Dynamics::Full, q0, qd0, dur, dur, io);
        const Trajectory u = simulate(sc, Dynamics::U, q0, qd0, dur, dur, io);
        REQUIRE(f.stop.reason == StopReason::None);
        REQUIRE(u.stop.reason == StopReason::None);
        const Vec3 du = u.samples.back().q - q0, d = f.samples.back().q - u.samples.back().q;
        rel_xy.push_back(d.head<2>().norm() / du.head<2>().norm());
        rel_th.push_back(std::abs(d[2] / du[2]));
    }
    for (int i = 0; i + 1 < 3; ++i) {
        INFO("k step " << i);
        CHECK(rel_xy[i] / rel_xy[i + 1] == Approx(4).margin(0.5));
        CHECK(rel_th[i] / rel_th[i + 1] == Approx(4).margin(0.5));
    }
    CHECK(rel_xy.back() < 1e-3);
}

TEST_CASE("Fig. 4: from rest near the edge, the part goes to the centre along the field's integral curve",
          "[trajectory][paper]") {
    const Scene sc = scene("fig4");
    const Vec3 q0(0.04, -0.04, 1.0);
    const double dur = 20, dt = 0.25;
    const Trajectory full = simulate(sc, Dynamics::Full, q0, Vec3::Zero(), dur, dt);
    const Trajectory u = simulate(sc, Dynamics::U, q0, Vec3::Zero(), dur, dt);
    const Trajectory curve = field_curve(sc, q0, dur, dt);
    REQUIRE(full.stop.reason == StopReason::None);
    REQUIRE(u.stop.reason == StopReason::None);
    REQUIRE(curve.stop.reason == StopReason::None);
    REQUIRE(full.samples.size() == curve.samples.size());

    // Converges toward the centre, principal axes toward the plate's (Section IV-C, Fig. 4).
    const Sample& end = full.samples.back();
    CHECK(end.q.head<2>().norm() < 0.05 * q0.head<2>().norm());
    CHECK(std::abs(end.q[2]) < 0.1);

    // How far may a trajectory sampled at phase 0 stand from the integral curve? In the reduced
    // model, a start from rest ends the transient displaced by X - xi_a t_end from the curve
    // (X = int q' dt, t_end at a period boundary); afterwards, as q changes, the phase-0 point of
    // the cycle moves about its mean by at most D = max |int_0^t (q'_LC - xi_a)| each way, and the
    // averaging error (the configuration moves within each period) builds up to about D times the
    // ratio of the field's fastest to slowest rate near its fixed point (1.6 / 0.22 ~ 7 for Fig. 4,
    // see the fixed-point test): allow 10 D.
    LimitCycleOptions lo;
    lo.record = true;
    lo.restarts = 0;
    const LimitCycleSummary lc = limit_cycle(sc, q0, lo);   // from rest, as the trajectory
    REQUIRE(lc.converged);
    const double T = sc.plate.T, t_last = lc.path.back().t;
    Vec3 X = Vec3::Zero(), disp = Vec3::Zero();
    double D = 0, D_th = 0;
    for (std::size_t i = 1; i < lc.path.size(); ++i) {
        const double h = lc.path[i].t - lc.path[i - 1].t;
        X += 0.5 * (lc.path[i].qd + lc.path[i - 1].qd) * h;
        if (lc.path[i - 1].t < t_last - T - 1e-12) continue;
        disp += (0.5 * (lc.path[i].qd + lc.path[i - 1].qd) - lc.twist) * h;
        D = std::max(D, disp.head<2>().norm());
        D_th = std::max(D_th, std::abs(disp[2]));
    }
    const Vec3 offset = X - lc.twist * t_last;
    const double bound_xy = offset.head<2>().norm() + 10 * D, bound_th = std::abs(offset[2]) + 10 * D_th;
    double worst_u = 0, worst_full = 0, worst_u_th = 0, worst_full_th = 0;
    INFO("bounds " << bound_xy << " m (offset " << offset.transpose() << ", D " << D << "), " << bound_th << " rad");
    for (std::size_t i = 0; i < curve.samples.size(); ++i) {
        if (curve.samples[i].t < 1.0) continue;   // after the transient
        CHECK((u.samples[i].q - curve.samples[i].q).head<2>().norm() < bound_xy);
        CHECK(std::abs(u.samples[i].q[2] - curve.samples[i].q[2]) < bound_th);
        // Full dynamics add the U approximation's error: at this amplitude (tilt alpha/w^2 = 6e-3
        // rad) the dropped terms are ~2% of mu g, so drift rates differ by ~2%: over 20 s at the
        // field's turning rate (<= 0.1 rad/s) that is 0.04 rad; bound 0.1 rad.
        CHECK((full.samples[i].q - curve.samples[i].q).head<2>().norm() < bound_xy + 0.002);
        CHECK(std::abs(full.samples[i].q[2] - curve.samples[i].q[2]) < bound_th + 0.1);
        worst_u = std::max(worst_u, (u.samples[i].q - curve.samples[i].q).head<2>().norm());
        worst_full = std::max(worst_full, (full.samples[i].q - curve.samples[i].q).head<2>().norm());
        worst_u_th = std::max(worst_u_th, std::abs(u.samples[i].q[2] - curve.samples[i].q[2]));
        worst_full_th = std::max(worst_full_th, std::abs(full.samples[i].q[2] - curve.samples[i].q[2]));
    }
    WARN("Fig. 4 from rest: U vs field curve " << worst_u << " m, " << worst_u_th << " rad; full vs curve " << worst_full
                                               << " m, " << worst_full_th << " rad");
}

TEST_CASE("a part that cannot break away rides the plate: stuck all along, not moved", "[trajectory][stick]") {
    Scene sc = scene("fig4");
    for (auto& h : sc.plate.harmonics) h.amp *= 0.05;   // |p''| << mu g
    for (Dynamics level : {Dynamics::U, Dynamics::Full}) {
        const Vec3 q0(0.01, -0.02, 0.3);
        const Trajectory t = simulate(sc, level, q0, Vec3::Zero(), 1.0, 0.1);
        REQUIRE(t.stop.reason == StopReason::None);
        CHECK(t.samples.back().t == Approx(1.0));
        for (const auto& s : t.samples) {
            CHECK(s.mode.kind == ModeKind::Stuck);
            CHECK(s.q == q0);
            CHECK(s.qd.isZero());
        }
        CHECK(t.events.size() == 1u);   // the start: slide -> stuck at t = 0
        CHECK(t.held_time[0] == Approx(1.0));
    }
}

TEST_CASE("fig1 from rest: stuck at t = 0, breaks away at the root of the stick condition, then slides for 5 s",
          "[trajectory][stick]") {
    // Point part (fig1_point at (-0.04, 0.03)): held while |F(t)| <= mu N(t), with the U-dynamics'
    // needed force F = m (p'' + omega1' x s)_xy and N = m (p'' + omega1' x s + g e_z)_z (33). Its
    // root, found here by bisection from the plate's harmonics alone, is the break-away time.
    const Scene pt = scene("fig1_point");
    const Vec3 s(-0.04, 0.03, 0);
    auto margin = [&](double t) {
        Vec3 pdd, wd;
        pt.plate.acceleration(t, pdd, wd);
        const Vec3 a = pdd + wd.cross(s);
        return pt.part.friction().static_(0) * (a.z() + pt.g) - a.head<2>().norm();
    };
    REQUIRE(margin(0) > 0);
    double lo = 0, hi = 0;
    while (margin(hi) > 0) hi += 1e-5;
    for (int i = 0; i < 200; ++i) (margin(0.5 * (lo + hi)) > 0 ? lo : hi) = 0.5 * (lo + hi);
    const double tb_point = breakaway_time(pt, s, 0, Dynamics::U);
    CHECK(tb_point == Approx(hi).epsilon(1e-9));
    // Full dynamics: the plate's tilt at t ~ 0 changes the needed friction; the break-away comes later.
    // Independently: the plate's orientation R(t) by RK4 on R' = omega^ R from R(0) = exp(phi(0)^)
    // (the engine takes it from the harmonics' closed form), and the world-frame condition for the
    // plate point r = R s: the acceleration a = p'' + omega' x r + omega x (omega x r) plus g e_z split
    // along the plate's normal n = R e_z into N and the tangential part F; held while |F| <= mu N.
    struct Orientation {
        const PlateMotion& u;
        double t = 0;
        Mat3 R;
        explicit Orientation(const PlateMotion& m) : u(m) { reset(); }
        void reset() {
            Vec3 p, phi;
            u.displacement(0, p, phi);
            t = 0;
            R = phi.norm() > 0 ? Mat3(Eigen::AngleAxisd(phi.norm(), phi.normalized())) : Mat3::Identity();
        }
        Mat3 rate(double tt, const Mat3& Rm) const {
            Vec3 pd, w;
            u.velocity(tt, pd, w);
            Mat3 W;
            W << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
            return W * Rm;
        }
        Mat3 at(double T) {   // steps of 1e-7 s (omega h ~ 1e-7: RK4's error far below 1e-12)
            if (T < t) reset();
            while (t < T) {
                const double h = std::min(1e-7, T - t);
                const Mat3 k1 = rate(t, R), k2 = rate(t + h / 2, R + h / 2 * k1), k3 = rate(t + h / 2, R + h / 2 * k2),
                           k4 = rate(t + h, R + h * k3);
                R += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
                t += h;
            }
            return R;
        }
    };
    const auto first_root = [](auto&& held) {   // the first t > 0 where held(t) turns negative, to 1e-15 s
        double lo = 0, hi = 0;
        while (held(hi) > 0) hi += 1e-5;
        lo = hi - 1e-5;
        for (int i = 0; i < 40; ++i) (held(0.5 * (lo + hi)) > 0 ? lo : hi) = 0.5 * (lo + hi);
        return hi;
    };
    Orientation point_R(pt.plate);
    const double tb_point_full = first_root([&](double t) {
        const Mat3 R = point_R.at(t);
        Vec3 pdd, wd, pd, w;
        pt.plate.acceleration(t, pdd, wd);
        pt.plate.velocity(t, pd, w);
        const Vec3 r = R * s, F = pdd + wd.cross(r) + w.cross(w.cross(r)) + Vec3(0, 0, pt.g), n = R.col(2);
        return pt.part.friction().static_(0) * F.dot(n) - (F - F.dot(n) * n).norm();
    });
    CHECK(breakaway_time(pt, s, 0, Dynamics::Full) == Approx(tb_point_full).epsilon(1e-8));   // 7.2236e-4 s
    CHECK(tb_point_full > tb_point * 1.03);                                                   // the tilt delays it by 3.75 %

    // The rigid part of Fig. 1 at (-0.04, 0.03, 1.2): at rest it needs about an eighth of the friction
    // it can have, breaks away near 0.77 ms (U) and later in full dynamics; after it every contact
    // slides (no new stick) for at least 5 s.
    const Scene sc = scene("fig1");
    const Vec3 q0(-0.04, 0.03, 1.2);
    Workspace ws;
    mode_accelerations(sc, Dynamics::U, q0, Vec3::Zero(), plate_state(sc.plate, 0, Dynamics::U), Mode{ModeKind::Stuck}, ws);
    const double gamma0 = friction_gauge(sc.part, q0[2], ws.n, ws.F_needed, ws.tau_needed).gamma;
    CHECK(gamma0 > 0.08);
    CHECK(gamma0 < 0.2);
    const double tb_u = breakaway_time(sc, q0, 0, Dynamics::U), tb_full = breakaway_time(sc, q0, 0, Dynamics::Full);
    // The roots of 1 - gauge (the derived stick condition: the needed wrench against the friction set,
    // checked against brute force in test_dynamics.cpp), by bisection; in full dynamics with the
    // plate's orientation from the RK4 above. (Measured 7.7306e-4 and 7.9932e-4 s: the tilt delays
    // it by 3.4 %; doubling the tilt would give 6.8 %.)
    Orientation rigid_R(sc.plate);
    const auto held = [&](Dynamics level, double t) {
        const PlateState ps =
            level == Dynamics::U ? plate_state(sc.plate, t, level) : plate_state(sc.plate, t, level, rigid_R.at(t));
        mode_accelerations(sc, level, q0, Vec3::Zero(), ps, Mode{ModeKind::Stuck}, ws);
        return 1 - friction_gauge(sc.part, q0[2], ws.n, ws.F_needed, ws.tau_needed).gamma;
    };
    CHECK(tb_u == Approx(first_root([&](double t) { return held(Dynamics::U, t); })).epsilon(1e-8));
    CHECK(tb_full == Approx(first_root([&](double t) { return held(Dynamics::Full, t); })).epsilon(1e-8));
    CHECK(tb_full > 1.03 * tb_u);
    for (Dynamics level : {Dynamics::U, Dynamics::Full}) {
        const Trajectory tr = simulate(sc, level, q0, Vec3::Zero(), 5.0, 0.05);
        REQUIRE(tr.stop.reason == StopReason::None);
        REQUIRE(tr.events.size() == 2u);   // slide -> stuck at the start, stuck -> slide at the break-away
        CHECK(tr.events[0].to.kind == ModeKind::Stuck);
        CHECK(tr.events[1].to.kind == ModeKind::Slide);
        CHECK(tr.events[1].t == Approx(level == Dynamics::U ? tb_u : tb_full).epsilon(1e-6));
        CHECK(tr.samples.back().mode.kind == ModeKind::Slide);
    }
}

TEST_CASE("friction never does positive work, in every mode (slide, pivot, stuck)", "[trajectory][stick]") {
    // The friction power sum_i f_i . v_i follows from the motion alone: with J_xz = J_yz = 0 the
    // planar rows of (31)/(32) give sum_i f_i = m s'' + f_dagger,xy and sum_i r_i x f_i =
    // J_zz theta'' + tau_dagger,z, so P = (m s'' + f_dagger,xy) . s' + theta' (J_zz theta'' + tau_dagger,z)
    // (v_i = s' + theta' e_z x r_i). Coulomb friction dissipates: P <= 0 to rounding.
    struct Case {
        const char* scene;
        Vec3 q0;
        double duration;
    };
    for (const Case& c : {Case{"fig6", Vec3(-0.05, 0.016666666666666663, 4.487989505128276), 0.2},
                          Case{"fig1", Vec3(-0.04, 0.03, 1.2), 0.05}, Case{"fig1_point", Vec3(-0.04, 0.03, 0), 0.05}}) {
        const Scene sc = scene(c.scene);
        const Part& P = sc.part;
        const Trajectory tr = simulate(sc, Dynamics::U, c.q0, Vec3::Zero(), c.duration, 2e-5);
        REQUIRE(tr.stop.reason == StopReason::None);
        std::array<int, 3> seen{};
        double worst = -1e300, scale = 0;
        Workspace ws;
        for (const Sample& s : tr.samples) {
            ++seen[static_cast<int>(s.mode.kind)];
            mode_accelerations(sc, Dynamics::U, s.q, s.qd, plate_state(sc.plate, s.t, Dynamics::U), s.mode, ws);
            const double power = (P.m * ws.qdd.head<2>() + ws.b.head<2>()).dot(s.qd.head<2>()) +
                                 (P.point ? 0.0 : s.qd[2] * (P.J(2, 2) * ws.qdd[2] + ws.b[5]));
            worst = std::max(worst, power);
            scale = std::max(scale, P.friction().kinetic().maxCoeff() * P.m * sc.g * sc.v_ref());
        }
        INFO(c.scene << ": largest friction power " << worst << " W (scale mu m g v_ref = " << scale << " W); samples in slide "
                     << seen[0] << ", pivot " << seen[1] << ", stuck " << seen[2]);
        CHECK(worst <= 1e-9 * scale);
        CHECK(seen[0] > 0);
        if (std::string(c.scene) == "fig6")
            CHECK(seen[1] > 0);
        else
            CHECK(seen[2] > 0);
    }
}

TEST_CASE("a held contact's friction stays in its disk: no stick outlives its break-away", "[trajectory][stick]") {
    // The power test above holds by construction wherever friction opposes the slip; this one tests
    // the hold logic. While stuck the needed friction wrench must lie in the set the contacts can
    // supply (gauge gamma <= 1, modes.hpp's friction_gauge over the three disks), and while pivoting
    // the held contact's force in its own disk (|f_k| <= mu_k N_k). Samples every 2e-5 s are step
    // ends (the engine stops its steps at them), where the hold guards were just evaluated: a sample
    // outside the disk means a hold kept with its guard negative (a crossing missed, or choose_mode
    // picking the hold again past the rim); 1e-9 allowed for rounding. It does not time the
    // break-aways (a late root inside a step would still end the hold before the sample): that is
    // "fig1 from rest" above, against an independent root. Where the holds are sampled densely to
    // their end (fig6's pivots, heave_yaw's sticks: thousands of samples) they reach the rim
    // (measured 0.99996 and 0.99999), so checked against 0.99 mu (a model with 1 % less friction than
    // the engine's) those cases fail (measured 1.0101); fig1's brief sticks are sampled 39 times.
    struct Case {
        const char* scene;
        Vec3 q0;
        double duration;
        bool pivots, rim;
    };
    for (const Case& c :
         {Case{"fig6", Vec3(-0.05, 0.016666666666666663, 4.487989505128276), 0.2, true, true},
          Case{"fig1", Vec3(-0.04, 0.03, 1.2), 0.05, false, false}, Case{"fig1_point", Vec3(-0.04, 0.03, 0), 0.05, false, false},
          Case{"heave_yaw", Vec3(0.03, 0.02, 1.0), 0.2, false, true}}) {
        const Scene sc = scene(c.scene);
        const Part& P = sc.part;
        const Trajectory tr = simulate(sc, Dynamics::U, c.q0, Vec3::Zero(), c.duration, 2e-5);
        REQUIRE(tr.stop.reason == StopReason::None);
        double gamma = 0, pivot = 0;
        int stuck = 0, pivoting = 0;
        Workspace ws;
        for (const Sample& s : tr.samples) {
            const PlateState ps = plate_state(sc.plate, s.t, Dynamics::U);
            mode_accelerations(sc, Dynamics::U, s.q, s.qd, ps, s.mode, ws);
            if (s.mode.kind == ModeKind::Stuck) {
                ++stuck;
                gamma = std::max(gamma, friction_gauge(P, s.q[2], ws.n, ws.F_needed, ws.tau_needed).gamma);
            } else if (s.mode.kind == ModeKind::Pivot) {
                ++pivoting;
                const int k = s.mode.k;
                pivot = std::max(pivot, ws.f_held[k].norm() / (P.friction().static_(k) * ws.n[k]));
            }
        }
        INFO(c.scene << ": samples stuck " << stuck << ", pivoting " << pivoting << "; largest gauge " << gamma
                     << ", largest |f_k| / mu_k N_k " << pivot);
        CHECK(stuck + pivoting > 20);
        if (c.pivots)
            CHECK(pivoting > 0);
        else
            CHECK(stuck > 0);
        CHECK(gamma <= 1 + 1e-9);
        CHECK(pivot <= 1 + 1e-9);
        if (c.rim) CHECK(std::max(gamma, pivot) > 0.9999);   // the holds reach the rim: the check is not slack
    }
}

TEST_CASE("a loose tolerance does not invent sticks: fig4's sliding part stays sliding at rtol 1e-2 to 1e-4",
          "[trajectory][stick]") {
    // Fig. 4's part from (0.04, -0.04, 1.0) slides for 20 s without a stick (the rtol 1e-12 run has
    // no mode change). The engine's slip thresholds grow with rtol; were they not capped (hint speed
    // 1e-4 v_ref, zero bound 3e-3 v_ref, below the creep speed 1e-2 v_ref), rtol 1e-2 would count
    // every slip below 3 v_ref as zero: 797 sticks, 3 rad off. rtol bounds local, not global, error;
    // over these 400 periods it measured <= 1.6 rtol (rad, and rho); bound 10 rtol, empirical.
    const Scene sc = scene("fig4");
    const Vec3 q0(0.04, -0.04, 1.0);
    IntegrationOptions io;
    io.rtol = 1e-12;
    const Trajectory ref = simulate(sc, Dynamics::Full, q0, Vec3::Zero(), 20, 20, io);
    REQUIRE(ref.stop.reason == StopReason::None);
    REQUIRE(ref.stats.mode_switches == 0);
    for (double rtol : {1e-2, 1e-3, 1e-4}) {
        io.rtol = rtol;
        const Trajectory tr = simulate(sc, Dynamics::Full, q0, Vec3::Zero(), 20, 20, io);
        INFO("rtol " << rtol);
        REQUIRE(tr.stop.reason == StopReason::None);
        CHECK(tr.stats.mode_switches == 0);
        const Vec3 d = tr.samples.back().q - ref.samples.back().q;
        CHECK(d.head<2>().norm() < 10 * rtol * sc.part.rho());
        CHECK(std::abs(d[2]) < 10 * rtol);
    }
}

TEST_CASE("a loose tolerance still finds the sticks that matter: sticking cycles within twice the cycle tolerance",
          "[trajectory][stick]") {
    // The other side of the capped thresholds: cycles that do stick (heave_yaw, fig6) at rtol 1e-3 and
    // 1e-4 (cycle tol 10 rtol), against tol 1e-9 / rtol 1e-10. Measured, capped: at most 9.4 rtol v_ref
    // (fig6 at (-0.0333, 0.0167, 4.488), whose 0.1-period stick rtol 1e-3 misses); uncapped the same
    // cycles were up to 48 rtol off (the thresholds held slips that were not stuck). Bound: twice the
    // cycle tolerance, 20 rtol.
    struct Case {
        const char* scene;
        Vec3 q;
    };
    const Case cases[] = {{"heave_yaw", Vec3(0, 0.02, 0)},
                          {"heave_yaw", Vec3(0.03, 0.02, 1.0)},
                          {"fig6", Vec3(-0.05 + 1.0 / 60, 1.0 / 60, 2 * kPi * 5 / 7)},
                          {"fig6", Vec3(0.0167, 0, 2.693)}};
    for (const Case& c : cases) {
        const Scene sc = scene(c.scene);
        const Vec3 S(sc.v_ref(), sc.v_ref(), sc.v_ref() / sc.part.rho());
        LimitCycleOptions ref;
        ref.tol = 1e-9;
        ref.integration.rtol = 1e-10;
        const LimitCycleSummary r = limit_cycle(sc, c.q, ref);
        REQUIRE(r.converged);
        REQUIRE(*std::max_element(r.stick_fraction.begin(), r.stick_fraction.end()) > 0);   // it sticks
        for (double rtol : {1e-3, 1e-4}) {
            INFO(c.scene << " at (" << c.q.transpose() << "), rtol " << rtol);
            LimitCycleOptions o;
            o.tol = 10 * rtol;
            o.integration.rtol = rtol;
            const LimitCycleSummary l = limit_cycle(sc, c.q, o);
            REQUIRE(l.converged);
            CHECK((l.twist - r.twist).cwiseQuotient(S).cwiseAbs().maxCoeff() < 2 * o.tol);
        }
        // The stick fractions at the default tolerances (rtol 1e-8): within 1e-3 of the period of the
        // tight ones -- event times to ~rtol T, and a slip taken as zero below zero_abs (3e2 rtol v_ref)
        // holds it for ~zero_abs / (mu g) per event, 1e-5 T here. (At rtol >= 1e-5 the capped zero bound,
        // 3e-3 v_ref, counts a slide that slow as held: heave_yaw's third contact at (0, 0.02, 0) 0.87
        // of the period against 0.78; the twist stays within the bound above.)
        const LimitCycleSummary d = limit_cycle(sc, c.q);
        REQUIRE(d.converged);
        for (int i = 0; i < 3; ++i) {
            INFO(c.scene << " at (" << c.q.transpose() << "), contact " << i + 1);
            CHECK(std::abs(d.stick_fraction[i] - r.stick_fraction[i]) < 1e-3);
        }
    }
}

TEST_CASE("stroboscopic averaging: fig4's 20 s from rest at a fraction of the cost, coning included", "[trajectory][averaged]") {
    // Against the full dynamics at rtol 1e-10. Heun's macro steps held to macro_tol 1e-2 locally (rho,
    // rho, 1 rad); over the run the error stays about that: bound macro_tol.
    const Scene sc = scene("fig4");
    const Vec3 q0(0.04, -0.04, 1.0);
    IntegrationOptions tight;
    tight.rtol = 1e-10;
    const Trajectory ref = simulate(sc, Dynamics::Full, q0, Vec3::Zero(), 20, 0.05, tight);
    IntegrationOptions io;
    io.rtol = 1e-5;
    AveragingOptions avg;
    avg.macro_tol = 1e-2;
    const Trajectory tr = simulate_averaged(sc, q0, Vec3::Zero(), 20, 0.05, io, avg);
    REQUIRE(tr.stop.reason == StopReason::None);
    REQUIRE(tr.samples.size() == ref.samples.size());
    // Every sample (the direct start's, the macro phase's Hermite interpolants, the direct end's), in
    // (rho, rho, 1 rad) -- not only the last, which sits in a sink that damps earlier errors.
    auto worst = [&](const Trajectory& a) {
        double e = 0;
        for (std::size_t k = 0; k < a.samples.size(); ++k) {
            const Vec3 dk = a.samples[k].q - ref.samples[k].q;
            e = std::max({e, dk.head<2>().norm() / sc.part.rho(), std::abs(dk[2])});
        }
        return e;
    };
    const double e1 = worst(tr);
    CHECK(e1 < avg.macro_tol);   // (measured 7.2e-3; before the start waited for the twist to settle: 2.4e-2 at 0.8 s)
    // Heun's method under local error control: the global error goes as macro_tol^(2/3), a quarter of
    // the tolerance divides it by 4^(2/3) = 2.5 (a first-order method's by 2; a bias that the macro
    // steps do not control, by 1). Measured 2.65.
    AveragingOptions quarter = avg;
    quarter.macro_tol = avg.macro_tol / 4;
    const Trajectory t4 = simulate_averaged(sc, q0, Vec3::Zero(), 20, 0.05, io, quarter);
    REQUIRE(t4.samples.size() == ref.samples.size());
    CHECK(e1 / worst(t4) > 2.2);
    const Vec3 d = tr.samples.back().q - ref.samples.back().q;
    CHECK(tr.samples.back().t == Approx(20));
    CHECK(d.head<2>().norm() < avg.macro_tol * sc.part.rho());
    CHECK(std::abs(d[2]) < avg.macro_tol);
    const Trajectory direct = simulate(sc, Dynamics::Full, q0, Vec3::Zero(), 20, 20, io);
    CHECK(tr.stats.rhs_evals < direct.stats.rhs_evals);   // (cheaper at the same rtol; measured 13 000 vs 28 000)
    // Coning, which the asymptotic field cannot see: from the fixed point the part turns at the plate's
    // yaw drift -1e4 / (2 (40 pi)^3) rad/s (design.hpp; the full dynamics follow it to 1e-5). Over
    // 100 s, within 2 % (the macro steps' error on a slope this smooth is far below).
    const double w = 2 * kPi / sc.plate.T, cone = -1e4 / (2 * w * w * w);
    const Trajectory still = simulate_averaged(sc, Vec3::Zero(), Vec3::Zero(), 100, 50, io, avg);
    REQUIRE(still.stop.reason == StopReason::None);
    REQUIRE(still.samples.size() == 3u);
    CHECK((still.samples[2].q[2] - still.samples[1].q[2]) / 50 == Approx(cone).epsilon(0.02));
}

TEST_CASE("a point part on a plate that heaves and twists about z follows the field's integral curve", "[trajectory][point]") {
    // heave_yaw_point: the plate's twist about z pushes the part along the tangent to its circle about
    // the origin (the Euler force -m w1' x s of (33)), the heave modulates the friction that resists
    // it, and the field drives the part about the origin. The U-dynamics from rest (their own kernels,
    // b~ (33) and the point part's solve) must follow the integral curve of the field, which is
    // computed from the reduced U-dynamics' cycles (the reduced kernels, (35)): two generations of the
    // same terms, and a wrong sign in either sends the curves apart at O(1).
    const Scene sc = scene("heave_yaw_point");
    const double dur = 20, dt = 1;
    for (const Vec3& q0 : {Vec3(0.05, 0.04, 0), Vec3(-0.03, 0.06, 0)}) {
        const Trajectory u = simulate(sc, Dynamics::U, q0, Vec3::Zero(), dur, dt);
        const Trajectory curve = field_curve(sc, q0, dur, dt);
        REQUIRE(u.stop.reason == StopReason::None);
        REQUIRE(curve.stop.reason == StopReason::None);
        REQUIRE(u.samples.size() == curve.samples.size());
        const Vec2 moved = curve.samples.back().q.head<2>() - q0.head<2>();
        double worst = 0;
        for (std::size_t i = 1; i < u.samples.size(); ++i)
            worst = std::max(worst, (u.samples[i].q - curve.samples[i].q).head<2>().norm());
        INFO("start " << q0.transpose() << ": moved " << moved.norm() << " m, worst distance from the curve " << worst << " m");
        // Measured: it moves 13.6 and 18.9 mm (0.21 and 0.28 of its distance from the origin), and stays
        // within 0.11 and 0.14 mm (0.85 and 0.76 % of that) of the curve; bounds at about 3x.
        CHECK(moved.norm() > 0.15 * q0.head<2>().norm());
        CHECK(worst < 0.025 * moved.norm());
    }
}
