// Stick-slip against an independent reference (issue 14, point 6): the regularised-friction law
// f = -mu N v / sqrt(|v|^2 + eps^2) has no stick, no modes and no events; its cycles, integrated by
// GSL's implicit Bulirsch-Stoer and extrapolated to eps -> 0 with the observed order
// (regularised_reference, study.hpp), must give the event-driven engine's twists.
#include "plate/field.hpp"
#include "plate/scene_io.hpp"
#include "plate/study.hpp"
#include "shipped_scenes.hpp"

#include <Eigen/SVD>
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

using namespace plate;

namespace {

using plate_tests::scene;

double twist_distance(const Scene& sc, const Vec3& a, const Vec3& b) {
    const double v = sc.v_ref();
    return (a - b).cwiseQuotient(Vec3(v, v, v / sc.part.rho())).cwiseAbs().maxCoeff();
}

// Does the cycle's last period change into mode `kind` somewhere?
bool enters(const LimitCycleSummary& lc, ModeKind kind) {
    return std::any_of(lc.mode_events.begin(), lc.mode_events.end(), [&](const ModeEvent& e) { return e.to.kind == kind; });
}

// dP/dx at start x by central differences of the period map, h of the scales (v_ref, v_ref,
// v_ref / rho), in those scales; false if a period leaves the model.
bool central_monodromy(const Scene& sc, const Vec3& q, const Vec3& x, double h, const IntegrationOptions& io, Mat3& M) {
    const Vec3 S(sc.v_ref(), sc.v_ref(), sc.v_ref() / sc.part.rho());
    for (int j = 0; j < 3; ++j) {
        Vec3 xp = x, xm = x, Pp, Pm;
        xp[j] += h * S[j];
        xm[j] -= h * S[j];
        if (!period_map(sc, q, xp, Pp, io) || !period_map(sc, q, xm, Pm, io)) return false;
        M.col(j) = (Pp - Pm).cwiseQuotient(S) / (2 * h);
    }
    return true;
}

}   // namespace

TEST_CASE("regularised reference: where nothing sticks it is today's twist at every eps", "[stick][reference]") {
    const Scene sc = scene("fig6");
    // (0.05, 0.05, 0): fig6's corner slides all period long (the engine's mode record says so).
    const Vec3 q(0.05, 0.05, 0);
    LimitCycleOptions o;
    o.integration.rtol = 1e-10;
    o.tol = 1e-9;
    const LimitCycleSummary lc = limit_cycle(sc, q, o);
    REQUIRE(lc.converged);
    REQUIRE(lc.stick_fraction[0] + lc.stick_fraction[1] + lc.stick_fraction[2] == 0.0);
    const RegularisedReference r = regularised_reference(sc, q);
    REQUIRE(r.ok);
    // Away from zero slip the regularised law differs from Coulomb by eps^2 / (2 |v|^2) relative: 5e-7 at
    // the largest eps (1e-5 v_ref) for a slip of 1e-2 v_ref, far less for the slips here, which stay well
    // above that (the difference is measured: 1.2e-10 at most over the eps; bound 4e-10).
    for (const Vec3& t : r.twists) CHECK(twist_distance(sc, lc.twist, t) < 4e-10);
}

TEST_CASE("stick-slip: fig6's pivoting cycles agree with the regularised-friction limit to 1e-7 v_ref", "[stick][reference]") {
    // The configurations of fig6's default 7x7x7 grid whose cycle holds a contact (a pivot) but is
    // never stuck as a whole, every fourth in grid order; the engine at rtol 1e-10 with cycles to 1e-9 (at 1e-9 one
    // of them was 2e-7 off with the creep's error budget at 10 rtol v_ref; it is 100 rtol now).
    // The bound: 1e-7 v_ref, three times the largest difference measured (3.4e-8; the reference's own
    // error estimate -- its Richardson correction and the change of the extrapolated limit from the
    // previous triple of eps -- is up to 2.3e-7 here, pessimistic).
    // (Cycles with a phase stuck as a whole: the next tests, and the report's table in every run.)
    const Scene sc = scene("fig6");
    const GridSpec grid;
    int seen = 0, checked = 0, substantial = 0;
    double worst = 0;
    for (int idx = 0; idx < grid.size(); ++idx) {
        const int i = idx / (grid.ny * grid.nth), j = (idx / grid.nth) % grid.ny, k = idx % grid.nth;
        const Vec3 q = grid.at(i, j, k);
        const LimitCycleSummary first = limit_cycle(sc, q);   // the default settings select
        REQUIRE(first.converged);
        const LimitCycleSummary& lc = first;
        const bool pivots = std::any_of(lc.stick_fraction.begin(), lc.stick_fraction.end(), [](double f) { return f > 0; });
        const bool stuck = lc.start_mode.kind == ModeKind::Stuck || enters(lc, ModeKind::Stuck);
        if (!pivots || stuck || seen++ % 4) continue;
        LimitCycleOptions o;
        o.integration.rtol = 1e-10;
        o.tol = 1e-9;
        const LimitCycleSummary tight = limit_cycle(sc, q, o);
        REQUIRE(tight.converged);
        const RegularisedReference r = regularised_reference(sc, q);
        REQUIRE(r.ok);
        const double d = twist_distance(sc, tight.twist, r.twist);
        INFO("q = (" << q[0] << ", " << q[1] << ", " << q[2] << "): engine " << tight.twist.transpose() << ", reference "
                     << r.twist.transpose() << " (order " << r.order << ", error " << r.error << ")");
        CHECK(d <= 1e-7);   // measured 3.4e-8 at most (the reference's own estimate up to 2.3e-7)
        // The reference itself must have converged in eps (a forced order of 0.1 means it did not, and
        // would widen the bound above through r.error): an observed order well above that, a small error.
        CHECK(r.order > 0.5);
        CHECK(r.error < 7e-7);   // measured 2.3e-7 at most
        // Near a stick the regularised law's error shrinks more slowly than eps: the observed order is below 1.
        CHECK(r.order < 1.2);
        worst = std::max(worst, d);
        ++checked;
        substantial += *std::max_element(tight.stick_fraction.begin(), tight.stick_fraction.end()) > 0.05;
    }
    INFO("largest difference " << worst);
    CHECK(checked >= 8);
    CHECK(substantial >= 8);   // cycles in which a contact is held more than 5% of the period
}

