// The integration methods of the speed-accuracy study, the limit-cycle solvers, event location
// and the model hierarchy.
#include "plate/field.hpp"
#include "plate/hierarchy.hpp"
#include "plate/random_scene.hpp"
#include "plate/methods.hpp"
#include "plate/scene_io.hpp"
#include "plate/simulate.hpp"
#include "plate/study.hpp"
#include "shipped_scenes.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace plate;

namespace {

using plate_tests::scene;

// y'' = -y with y(0) = 1, y'(0) = 0: y = cos t (smooth; exact solution known).
OdeSystem oscillator() {
    OdeSystem s;
    s.n = 2;
    s.f = [](double, const double* y, double* f) {
        f[0] = y[1];
        f[1] = -y[0];
    };
    s.jac = [](double, const double*, double* J, double* dfdt) {
        J[0] = 0;
        J[1] = 1;
        J[2] = -1;
        J[3] = 0;
        dfdt[0] = dfdt[1] = 0;
    };
    return s;
}

}   // namespace

TEST_CASE("every fixed-step method converges at its order on a smooth problem", "[methods]") {
    // The pendulum theta'' = -sin theta from theta = 1 at rest, over [0, 6.4]: nonlinear and analytic
    // (a linear test problem would flatter methods whose stability polynomial matches e^z beyond
    // their order). Richardson: with steps h, h/2, h/4 the differences of the results fall by 2^p.
    OdeSystem s;
    s.n = 2;
    s.f = [](double, const double* y, double* f) {
        f[0] = y[1];
        f[1] = -std::sin(y[0]);
    };
    s.jac = [](double, const double* y, double* J, double* dfdt) {
        J[0] = 0;
        J[1] = 1;
        J[2] = -std::cos(y[0]);
        J[3] = 0;
        dfdt[0] = dfdt[1] = 0;
    };
    for (const auto& mi : all_methods()) {
        if (mi.order == 0) continue;
        const double h = mi.order >= 8 ? 0.4 : 0.1;
        double r[3];
        for (int k = 0; k < 3; ++k) {
            std::vector<double> y{1, 0};
            MethodOptions o;
            o.h = h / (1 << k);
            o.fixed = true;
            MethodRun run;
            REQUIRE(integrate(mi.method, s, 0, 6.4, y, o, run));
            r[k] = y[0];
        }
        const double d1 = std::abs(r[0] - r[1]), d2 = std::abs(r[1] - r[2]);
        const double p = std::log2(d1 / d2);
        INFO(mi.name << ": differences " << d1 << ", " << d2 << ", observed order " << p);
        CHECK(d2 > 1e-13);   // above rounding
        // The next term of the error expansion shifts the observed order by O(h) (measured here: +0.3
        // for RK4, +0.5 for the eighth-order pair); a method of the wrong order is off by >= 1.
        CHECK(std::abs(p - mi.order) < 0.65);
    }
}

TEST_CASE("every adaptive method meets its tolerance on a smooth problem", "[methods]") {
    // Each accepted step's local error is below tol (absolute and relative, |y| <= 1 here), and the
    // oscillator neither amplifies nor damps errors: the global error is at most the sum of the
    // local ones, steps x tol (x 2 for the controllers' estimate of the local error).
    for (const auto& mi : all_methods()) {
        if (!mi.adaptive) continue;
        for (double tol : {1e-6, 1e-9}) {
            const OdeSystem s = oscillator();
            std::vector<double> y{1, 0};
            MethodOptions o;
            o.tol = tol;
            MethodRun run;
            REQUIRE(integrate(mi.method, s, 0, 2, y, o, run));
            const double e = std::hypot(y[0] - std::cos(2.0), y[1] + std::sin(2.0));
            INFO(mi.name << " tol " << tol << ": error " << e << " after " << run.steps << " steps");
            CHECK(e <= 2 * run.steps * tol);
        }
    }
}

TEST_CASE("methods fail clearly: a Jacobian that is needed but missing, an exhausted budget", "[methods]") {
    OdeSystem s = oscillator();
    s.jac = nullptr;
    for (Method m : {Method::Rosenbrock4, Method::GslMsbdf, Method::GslBsimp}) {
        std::vector<double> y{1, 0};
        MethodRun run;
        CHECK_FALSE(integrate(m, s, 0, 1, y, MethodOptions{}, run));
        CHECK(run.failure.find("Jacobian") != std::string::npos);
    }
    // A right-hand side with a discontinuity the controller cannot pass (sign(y) at y = 0 with y' =
    // -sign(y)): chatter, ended by the evaluation budget, never a hang.
    OdeSystem chatter;
    chatter.n = 1;
    chatter.f = [](double, const double* y, double* f) { f[0] = y[0] > 0 ? -1.0 : 1.0; };
    std::vector<double> y{0.5};
    MethodOptions o;
    o.tol = 1e-12;
    o.max_evals = 200000;
    MethodRun run;
    CHECK_FALSE(integrate(Method::Dopri5, chatter, 0, 2, y, o, run));
    CHECK((run.failure.find("budget") != std::string::npos || run.failure.find("collapse") != std::string::npos));
    CHECK(run.rhs_evals <= o.max_evals + 20);
}