TEST_CASE("shooting through stick-slip: a full stick's monodromy is zero, a pivot's is the period map's derivative",
          "[limit_cycle][stick]") {
    // Warm-started 1e-4 of the scales off a cycle (as a field's or a design's neighbour would), the
    // shooting solver must reach the period-by-period cycle (tol 1e-10) within its tolerance,
    // 1e-7 v_ref, with a monodromy of its own (not Anderson's fallback).
    struct Case {
        const char* scene;
        Vec3 q;
        bool full_stick;
    };
    const Case cases[] = {{"heave_yaw", Vec3(0.03, 0.02, 1.0), true},                            // stuck, slides, stuck again
                          {"fig6", Vec3(-0.05 + 1.0 / 60, 1.0 / 60, 2 * kPi * 5 / 7), false}};   // pivots about 1
    for (const Case& c : cases) {
        INFO(c.scene);
        const Scene sc = scene(c.scene);
        LimitCycleOptions plain;
        plain.solver = CycleSolver::PeriodByPeriod;
        plain.tol = 1e-10;
        const LimitCycleSummary ref = limit_cycle(sc, c.q, plain);
        REQUIRE(ref.converged);
        const bool stuck = enters(ref, ModeKind::Stuck);
        const bool pivots = enters(ref, ModeKind::Pivot);
        REQUIRE(stuck == c.full_stick);
        REQUIRE((pivots || stuck));
        const Vec3 S(sc.v_ref(), sc.v_ref(), sc.v_ref() / sc.part.rho());
        const Vec3 warm = ref.qd_start + Vec3(1e-4, -1e-4, 1e-4).cwiseProduct(S);
        const LimitCycleSummary sh = limit_cycle(sc, c.q, LimitCycleOptions{}, warm);
        REQUIRE(sh.converged);
        CHECK(sh.has_monodromy);
        {
            // The twist within the solver's tolerance of the period-by-period cycle, both integrated at
            // rtol 1e-10: at the default 1e-8 two solvers' runs differ by the integration's own error,
            // which depends on their step histories (fig6's cycle here: 2.3e-7 v_ref apart at rtol 1e-8
            // with a creep budget of 20 or 30 rtol v_ref, 2e-8 with 10, and both 1e-7 to 2.5e-7 from
            // the rtol-1e-11 cycle whatever the budget), not the solver's tolerance. From 3e-2 of the
            // scales off (a field's typical prediction) so that the acceptance rule is what is tested:
            // measured 2.5e-10 for fig6, 3.0e-9 for heave_yaw: bound 1e-8; the same with the solver's tol
            // at 1e-4 is 2.8e-7 off (fails).
            LimitCycleOptions fine_plain = plain, fine_shooting;
            fine_plain.integration.rtol = fine_shooting.integration.rtol = 1e-10;
            const LimitCycleSummary ref_fine = limit_cycle(sc, c.q, fine_plain);
            const LimitCycleSummary sh_fine =
                limit_cycle(sc, c.q, fine_shooting, ref_fine.qd_start + Vec3(3e-2, -3e-2, 3e-2).cwiseProduct(S));
            REQUIRE(ref_fine.converged);
            REQUIRE(sh_fine.converged);
            CHECK(sh_fine.has_monodromy);
            CHECK((sh_fine.twist - ref_fine.twist).cwiseQuotient(S).cwiseAbs().maxCoeff() < 1e-8);
            // And the default settings' twist (sh) near the rtol-1e-11 cycle (the study's accuracy is 1e-6
            // v_ref; measured 1.7e-7 at most, for fig6 with the creep's budget at 100 rtol v_ref: bound 5e-7).
            LimitCycleOptions exact = plain;
            exact.integration.rtol = 1e-11;
            const LimitCycleSummary ref_exact = limit_cycle(sc, c.q, exact);
            REQUIRE(ref_exact.converged);
            CHECK((sh.twist - ref_exact.twist).cwiseQuotient(S).cwiseAbs().maxCoeff() < 5e-7);
        }
        // Central differences of the period map at the cycle, independently of the solver (h = 1e-4
        // of the scales: truncation h^2 |P'''| and noise rtol/h ~ 1e-4 of |M|).
        Mat3 Mc;
        REQUIRE(central_monodromy(sc, c.q, ref.qd_start, 1e-4, IntegrationOptions{}, Mc));
        INFO("shooting M\n" << sh.monodromy << "\ncentral differences\n" << Mc);
        if (c.full_stick) {
            CHECK(Mc.norm() < 1.5e-6);       // the period's end forgets its start (measured 4.6e-7)...
            CHECK(sh.monodromy.isZero(0));   // ...and the solver says so
        } else {
            // The bound follows from the period map's own errors (against rtol 1e-11) at the points the
            // two difference quotients use: e_w at the solver's forward differences from the warm start
            // w (columns (P(w + h S_j) - P(w)) / h, at the solver's rtol 1e-8) and e_c at the central
            // ones about the cycle c (Mc, at IntegrationOptions{}'s rtol 1e-9). Each entry of the
            // difference is then off by at most (2 e_w + e_c) / h, its Frobenius norm by 3 times that.
            // Plus the map's curvature over h/2 + |w - c| -- an estimate, not a bound (|P''| from
            // forward against central differences at 10 h: diagonal terms only, and P is smooth only
            // piecewise). A fixed 2e-3 of |M| once passed at 4.7e-4 and failed at 4.7e-3 after a change
            // of u(t)'s rounding: noise, not the model. (Premise: the solver's M is the one at w -- from
            // a start this close it takes its three differences on the first period, from w.)
            IntegrationOptions fine;
            fine.rtol = 1e-11;
            const IntegrationOptions solver = LimitCycleOptions{}.integration;
            auto error_at = [&](const Vec3& x, const IntegrationOptions& io) {
                Vec3 a, b;
                REQUIRE(period_map(sc, c.q, x, a, io));
                REQUIRE(period_map(sc, c.q, x, b, fine));
                return (a - b).cwiseQuotient(S).cwiseAbs().maxCoeff();
            };
            double e_w = error_at(warm, solver), e_c = 0;
            for (int j = 0; j < 3; ++j) {
                Vec3 d = Vec3::Zero();
                d[j] = 1e-4 * S[j];
                e_w = std::max(e_w, error_at(warm + d, solver));
                e_c = std::max(
                    {e_c, error_at(ref.qd_start + d, IntegrationOptions{}), error_at(ref.qd_start - d, IntegrationOptions{})});
            }
            Mat3 Mc10, Mf10;
            REQUIRE(central_monodromy(sc, c.q, ref.qd_start, 1e-3, fine, Mc10));
            Vec3 P0;
            REQUIRE(period_map(sc, c.q, ref.qd_start, P0, fine));
            for (int j = 0; j < 3; ++j) {
                Vec3 xp = ref.qd_start, Pp;
                xp[j] += 1e-3 * S[j];
                REQUIRE(period_map(sc, c.q, xp, Pp, fine));
                Mf10.col(j) = (Pp - P0).cwiseQuotient(S) / 1e-3;
            }
            const double curvature = 2 * (Mf10 - Mc10).norm() / 1e-3;   // |P''|, scaled (estimated)
            const double bound = 3 * (2 * e_w + e_c) / 1e-4 + curvature * (0.5e-4 + 1e-4 * std::sqrt(3.0));
            INFO("period map errors e_w " << e_w << ", e_c " << e_c << ", |P''| " << curvature << ", bound " << bound);
            CHECK((sh.monodromy - Mc).norm() <= bound);
            // The solver's rtol-1e-8 periods are the noise (e_w 2.0e-7 measured, e_c 1.7e-8): the bound is
            // 4.5 % of |M| (the difference 0.47 %). It still tells the derivative from what else a
            // solver could report (a full stick's M = 0 is 100 % off; a monodromy 5 % off fails it).
            CHECK(bound < 0.06 * Mc.norm());
            CHECK(Mc.eigenvalues().cwiseAbs().maxCoeff() < 1);
            CHECK(Mc.norm() > 0.1);   // not a full stick: the start matters
        }
    }
    // From a start two scales off a sliding fig6 cycle (far steps, a fresh Newton step, then chord
    // steps), at rtol 1e-10 so that the integration is not what is measured: the twist must agree
    // with the period-by-period cycle at tol 1e-10 within the solver's tolerance, 1e-7 v_ref. An
    // estimate that left out Pa's own error accepted one 2.6e-7 off from this start.
    {
        const Scene sc = scene("fig6");
        const Vec3 q(-0.025, 0.025, 1.5 * kPi);
        const Vec3 S(sc.v_ref(), sc.v_ref(), sc.v_ref() / sc.part.rho());
        LimitCycleOptions plain;
        plain.solver = CycleSolver::PeriodByPeriod;
        plain.tol = 1e-10;
        plain.integration.rtol = 1e-10;
        const LimitCycleSummary ref = limit_cycle(sc, q, plain);
        REQUIRE(ref.converged);
        LimitCycleOptions o;
        o.integration.rtol = 1e-10;
        const LimitCycleSummary sh = limit_cycle(sc, q, o, ref.qd_start + Vec3(-2, 2, 2).cwiseProduct(S));
        REQUIRE(sh.converged);
        CHECK((sh.twist - ref.twist).cwiseQuotient(S).cwiseAbs().maxCoeff() < 2.5e-9);   // measured 7.3e-10
    }
}

TEST_CASE("a pivot leaves the twist one degree of freedom: a pivoting cycle's period map has rank one", "[limit_cycle][stick]") {
    // Held about contact k, the twist satisfies two constraints (contact k's slip is zero), so it has
    // one free component, theta'; whatever the period's start, its state on leaving the pivot is one
    // number, and the period map's derivative is u v^T: one nonzero singular value (as long as nearby
    // starts keep the mode sequence, and up to the engine's snap onto a hold at 3e2 rtol v_ref). A
    // sliding cycle has no such bottleneck (rank >= 2: the control below, on which the check fails).
    // What this checks is that a pivot has exactly one degree of freedom and that the mode sequence
    // is the same within +-h; that each hold is the right one is the regularised-reference tests' job
    // (a hold that slips by up to a few percent of v_ref would pass here too: the near-stick
    // relaxation contracts the other directions as well). Central differences at the cycle, rtol
    // 1e-11, h = 1e-2 of the scales: truncation h^2 |P'''| and the hold snap's noise ~1e-8 / h
    // (at h = 1e-3 the fourth case below is at 1.4e-5, growing as 1/h); bound 1e-4 on sigma_2 /
    // sigma_1 (measured <= 7.6e-7 on these four; the sliding ones >= 0.157).
    const Scene sc = scene("fig6");
    const auto grid = [](int i, int j, int k) { return Vec3(-0.05 + i / 60.0, -0.05 + j / 60.0, 2 * kPi * k / 7); };
    struct Case {
        Vec3 q;
        bool pivots;
    };
    const Case cases[] = {{grid(1, 3, 2), true},                    // pivots about contact 2 three times a period
                          {grid(4, 2, 1), true},                    // about contact 1, three times
                          {grid(5, 4, 2), true},                    // about contact 1, twice
                          {grid(0, 0, 6), true},                    // about contact 1, once (the noisiest)
                          {Vec3(1.0 / 60, 1.0 / 60, 1.0), false},   // slides all period long
                          {Vec3(-0.025, 0.025, 1.5 * kPi), false}};
    IntegrationOptions io;
    io.rtol = 1e-11;
    int shooting_periods = 0;
    for (const Case& c : cases) {
        INFO("q = " << c.q.transpose());
        LimitCycleOptions plain;
        plain.solver = CycleSolver::PeriodByPeriod;
        plain.tol = 1e-11;
        plain.integration = io;
        const LimitCycleSummary ref = limit_cycle(sc, c.q, plain);
        REQUIRE(ref.converged);
        REQUIRE(enters(ref, ModeKind::Pivot) == c.pivots);
        REQUIRE(!enters(ref, ModeKind::Stuck));
        Mat3 M;
        REQUIRE(central_monodromy(sc, c.q, ref.qd_start, 1e-2, io, M));
        const Vec3 sigma = Eigen::JacobiSVD<Mat3>(M).singularValues();
        INFO("singular values " << sigma.transpose());
        CHECK(sigma[0] > 1e-2);   // the start matters (no full stick)
        if (c.pivots)             // (measured 7.6e-7 of sigma_1 at most)
            CHECK(sigma[1] <= 2.3e-6 * sigma[0]);
        else
            CHECK(sigma[1] > 1e-1 * sigma[0]);
        if (!c.pivots) continue;
        // The shooting solver uses it (limit_cycle.cpp): from a start 0.1 of the scales off, a plain
        // period puts x on the map's image curve, one difference along the residual gives lambda and
        // Pa u, and Newton runs along that line. At rtol 1e-10 and tol 1e-9 the twist is the
        // reference's within tol times |Pa| (<= 0.7 on fig6) plus the integration's error (the hold's
        // snap up to 3e2 rtol v_ref): 1e-8 (measured 0.5-2.3e-9, as with three differences); one
        // differenced period where three were taken: 6, 6, 6, 7 periods (three differences: 8, 7, 8, 8).
        const Vec3 S(sc.v_ref(), sc.v_ref(), sc.v_ref() / sc.part.rho());
        LimitCycleOptions o;
        o.integration.rtol = 1e-10;
        o.tol = 1e-9;
        const LimitCycleSummary s = limit_cycle(sc, c.q, o, ref.qd_start + Vec3(0.1, -0.1, 0.1).cwiseProduct(S));
        REQUIRE(s.converged);
        CHECK((s.twist - ref.twist).cwiseQuotient(S).cwiseAbs().maxCoeff() < 6e-9);   // measured 1.9e-9 at most
        shooting_periods += s.periods;
        // The monodromy it reports is that rank-one M, lambda u u^T, taken at a start up to 3e-2 off the
        // cycle: lambda within 3 % of the central differences' (measured 0.4-1.7 %).
        CHECK(s.monodromy.eigenvalues().cwiseAbs().maxCoeff() == Approx(M.eigenvalues().cwiseAbs().maxCoeff()).epsilon(0.03));
    }
    // 25-26 measured (a period moves with rounding); with three differences 31, with lambda halved 35:
    // the bound between them.
    CHECK(shooting_periods <= 28);
}