TEST_CASE("event location: a part sliding on a still plate stops at v0 / (mu g) to 1e-10 s", "[methods][events]") {
    // Kinetic friction decelerates a sliding part at mu g exactly (the plate does not move), so
    // the slip reaches zero at t* = v0 / (mu g), where static friction holds it: stuck from t* on.
    for (const char* name : {"fig1_point", "fig5"}) {
        Scene sc = scene(name);
        for (auto& h : sc.plate.harmonics) h.amp = 0;
        const double mu = sc.part.friction().kinetic(0), g = sc.g, v0 = 0.05;
        sc.part.mu = Vec3::Constant(mu);
        const double t_star = v0 / (mu * g);
        const Trajectory tr = simulate(sc, Dynamics::U, Vec3(0.01, 0.02, 0), Vec3(v0, 0, 0), 2 * t_star, t_star / 4);
        INFO(name << ": stop " << tr.stop.describe() << ", expected t* = " << t_star);
        REQUIRE(tr.stop.reason == StopReason::None);
        REQUIRE(tr.events.size() == 1u);
        CHECK(tr.events[0].to.kind == ModeKind::Stuck);
        CHECK(std::abs(tr.events[0].t - t_star) < 1e-10);
        // x(t) = x0 + v0 t - mu g t^2 / 2 before t*, x0 + v0^2 / (2 mu g) after (uniform deceleration).
        for (const auto& smp : tr.samples) {
            const double t = std::min(smp.t, t_star);
            CHECK(smp.q[0] - 0.01 == Approx(v0 * t - 0.5 * mu * g * t * t).margin(1e-12));
        }
    }
}

TEST_CASE("limit-cycle solvers agree: period by period, Anderson and Newton shooting", "[limit_cycle][methods]") {
    for (const char* name : {"fig4", "fig5", "fig3_random", "fig1_point"}) {
        const Scene sc = scene(name);
        const Vec3 q(0.03, -0.02, sc.part.point ? 0.0 : 0.7);
        LimitCycleOptions o;
        o.tol = 1e-9;
        o.integration.rtol = 1e-10;
        o.solver = CycleSolver::PeriodByPeriod;
        const LimitCycleSummary a = limit_cycle(sc, q, o);
        o.solver = CycleSolver::Anderson;
        const LimitCycleSummary b = limit_cycle(sc, q, o);
        o.solver = CycleSolver::Newton;
        const LimitCycleSummary c = limit_cycle(sc, q, o);
        INFO(name << "\n" << a.report() << b.report() << c.report());
        REQUIRE(a.converged);
        REQUIRE(b.converged);
        REQUIRE(c.converged);
        const double v = sc.v_ref(), w = v / sc.part.rho();
        const Vec3 scale(v, v, w);
        // Each estimates its distance to the cycle below tol = 1e-9; the estimates are heuristics (a
        // measured contraction), so allow 100x: 1e-7 between them, far below any charted accuracy.
        CHECK(((a.twist - b.twist).array() / scale.array()).abs().maxCoeff() < 1e-7);
        CHECK(((a.twist - c.twist).array() / scale.array()).abs().maxCoeff() < 1e-7);
        // Anderson needs fewer periods than plain iteration.
        CHECK(b.periods < a.periods);
    }
}

TEST_CASE("the generated Jacobian of the reduced U-dynamics matches central differences", "[methods][kernels]") {
    for (const char* name : {"fig4", "fig3_random", "fig1_point"}) {
        const Scene sc = scene(name);
        for (FrictionLaw law : {FrictionLaw::Coulomb, FrictionLaw::Tanh, FrictionLaw::Linear}) {
            Workspace ws;
            ws.law = law;
            ws.law_eps = 0.2 * sc.v_ref();   // wide, so that the states below sit inside and outside it
            const Vec3 q(0.02, -0.01, 0.5);
            for (const Vec3& qd0 : {Vec3(0.05, -0.03, 1.5), Vec3(0.01, 0.004, -0.3)}) {
                const Vec3 qd = sc.part.point ? Vec3(qd0[0], qd0[1], 0) : qd0;
                const PlateState ps = plate_state(sc.plate, 0.013, Dynamics::ReducedU);
                Mat3 J, F;
                twist_jacobian(sc, Dynamics::ReducedU, q, qd, ps, ws, J);
                for (int j = 0; j < 3; ++j) {
                    const double h = 1e-6 * std::max(1.0, std::abs(qd[j]));
                    Vec3 a = qd, b = qd;
                    a[j] += h;
                    b[j] -= h;
                    accelerations(sc, Dynamics::ReducedU, q, a, ps, ws);
                    const Vec3 fa = ws.qdd;
                    accelerations(sc, Dynamics::ReducedU, q, b, ps, ws);
                    F.col(j) = (fa - ws.qdd) / (2 * h);
                }
                INFO(name << " " << friction_law_name(law) << "\n" << J << "\n\n" << F);
                // Central differences: error ~ h^2 f''' ~ 1e-12 relative, rounding ~ 1e-16/h ~ 1e-10.
                CHECK((J - F).norm() <= 1e-6 * (1 + F.norm()));
            }
        }
    }
}