// A contact sliding at the rim of its friction disk with a slip that stays ~2e-9 m/s for 15 ms (neither
// lingering nor crossing zero) was integrated along v/|v| in steps of 3e-9 s: 2.1e7 right-hand sides
// for heave_yaw's cycle with z 2 m/s^2 and rz 60 rad/s^2 at (0, 0.02, 0). It creeps again now (its
// friction along the consistent direction): at the default settings the cycle must cost < 1e6 and
// still be the regularised reference's, within the default tolerance's reach (tol 1e-7 plus the
// integrator's ~60 rtol).
TEST_CASE("a slip that stays at the disk's rim creeps: cheap, and the regularised reference's twist", "[stick][reference]") {
    Scene sc = scene("heave_yaw");
    sc.plate.harmonics[0].amp = 2;    // z
    sc.plate.harmonics[1].amp = 60;   // rz
    const Vec3 q(0, 0.02, 0);
    const LimitCycleSummary lc = limit_cycle(sc, q);
    REQUIRE(lc.converged);
    CHECK(lc.stats.rhs_evals < 1'000'000);
    CHECK(*std::max_element(lc.stick_fraction.begin(), lc.stick_fraction.end()) > 0.3);   // (it sticks)
    // The part sticks as a whole twice a period, which forgets the period's start: the period map is
    // constant to the integration's error (a few rtol v_ref), so from rest the first period's end is
    // the cycle's start and the second period confirms it (measured: 3e-8 v_ref apart; 2 periods). With the
    // engine carried across the period boundary the returns were 4e-7-1.6e-6 v_ref apart (its step in
    // progress made the error depend on the history) and the cycle took 12 periods, accepted by chance.
    // (2 is the fewest a cycle from rest can report; 3 leaves room for a change of step control.)
    CHECK(enters(lc, ModeKind::Stuck));
    CHECK(lc.periods <= 3);
    // Plain periods likewise; and there the start's error is the return r itself, not r c / (1 - c):
    // with c = r / r_prev (the transient's) that would be r^2 / r_prev, 7e-15 for a 3e-8 return.
    LimitCycleOptions plain;
    plain.solver = CycleSolver::PeriodByPeriod;
    const LimitCycleSummary pl = limit_cycle(sc, q, plain);
    REQUIRE(pl.converged);
    CHECK(pl.periods <= 3);
    CHECK(pl.error_estimate >= pl.residual);
    const RegularisedReference r = regularised_reference(sc, q);
    REQUIRE(r.ok);
    INFO("engine " << lc.twist.transpose() << ", reference " << r.twist.transpose() << " (order " << r.order << ", error "
                   << r.error << ")");
    // (The engine's claim: tol + 60 rtol v_ref plus the reference's error; measured 1.3e-7, the reference's
    // own estimate 1.1e-7.)
    CHECK(twist_distance(sc, lc.twist, r.twist) <= 4e-7);
    CHECK(r.error < 3.5e-7);
}

// The shipped scene itself (issue 14 asks for heave_yaw against the regularised reference; the tests
// above change its amplitudes), at rtol 1e-10 and tol 1e-9. The engine claims the cycle tolerance plus
// the zero band (3e2 rtol v_ref); measured 3.9e-9 and 3.0e-10 v_ref, bound 1.2e-8 (with the engine's
// friction 0.1 % too high, 8.7e-6 and 3.8e-6: it fails).
TEST_CASE("heave_yaw as shipped: its sticking cycles are the regularised limit's", "[stick][reference]") {
    const Scene sc = scene("heave_yaw");
    for (const Vec3& q : {Vec3(0, 0.02, 0), Vec3(0.03, 0.02, 1.0)}) {
        INFO("q = " << q.transpose());
        LimitCycleOptions o;
        o.integration.rtol = 1e-10;
        o.tol = 1e-9;
        const LimitCycleSummary lc = limit_cycle(sc, q, o);
        REQUIRE(lc.converged);
        const double held = *std::max_element(lc.stick_fraction.begin(), lc.stick_fraction.end());
        CHECK(held > 0.05);   // it sticks for part of the period
        CHECK(!lc.stuck_all_period());
        const RegularisedReference r = regularised_reference(sc, q);
        REQUIRE(r.ok);
        const double d = twist_distance(sc, lc.twist, r.twist);
        INFO("engine " << lc.twist.transpose() << ", reference " << r.twist.transpose() << " (error " << r.error << "), d " << d);
        CHECK(d <= 1.2e-8);
    }
}

// A cycle with a brief full stick (fig6 at (0.0167, 0, 2.693): stuck 0.8 % of the period) must be the
// regularised reference's too. The fixed-point sampling above leaves full sticks out; this one showed
// the engine 1.8e-4 v_ref off, held 0.13 ms too long by a friction gauge that came out low next to a
// kink of the support function (modes.cpp; test_dynamics.cpp checks the gauge by brute force).
TEST_CASE("a cycle with a full stick is the regularised reference's: fig6 at (0.0167, 0, 2.693)", "[stick][reference]") {
    const Scene sc = scene("fig6");
    const Vec3 q(0.05 / 3, 0, 2 * kPi * 3 / 7);
    LimitCycleOptions o;
    o.integration.rtol = 1e-10;
    o.tol = 1e-9;
    const LimitCycleSummary lc = limit_cycle(sc, q, o);
    REQUIRE(lc.converged);
    REQUIRE(enters(lc, ModeKind::Stuck));
    const RegularisedReference r = regularised_reference(sc, q);
    REQUIRE(r.ok);
    INFO("engine " << lc.twist.transpose() << ", reference " << r.twist.transpose() << " (order " << r.order << ", error "
                   << r.error << ")");
    CHECK(twist_distance(sc, lc.twist, r.twist) <= 1.1e-8);   // measured 3.6e-9 (the reference's estimate 4e-7)
}

// The same rim-sliding contact at tight tolerances: at rtol 1e-9 its slip hovered at ~1.5e-8 v_ref (a
// few hint speeds, the integrator's noise level), its creep was stopped as "inconsistent" on that
// noise's direction after every step, and Dormand-Prince crawled along v/|v| in steps of 4e-10 s:
// 2.2e7 right-hand sides for the cycle, and at 1e-10 none within 6e7. A creeping slip's direction is
// judged only above kCreepJudged = 4 hint speeds (engine.hpp). Each tolerance must converge within the
// default budget and agree with the tightest within tol + 3e2 rtol of the coarser (v_ref): a lingering
// or creeping slip is taken as zero below zero_abs_ = 3e2 rtol v_ref, the engine's bound on that error.
// Measured 4.1e-9 (4 rtol) at 1e-9, 5.3e-11 at 1e-10; bounds 1.2e-8 and 1.6e-10.
TEST_CASE("tight tolerances through a rim-sliding stick: converged, cheap, and consistent", "[stick][reference]") {
    const Scene sc = scene("heave_yaw");
    const Vec3 q(0, 0.02, 0);
    std::vector<Vec3> twists;
    for (double rtol : {1e-9, 1e-10, 1e-11}) {
        LimitCycleOptions o;
        o.integration.rtol = rtol;
        o.tol = 1e-9;
        const LimitCycleSummary lc = limit_cycle(sc, q, o);
        INFO("rtol " << rtol << ": " << lc.stats.rhs_evals << " right-hand sides");
        REQUIRE(lc.converged);
        CHECK(lc.stats.rhs_evals < 1'000'000);   // measured 2.5e5, 1.7e5, 4.1e5
        twists.push_back(lc.twist);
    }
    CHECK(twist_distance(sc, twists[0], twists[2]) <= 1.2e-8);
    CHECK(twist_distance(sc, twists[1], twists[2]) <= 1.6e-10);
}

TEST_CASE("no chattering at the noise floor: a cycle's mode sequence is the same at every tight tolerance",
          "[stick][reference]") {
    // heave_yaw at (0, 0.02, 0): held about contact 2, sliding, held about 2 again, stuck; then the same
    // about contact 3 -- eight changes of held contacts a period. Right after a reversal (a slip
    // reaching zero that static friction cannot hold) the slips sit at the integrator's noise, and each
    // crossing of zero used to be taken as a new reversal: 91, 1 519 and 117 mode changes at rtol 1e-8,
    // 1e-9, 1e-10 for the same cycle (engine.hpp: fresh_). The holds and their times cannot depend on
    // the tolerance, nor can the stick fractions (within 1e-3 of the period).
    // Reversals (slide -> slide) come right after a pivot breaks away: 1e-6 T after contact 2's at
    // every tolerance, and 1e-6-1e-5 T after contact 3's at rtol 1e-8 and 1e-10 but not at 1e-9. There
    // contact 3 slides on at the noise floor (its slip scales with rtol: 2e-10 m/s at 1e-9, 2e-11 =
    // 1.5e-9 v_ref at 1e-10: it stays at the rim of its disk), the other two at 1e-8 and 2e-9 m/s, all
    // inside rtol 1e-8's zero band (3e2 rtol v_ref), so whether it touches zero is noise. So: the first
    // reversal matched (time within 1e-3 T at every tolerance), every reversal within 1e-5 T after a
    // break-away, and one or two a cycle (chattering gave hundreds; with the reversal band off 100).
    const Scene sc = scene("heave_yaw");
    std::vector<LimitCycleSummary> c;
    std::vector<std::vector<ModeEvent>> holds;   // the events that are not reversals
    std::vector<double> first_reversal;
    for (double rtol : {1e-8, 1e-9, 1e-10}) {
        LimitCycleOptions o;
        o.tol = 1e-9;
        o.integration.rtol = rtol;
        c.push_back(limit_cycle(sc, Vec3(0, 0.02, 0), o));
        REQUIRE(c.back().converged);
        holds.emplace_back();
        int reversals = 0;
        double broke = -HUGE_VAL;   // the last break-away of a pivot
        for (const ModeEvent& e : c.back().mode_events) {
            if (e.from.kind == ModeKind::Slide && e.to.kind == ModeKind::Slide) {
                INFO("rtol " << rtol << ": a reversal at " << e.t / sc.plate.T << " T, the last break-away at "
                             << broke / sc.plate.T);
                CHECK(e.t - broke <= 1e-5 * sc.plate.T);
                if (reversals++ == 0) first_reversal.push_back(e.t);
            } else {
                holds.back().push_back(e);
                if (e.from.kind == ModeKind::Pivot && e.to.kind == ModeKind::Slide) broke = e.t;
            }
        }
        INFO("rtol " << rtol);
        CHECK(reversals >= 1);
        CHECK(reversals <= 2);
    }
    REQUIRE(first_reversal.size() == 3u);
    // (Measured: reversals within 4.5e-7 T of each other, holds within 1.4e-4 T, stick fractions within
    // 1.4e-4 across the tolerances; bounds three times those.)
    for (double t : first_reversal) CHECK(std::abs(t - first_reversal[0]) < 1.5e-6 * sc.plate.T);
    for (std::size_t k = 1; k < c.size(); ++k) {
        INFO("rtol 1e-" << 8 + k << " against 1e-8");
        REQUIRE(holds[k].size() == holds[0].size());
        for (std::size_t e = 0; e < holds[0].size(); ++e) {
            CHECK(holds[k][e].to == holds[0][e].to);
            CHECK(std::abs(holds[k][e].t - holds[0][e].t) < 4.5e-4 * sc.plate.T);
        }
        for (int i = 0; i < 3; ++i) CHECK(std::abs(c[k].stick_fraction[i] - c[0].stick_fraction[i]) < 4.5e-4);
    }
    // And the sequence is the physical one, not merely the same at each tolerance (with stick detection
    // off there would be no events at all, and the comparisons above would hold) (measured at all three).
    const std::vector<Mode> expected = {{ModeKind::Pivot, 1}, {ModeKind::Slide, -1}, {ModeKind::Pivot, 1}, {ModeKind::Stuck, -1},
                                        {ModeKind::Pivot, 2}, {ModeKind::Slide, -1}, {ModeKind::Pivot, 2}, {ModeKind::Stuck, -1}};
    REQUIRE(holds[0].size() == expected.size());
    for (std::size_t e = 0; e < expected.size(); ++e) CHECK(holds[0][e].to == expected[e]);
    // Each contact has zero slip about three quarters of the period (measured 0.74699, 0.78170, 0.78377
    // at rtol 1e-8; within the tolerances' spread, 4.5e-4, above).
    for (int i = 0; i < 3; ++i)
        CHECK(c[0].stick_fraction[i] == Approx(std::array<double, 3>{0.74699, 0.78170, 0.78377}[i]).margin(4.5e-4));
}