TEST_CASE("auto never picks a model whose measured error exceeds the tolerance on the shipped scenes", "[hierarchy]") {
    struct Q {
        const char* scene;
        Vec3 q0;
    };
    for (const Q& q :
         {Q{"fig4", Vec3(0.04, -0.04, 1.0)}, Q{"fig5", Vec3(0.02, -0.01, 0.5)}, Q{"fig3_random", Vec3(0.02, -0.01, 0.5)}}) {
        const Scene sc = scene(q.scene);
        for (double tol : {3e-2, 1e-2}) {
            const ModelChoice mc = choose_model(sc, q.q0, 1.0, tol);
            INFO(q.scene << "\n" << mc.explain());
            REQUIRE(mc.picked.ok);
            CHECK(mc.picked.error <= tol);
            // Measured again, independently, at tighter integration tolerances: still within tol.
            IntegrationOptions tight;
            tight.rtol = 1e-11;
            const Trajectory ref = simulate(sc, Dynamics::Full, q.q0, Vec3::Zero(), 1.0, 1.0, tight);
            const Scene s = simplified(sc, mc.picked.part);
            Trajectory tr;
            if (mc.picked.dynamics == Dynamics::ReducedU) {
                LimitCycleOptions lo;
                lo.tol = 1e-9;
                lo.integration.rtol = 1e-10;
                tr = field_curve(s, q.q0, 1.0, 1.0, lo, std::min(s.plate.T, 1.0 / 20));
            } else {
                tr = simulate(s, mc.picked.dynamics, q.q0, Vec3::Zero(), 1.0, 1.0, tight);
            }
            REQUIRE(ref.stop.reason == StopReason::None);
            REQUIRE(tr.stop.reason == StopReason::None);
            const Vec3 d = tr.samples.back().q - ref.samples.back().q;
            const double err =
                std::max({std::abs(d[0]) / sc.part.rho(), std::abs(d[1]) / sc.part.rho(), std::abs(wrap_angle(d[2]))});
            CHECK(err <= tol);
        }
    }
}

TEST_CASE("a-priori auto: the error estimates bound the measured errors on seeded random scenes", "[hierarchy][auto]") {
    // Validation on scenes the safety factor was not chosen on (seeds 5000+; it was set on 1000+,
    // where it bounds 96% at 10 s and >= 99.5% up to 3 s): the prediction must bound the measured
    // error of every rung in >= 95% of cases.
    int total = 0, bounded = 0;
    for (int k = 0; k < 12; ++k) {
        RandomSceneOptions ro;
        ro.thin = k % 3 == 0;
        const Scene sc = random_scene(5000 + static_cast<std::uint64_t>(k), ro);
        Rng r(77 + k);
        const Vec3 q0{r.uniform(-0.02, 0.02), r.uniform(-0.02, 0.02), r.uniform(-kPi, kPi)};
        const ModelChoice mc = choose_model(sc, q0, 1.0, 1e-2);
        const ModelEstimate est = estimate_model_errors(sc, q0, 1.0);
        if (!est.ok || mc.rungs.size() < 2) continue;
        const PartModel own = mc.rungs.back().part;
        for (const auto& rg : mc.rungs) {
            if (&rg == &mc.rungs.back() || !rg.ok) continue;
            ++total;
            bounded += est.predicted(rg.part, own, rg.dynamics) >= rg.error;
        }
    }
    INFO(bounded << " of " << total);
    CHECK(total >= 60);
    CHECK(bounded >= 0.95 * total);
}