TEST_CASE("stick-slip on scenes nobody tuned: 36 seeded random sticking scenes agree with the regularised limit",
          "[stick][reference][random]") {
    // Thick, thin and point parts (seed % 3), six-axis motions with the x, y amplitudes rescaled to
    // 0.05..1.2 mu g and the heave by 0.5..2.5 (sticking_random_scene, study.hpp), one random
    // configuration each within 3 cm. Two engines against the regularised limit, each bounded by its own
    // accuracy plus the reference's error estimate (what the reference is worth: the difference of two
    // estimates is at most the sum of their errors):
    //   the default (rtol 1e-8, cycles to 1e-7 v_ref): a slip that passes within the zero band of zero
    //     (3e2 rtol v_ref, engine.hpp) is taken as reaching it, an error below the band's width, plus
    //     the cycle tolerance -- the accuracy the engine claims (measured over 800 seeds: README);
    //   a tight one (rtol 1e-10, cycles to 1e-9): the same terms, 3e-8 + 1e-9 v_ref, so that a model
    //     error of a few 1e-7 v_ref (a gauge that holds the part 0.3 % too long: 2.5e-6) cannot hide in
    //     the default's band.
    // Bounded at three times what they measured on these 36 seeds, well inside those claims: the
    // default 2.75e-7 v_ref at most (bound 8e-7), the tight one 8.6e-9 (bound 2.6e-8) -- each plus the
    // reference's own error estimate (RegularisedReference::error, the eps extrapolation's): 1e-12-3.6e-7
    // on 35 seeds, but 2.8e-6 on seed 13 on an AMD EPYC machine, where both engines (which agree with
    // each other to 7e-9) differ from it by 1.8e-6.
    // The cases must cover what the test is about: cycles that hold a contact for part of the period
    // (a cycle stuck all period has twist exactly 0 on both sides and proves nothing), pivots that break
    // away at the disk's rim, point parts that stick and slip; the median over the partial ones within
    // three times its measured 8.3e-9 (the cycle tolerance is 1e-7).
    LimitCycleOptions tight;
    tight.integration.rtol = 1e-10;
    tight.tol = 1e-9;
    int partial = 0, pivot_breaks = 0, point_partial = 0;
    std::vector<double> errors;
    for (std::uint64_t seed = 1; seed <= 36; ++seed) {
        const RandomStickCase c = random_stick_case(seed);
        INFO("seed " << seed << " (" << c.scene.name << ", ratio " << c.ratio << "): " << c.failure << " reference error "
                     << c.reference_error);
        REQUIRE(c.converged());
        REQUIRE(c.reference_ok);
        CHECK(c.error <= 8e-7 + c.reference_error);
        const LimitCycleSummary t = limit_cycle(c.scene, c.q0, tight);
        REQUIRE(t.converged);
        CHECK(twist_distance(c.scene, t.twist, c.reference_twist) <= 2.6e-8 + c.reference_error);
        if (c.held == 0 || c.cycle.stuck_all_period()) continue;
        ++partial;
        point_partial += c.scene.part.point;
        pivot_breaks += std::any_of(c.cycle.mode_events.begin(), c.cycle.mode_events.end(), [](const ModeEvent& e) {
            return e.from.kind == ModeKind::Pivot && e.to.kind == ModeKind::Slide;
        });
        errors.push_back(c.error);
    }
    CHECK(partial >= 18);
    CHECK(pivot_breaks >= 6);
    CHECK(point_partial >= 5);
    std::sort(errors.begin(), errors.end());
    REQUIRE(!errors.empty());
    CHECK(errors[errors.size() / 2] <= 2.5e-8);
}

TEST_CASE("slips at the rim of the disk and grazing contacts: random scenes that broke a faster step control or spent the budget",
          "[stick][random]") {
    // Among 3 000 sticking_random_scene seeds (docs/decisions.md, "Predictive step control with a lower
    // hold threshold: landed, then reverted"): seed 2512 (a thin part
    // with a contact sliding at its disk's rim, its slip chattering between 3e-8 and 1.5e-6 v_ref at
    // rtol 1e-8) spent the whole 2e7 budget without a cycle at the default options; seed 495 (its cycle
    // grazes, smallest normal force about 1e-3 m g) was reported losing contact in the transient from
    // rest at rtol 1e-9 and 1e-10. The engine as it stands finds both cycles, and the tight cycle (rtol
    // 1e-11) is the reference for their twists: within the zero band plus both cycle tolerances.
    // Seed 2512 at rtol 1e-9 and seed 3121 at the default rtol 1e-8: after the stuck
    // part breaks away next to a pivot one contact slides at its disk's rim while the two others grow
    // from zero, and their repeated creeps, each completing a creep of the whole twist (which reversed
    // the slips at once), spent the whole 2e7 budget until a growing slip no longer restarts such a
    // creep (engine_creep.hxx, creep_step); without that rule this case fails on both. (2512 still spends
    // it at rtol 5e-9, 5e-10, 2e-10 and 1e-10: docs/guide.md, Reliability.)
    LimitCycleOptions tight;
    tight.integration.rtol = 1e-11;
    tight.tol = 1e-10;
    struct Case {
        std::uint64_t seed;
        std::vector<double> rtols;
    };
    for (const Case& c : {Case{2512, {1e-8, 1e-9}}, Case{3121, {1e-8}}, Case{495, {1e-9, 1e-10}}}) {
        Vec3 q0;
        const Scene sc = sticking_random_scene(c.seed, q0);
        const LimitCycleSummary ref = limit_cycle(sc, q0, tight);
        for (const double rtol : c.rtols) {
            LimitCycleOptions o;
            o.integration.rtol = rtol;
            o.tol = 10 * rtol;
            const LimitCycleSummary lc = limit_cycle(sc, q0, o);
            INFO("seed " << c.seed << " at rtol " << rtol << ": " << lc.report());
            CHECK(ref.converged);
            CHECK(lc.stop.reason != StopReason::ContactLost);
            CHECK(lc.converged);
            // (The engine's bound: the zero band plus both tolerances; measured 5 % of it at most, bound 15 %.)
            if (ref.converged && lc.converged)
                CHECK(twist_distance(sc, lc.twist, ref.twist) <= 0.15 * (3e2 * rtol + o.tol + tight.tol));
        }
    }
}

TEST_CASE("a pivot that comes to rest for a moment inside one step is not missed (random scene 562)",
          "[stick][reference][random]") {
    // sticking_random_scene(562): a thin part pivoting about its third contact decelerates to rest at
    // 0.9034 T, stays stuck for 3 ms and turns on the same way. The engine's step across it (0.011 T)
    // ended with the turn positive at both ends, so the rest was missed from most starts: the period
    // map jumped between two ends 5.3e-5 v_ref apart for starts 1e-6 v_ref apart, and the cycle was
    // 1.9e-5 v_ref off the regularised limit. A period with a full stick forgets its start, so its map
    // is flat: starts either side of the cycle's end at one point (to the integration's error), and the
    // twist is the regularised limit's within the cycle tolerance and the reference's error.
    const RandomStickCase c = random_stick_case(562);
    REQUIRE(c.converged());
    REQUIRE(c.reference_ok);
    CHECK(c.error <= 8e-9);   // measured 2.6e-9 (the reference's estimate 2.7e-8)
    CHECK(std::any_of(c.cycle.mode_events.begin(), c.cycle.mode_events.end(),
                      [](const ModeEvent& e) { return e.from.kind == ModeKind::Pivot && e.to.kind == ModeKind::Stuck; }));
    const double v = c.scene.v_ref();
    const Vec3 S(v, v, v / c.scene.part.rho());
    Vec3 first = Vec3::Zero();
    double spread = 0;
    for (int i = -6; i <= 6; ++i) {
        Vec3 end;
        REQUIRE(period_map(c.scene, c.q0, c.cycle.qd_start + Vec3(i * 1e-6 * v, 0, 0), end));
        if (i == -6) first = end;
        spread = std::max(spread, (end - first).cwiseQuotient(S).cwiseAbs().maxCoeff());
    }
    CHECK(spread <= 2.2e-10);   // measured 7.1e-11
}

TEST_CASE("a cycle stuck as a whole once a period is accepted when its return is within the engine's accuracy (random scene 256)",
          "[stick][random]") {
    // sticking_random_scene(256): a rigid part stuck from 0.526 T to 0.990 T of each period, then
    // sliding to its end. While stuck it moves with the plate, so the period's end does not depend on
    // its start: from rest the first period's end is the cycle's start, to the integration's error.
    // The engine's end does depend on its start at that level (its step carries through the stick from
    // the slide before it): from rest, periods on fresh engines alternated between two ends 6e-7 v_ref
    // apart forever, above tol 1e-7 and within the zero band (3e2 rtol v_ref, the engine's error
    // bound) -- 400 periods without a cycle. Such a return is accepted now (limit_cycle.cpp,
    // one_start), and the twist is the tight cycle's within that bound plus both tolerances (measured
    // 9.4e-9 v_ref, bound 2.8e-8: the average over the period varies far less than its end).
    Vec3 q0;
    const Scene sc = sticking_random_scene(256, q0);
    const LimitCycleSummary lc = limit_cycle(sc, q0);
    REQUIRE(lc.converged);
    CHECK(lc.periods <= 3);
    CHECK(enters(lc, ModeKind::Stuck));
    CHECK(lc.error_estimate >= lc.residual);
    LimitCycleOptions tight;
    tight.integration.rtol = 1e-11;
    tight.tol = 1e-10;
    const LimitCycleSummary ref = limit_cycle(sc, q0, tight);
    REQUIRE(ref.converged);
    CHECK(twist_distance(sc, lc.twist, ref.twist) <= 2.8e-8);
}