TEST_CASE("a-priori auto picks the cheaper rung where it is exact by construction, and verifies it", "[hierarchy][auto]") {
    // A plate that only translates: U-dynamics drop nothing (no tilt, no Coriolis, no centripetal
    // terms), and a part symmetric about the drive with equal friction drifts like a point, without
    // turning. auto must not run the full model; the error it accepts is measured within tol, and
    // the estimate costs less than half of the answer (right-hand sides, the 20 s question; its time
    // against the full model's is in bench_auto).
    for (const char* name : {"fig4", "fig1"}) {
        INFO(name);
        Scene sc = scene(name);
        std::vector<Harmonic> translation;
        for (const auto& h : sc.plate.harmonics)
            if (h.axis == Axis::x || h.axis == Axis::y || h.axis == Axis::z) translation.push_back(h);
        sc.plate.harmonics = translation;
        const Vec3 q0(0.02, -0.01, 0.5);
        const APrioriChoice c = choose_model_a_priori(sc, q0, 20.0, 1e-2, true);
        INFO(c.explain());
        REQUIRE(c.estimate.ok);
        CHECK(c.estimate.eps_U == 0);
        CHECK(c.picked.dynamics != Dynamics::Full);
        REQUIRE(c.verified);
        CHECK(c.measured <= 1e-2);
        CHECK(c.predicted <= 1e-2);
        // The picked rung is exact here, so what is measured is the two runs' integration error (rtol
        // 1e-9 each, at most about 10 rtol over the 20 s: "a loose tolerance does not invent sticks";
        // fig1's 9.7e-9, 1.8e-11 at rtol 1e-10), which the prediction of the model's error leaves out.
        CHECK(c.measured <= c.predicted + 2 * 10 * IntegrationOptions{}.rtol);
        CHECK(c.estimate.work < 0.5 * c.reference_work);
    }
    // Where nothing simpler is predicted within tol the scene's own model runs, and alone.
    const Scene f4 = scene("fig4");
    const APrioriChoice c = choose_model_a_priori(f4, Vec3(0.02, -0.01, 0.5), 20.0, 1e-3, false);
    CHECK(c.picked.dynamics == Dynamics::Full);
    CHECK_FALSE(c.verified);
}

TEST_CASE("a-priori auto: a part made nearly thin picks the thin rung, and a spinning plate keeps U out", "[hierarchy][auto]") {
    // fig6's part with its contacts raised to a thousandth of their depth and J_xz = J_yz = 0: the
    // thin simplification is exact to first order. fig6's plate spins about z (no tilt): U-dynamics
    // drop its angular velocity, which the U-vs-full transient and the Coriolis term must see (an
    // estimate that looked only at the tilt predicted 0.003 for thin / U, measured 0.52).
    Scene sc = scene("fig6");
    for (auto& c : sc.part.c) c.z() *= 1e-3;
    sc.part.J(0, 2) = sc.part.J(2, 0) = sc.part.J(1, 2) = sc.part.J(2, 1) = 0;
    REQUIRE_FALSE(sc.part.thin());
    const APrioriChoice c = choose_model_a_priori(sc, Vec3(0.02, -0.01, 0.5), 20.0, 1e-2, true);
    INFO(c.explain());
    CHECK(c.picked.part == PartModel::Thin);
    CHECK(c.picked.dynamics == Dynamics::Full);
    REQUIRE(c.verified);
    CHECK(c.measured <= c.predicted);
    CHECK(c.estimate.dynamics_term(Dynamics::U) > 1e-2);
}

TEST_CASE("every method gets the engine's start and restart rule (issue 15's failure maps)", "[methods][restart]") {
    // Random scene 226 at this configuration: released at rest, the part loses a contact in its
    // transient (it would tip), while its sliding cycle keeps all three: the engine starts again
    // from another twist (limit_cycle's rule). A general method given the same rule reaches the same
    // cycle instead of being charged with a contact loss the engine also met.
    // (The configuration was drawn by Rng(226) when g++ evaluated Vec3's arguments last to first; the
    // draws are now in order on every compiler, so it is written out.)
    const Scene sc = random_scene(226);
    const Vec3 q0(-0.012930818368603558, -0.0022664680119125584, 0.6638159462880342);
    const LimitCycleSummary lc = limit_cycle(sc, q0);
    REQUIRE(lc.converged);
    REQUIRE(lc.restarts > 0);
    REQUIRE_FALSE(lc.transient_stops.empty());
    CHECK(lc.transient_stops[0].reason == StopReason::ContactLost);
    Solver s;
    s.method = Method::Dopri5;
    const RunResult run = twist_run(sc, q0, s, 1e-8, 1e-8);
    INFO(run.failure);
    REQUIRE(run.ok);
    // Both at rtol 1e-8 and cycle tolerance ~1e-7: within 1e-6 v_ref (measured 7e-8).
    CHECK(twist_error(sc, run.value, {lc.twist[0], lc.twist[1], lc.twist[2]}) < 1e-6);
}