TEST_CASE("full dynamics through stick-slip on random scenes: the regularised trajectories converge to the engine's",
          "[stick][reference][random][full]") {
    // Five sticking_random_scene seeds (two thick, two thin, one point part) whose full-dynamics run from
    // rest holds a contact again after its break-away (1 to 11 times in the 0.5 s). Both methods from the break-away for 0.5 s
    // (trajectory_run, study.hpp: the engine at rtol 1e-10; GSL's bsimp with f = -mu N v / sqrt(|v|^2 + eps^2) at eps = 1e-4,
    // 1e-5, 1e-6 v_ref, tol 1e-10), the configuration's difference at 0.5 s (relative to rho, rho, 1 rad). Where the engine is
    // the eps -> 0 limit the difference shrinks like eps^p, p about 0.8 near sticking (docs/stick-slip.md): at least 10^0.5 per
    // decade here. A model error in the engine (mu 1 % off) makes it level off at that error instead.
    int held = 0;
    for (std::uint64_t seed : {22, 92, 102, 138, 148}) {
        Vec3 q0;
        const Scene sc = sticking_random_scene(seed, q0);
        INFO("seed " << seed << " (" << sc.name << ")");
        const Trajectory tr = simulate(sc, Dynamics::Full, q0, Vec3::Zero(), 0.5, 0.5);
        REQUIRE(tr.stop.reason == StopReason::None);
        held += std::any_of(tr.events.begin(), tr.events.end(),
                            [&](const ModeEvent& e) { return e.t > tr.events.front().t && e.to.kind != ModeKind::Slide; });
        Solver engine;
        engine.engine = true;
        const RunResult e = trajectory_run(sc, q0, 0.5, 0.5, engine, 1e-10);
        REQUIRE(e.ok);
        std::vector<double> d;
        for (double eps : {1e-4, 1e-5, 1e-6}) {
            Solver s;
            s.method = Method::GslBsimp;
            s.law = FrictionLaw::Sqrt;
            s.law_eps = eps;
            const RunResult r = trajectory_run(sc, q0, 0.5, 0.5, s, 1e-10);
            REQUIRE(r.ok);
            const std::size_t n = e.value.size();
            double dist = 0;
            for (int i = 0; i < 3; ++i)
                dist = std::max(dist, std::abs(e.value[n - 3 + i] - r.value[n - 3 + i]) / (i < 2 ? sc.part.rho() : 1.0));
            d.push_back(dist);
        }
        INFO("differences at eps 1e-4, 1e-5, 1e-6 v_ref: " << d[0] << ", " << d[1] << ", " << d[2]);
        CHECK(d[0] >= std::sqrt(10.0) * d[1]);
        CHECK(d[1] >= std::sqrt(10.0) * d[2]);
    }
    CHECK(held == 5);
}

TEST_CASE("a pivot's break-away inside one step is not missed (random scene 132 at rtol 1e-5)", "[stick][random]") {
    // sticking_random_scene(132): the pivot's static-friction margin goes 7.7e-4 -> -3.6e-3 -> 1.9e-3
    // within one step of 0.075 T at loose tolerances (an outside review's probe of the dense output);
    // both ends positive, the break-away was missed and the cycle held its contact 0.82 of the period
    // instead of 0.72, with 4 mode changes instead of 6, 1.75e-4 v_ref off. The step's stages see the
    // negative margin (engine.hpp, note_stage). Bound: the loose-tolerance cycles' 10 rtol v_ref (docs/stick-slip.md).
    Vec3 q0;
    const Scene sc = sticking_random_scene(132, q0);
    LimitCycleOptions tight, loose;
    tight.integration.rtol = 1e-10;
    tight.tol = 1e-9;
    loose.integration.rtol = 1e-5;
    loose.tol = 1e-4;
    const LimitCycleSummary t = limit_cycle(sc, q0, tight), l = limit_cycle(sc, q0, loose);
    REQUIRE(t.converged);
    REQUIRE(l.converged);
    CHECK(l.mode_events.size() == t.mode_events.size());
    CHECK(std::abs(l.stick_fraction[1] - t.stick_fraction[1]) < 0.02);
    CHECK(twist_distance(sc, l.twist, t.twist) <= 10 * 1e-5);
}

TEST_CASE("a slip reversing along a line is not overrun: fig1_point's period map and field at rtol 1e-8", "[stick][reference]") {
    // fig1_point at (0, -0.05): the plate drives the point part along x, so its slip passes through
    // zero along a line twice a period (a reversal: static friction cannot hold it). Steps that
    // overran the zero put reversed friction into their later stages; the error estimate jumped by
    // 10^3-10^5 and the step was cut down to the zero, where one was accepted at an error near 1 while
    // straddling the reversed friction. One period from the cycle's start at rtol 1e-8 was then 3e-7 to
    // 5e-7 v_ref from the rtol-1e-11 period, depending on the first step; with the steps ending just
    // past a slip's predicted zero (engine.hpp, zero_cap) at most 1.9e-9 (0.2 rtol); bound 6e-9 (a period of
    // local errors below rtol leaves up to 10 rtol where the flow contracts).
    const Scene sc = scene("fig1_point");
    const Vec3 q(0, -0.05, 0);
    LimitCycleOptions ro;
    ro.integration.rtol = 1e-11;
    ro.tol = 1e-11;
    ro.solver = CycleSolver::Anderson;
    const LimitCycleSummary ref = limit_cycle(sc, q, ro);
    REQUIRE(ref.converged);
    IntegrationOptions fine;
    fine.rtol = 1e-11;
    for (double h0 : {0.0, 1e-4, 1e-3, 3e-3})
        for (double off : {0.0, 1e-6, -1e-6, 1e-5}) {
            const Vec3 x = ref.qd_start + Vec3(off * sc.v_ref(), 0, 0);
            IntegrationOptions io;
            io.rtol = 1e-8;
            io.h0 = h0;
            Vec3 p, pr;
            REQUIRE(period_map(sc, q, x, p, io));
            REQUIRE(period_map(sc, q, x, pr, fine));
            INFO("first step " << h0 << " T, start " << off << " v_ref off the cycle");
            CHECK(twist_distance(sc, p, pr) <= 6e-9);
        }
    // The field at its defaults against the same field at rtol 1e-11 (its shooting's twists): the cycle
    // tolerance is 1e-7 v_ref; 1.07e-6 before, 8.4e-9 now (bound 2.5e-8).
    FieldOptions fo, fr;
    fr.cycle.integration.rtol = 1e-11;
    fr.cycle.integration.large_slip_factor = 1;
    fr.cycle.tol = 1e-10;
    const Field f = compute_field(sc, GridSpec{}, fo), r = compute_field(sc, GridSpec{}, fr);
    double worst = 0;
    for (std::size_t i = 0; i < f.points.size(); ++i) {
        REQUIRE(f.points[i].converged);
        worst = std::max(worst, twist_distance(sc, f.points[i].twist, r.points[i].twist));
    }
    CHECK(worst <= 2.5e-8);
}
