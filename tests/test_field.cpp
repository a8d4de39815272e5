// Asymptotic twist fields and their fixed points against the paper's claims (Section IV-D, V).
#include "plate/field.hpp"
#include "plate/study.hpp"
#include "plate/scene_io.hpp"
#include "shipped_scenes.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

using namespace plate;

namespace {

using plate_tests::scene;

bool line_at(const FixedLine& l, double theta, double tol_x, double tol_th) {
    for (const auto& q : l.points)
        if (std::abs(q[0]) > tol_x || std::abs(wrap_angle(q[2] - theta)) > tol_th) return false;
    return true;
}

double y_span(const FixedLine& l) {
    double lo = 1e9, hi = -1e9;
    for (const auto& q : l.points) {
        lo = std::min(lo, q[1]);
        hi = std::max(hi, q[1]);
    }
    return hi - lo;
}

bool sticks(const FieldPoint& p) { return std::max({p.stick_fraction[0], p.stick_fraction[1], p.stick_fraction[2]}) > 0; }

// The outside reference for a field's twist at q, nothing of the engine's cycle solvers, events or
// modes: GSL's rk8pd with exact Coulomb and its own period-by-period loop from rest (twist_run) at
// 1e-12, or, where the part may stick (exact Coulomb then stalls rk8pd at zero slip), the
// regularised-friction limit (regularised_reference, eps -> 0) with its own error estimate.
struct Reference {
    bool ok = false;
    Vec3 twist = Vec3::Zero();
    double error = 0;   // the reference's own, relative to (v_ref, v_ref, v_ref / rho)
};

Reference reference_twist(const Scene& sc, const Vec3& q, bool regularised) {
    Reference out;
    if (regularised) {
        const RegularisedReference r = regularised_reference(sc, q);
        out.ok = r.ok;
        out.twist = r.twist;
        out.error = r.error;
        return out;
    }
    Solver independent;
    independent.method = Method::GslRk8pd;
    const RunResult r = twist_run(sc, q, independent, 1e-12, 1e-12);
    out.ok = r.ok;
    if (r.ok) out.twist = Vec3(r.value[0], r.value[1], r.value[2]);
    return out;
}

// The field against the reference at every stride-th point and (stick_stride > 0) every
// stick_stride-th of the points where a contact sticks: the largest distance, relative to (v_ref,
// v_ref, v_ref / rho), less the reference's own error estimate; `sampled_sticking` counts the sampled
// points that stick.
double worst_against_reference(const Scene& sc, const Field& f, int stride, int stick_stride, bool regularised,
                               int& sampled_sticking) {
    const Vec3 S(sc.v_ref(), sc.v_ref(), sc.v_ref() / sc.part.rho());
    double worst = 0;
    int seen_sticking = 0;
    sampled_sticking = 0;
    for (std::size_t i = 0; i < f.points.size(); ++i) {
        const FieldPoint& p = f.points[i];
        const bool sampled_stick = sticks(p) && stick_stride > 0 && seen_sticking++ % stick_stride == 0;
        if (i % static_cast<std::size_t>(stride) != 0 && !sampled_stick) continue;
        INFO("at " << p.q.transpose());
        REQUIRE(p.converged);
        const Reference r = reference_twist(sc, p.q, regularised);
        REQUIRE(r.ok);
        sampled_sticking += sticks(p);
        const double d = (p.twist - r.twist).cwiseQuotient(S).cwiseAbs().maxCoeff();
        worst = std::max(worst, d - r.error);
    }
    return worst;
}

}   // namespace

TEST_CASE("field: grid, parallel evaluation and warm starts give the single-configuration twist", "[field]") {
    const Scene sc = scene("fig4");
    GridSpec g;
    g.nx = g.ny = 2;
    g.nth = 3;
    FieldOptions o;
    o.threads = 3;   // not the default (all cores), and no more than the field's lines
    const Field f = compute_field(sc, g, o);
    REQUIRE(f.points.size() == 12u);
    const Vec3 S(sc.v_ref(), sc.v_ref(), sc.v_ref() / sc.part.rho());
    for (const auto& p : f.points) {
        REQUIRE(p.converged);
        INFO("at " << p.q.transpose());
        const LimitCycleSummary lc = limit_cycle(sc, p.q);   // from rest, alone
        // Both within tol = 1e-7 v_ref of the cycle average (up to ~3x the estimate, measured on
        // fig6); integration errors ~1e-8 v_ref. All three components, scaled.
        CHECK((lc.twist - p.twist).cwiseQuotient(S).cwiseAbs().maxCoeff() < 3e-7);
        // Pinned independently: the same twist by another integrator and cycle loop at 1e-12
        // (reference_twist: nothing of the engine; measured agreement 5e-8).
        const Reference r = reference_twist(sc, p.q, false);
        REQUIRE(r.ok);
        CHECK((p.twist - r.twist).cwiseQuotient(S).cwiseAbs().maxCoeff() < 3e-7);
    }
    CHECK(f.threads == o.threads);
}

TEST_CASE("Fig. 1: lines of stable fixed points at (0, s_y, 0) and (0, s_y, pi), unstable at +-pi/2", "[field][paper]") {
    const Scene sc = scene("fig1");
    const Field f = compute_field(sc, GridSpec{});
    const FixedPoints fp = find_fixed_points(sc, f);
    CHECK(fp.points.empty());
    int stable0 = 0, stablepi = 0, unstable = 0;
    for (const auto& l : fp.lines) {
        INFO("line from " << l.points.front().transpose() << " to " << l.points.back().transpose());
        // The lines run across the whole grid in s_y (the field of u1 does not depend on s_y).
        CHECK(y_span(l) > 0.09);
        CHECK(std::abs(l.direction[1]) > 0.99 * l.direction.norm());
        if (l.stability == Stability::Stable && line_at(l, 0, 1e-5, 1e-3)) ++stable0;
        if (l.stability == Stability::Stable && line_at(l, kPi, 1e-5, 1e-3)) ++stablepi;
        if (l.stability != Stability::Stable && (line_at(l, kPi / 2, 1e-5, 1e-3) || line_at(l, -kPi / 2, 1e-5, 1e-3))) ++unstable;
    }
    CHECK(stable0 == 1);
    CHECK(stablepi == 1);
    CHECK(unstable == 2);
    CHECK(fp.lines.size() == 4u);
    CHECK(fp.suggested_grid == 0);   // the default grid resolves the field: no warning (4 points do not)
}

TEST_CASE("Fig. 1(b): the point part's velocity field has a stable line of fixed points on s_x = 0", "[field][paper][point]") {
    const Scene sc = scene("fig1_point");
    const Field f = compute_field(sc, GridSpec{});
    CHECK(f.point_part);
    CHECK(f.points.size() == 49u);
    // u1 moves the plate along x and tilts it about y: no force along y.
    for (const auto& p : f.points) CHECK(std::abs(p.twist[1]) < 1e-12);
    const FixedPoints fp = find_fixed_points(sc, f);
    REQUIRE(fp.lines.size() == 1u);
    CHECK(fp.lines[0].stability == Stability::Stable);
    CHECK(y_span(fp.lines[0]) > 0.09);
    for (const auto& q : fp.lines[0].points) CHECK(std::abs(q[0]) < 1e-5);
}

TEST_CASE("Fig. 4: stable fixed points near (0,0,0) and (0,0,pi), unstable near (0,0,+-pi/2)", "[field][paper]") {
    const Scene sc = scene("fig4");
    const Field f = compute_field(sc, GridSpec{});
    const FixedPoints fp = find_fixed_points(sc, f);
    CHECK(fp.lines.empty());
    REQUIRE(fp.points.size() == 4u);
    int stable = 0, unstable = 0;
    for (const auto& p : fp.points) {
        INFO(p.q.transpose() << " " << stability_name(p.stability));
        CHECK(p.q.head<2>().norm() < 1e-4);   // over the centre of the plate
        const double th = std::abs(p.q[2]);
        if (p.stability == Stability::Stable) {
            ++stable;
            CHECK(std::min(th, kPi - th) < 0.05);   // "near" 0 or pi: the paper's phases are tuned
        } else {
            ++unstable;
            CHECK(std::abs(th - kPi / 2) < 0.15);
        }
    }
    CHECK(stable == 2);
    CHECK(unstable == 2);
    CHECK(fp.undefined_cells == 0);
    CHECK(fp.cells == 6 * 6 * 7);                                 // 7x7 grid in (x, y), theta wrapping: 7 cells around
    CHECK(fixed_points_sentence(fp) == "4 fixed points found");   // (no grid warning)

    // A datum made undefined (a corner with no cycle) is counted, not silently skipped: the cells
    // sharing that corner are undefined and the sentence says where nothing was searched.
    Field holed = f;
    const int i = 3, j = 3, k = 0;   // (0, 0, 0): the stable point's corner
    holed.points[holed.grid.index(i, j, k)].converged = false;
    const FixedPoints fh = find_fixed_points(sc, holed);
    CHECK(fh.undefined_cells == 8);   // the corner belongs to 2 x 2 cells in (x, y), 2 in theta
    CHECK(fixed_points_sentence(fh).find("(8 of 252 cells undefined") != std::string::npos);
}

TEST_CASE("Fig. 5: transports along y while attracting theta to 0 or pi, no fixed points", "[field][paper]") {
    const Scene sc = scene("fig5");
    GridSpec g;
    g.x0 = -0.03;   // the plate tilts about y: keep |s_x| where the part stays in contact
    g.x1 = 0.03;
    g.nth = 12;
    const Field f = compute_field(sc, g);
    int n = 0;
    for (const auto& p : f.points) {
        REQUIRE(p.converged);
        CHECK(p.twist[1] > 0);   // transport along +y everywhere
        const double th = wrap_angle(p.q[2]);
        // Orientation attracted to 0 and pi, repelled from +-pi/2 (on the line s_x = 0).
        if (std::abs(p.q[0]) < 1e-12 && std::abs(std::sin(2 * th)) > 0.3) {
            CHECK(p.twist[2] * std::sin(2 * th) < 0);
            ++n;
        }
    }
    CHECK(n > 0);
    CHECK(find_fixed_points(sc, f).points.empty());
    // Against the outside reference (rk8pd, exact Coulomb: fig5 slides everywhere) at every 7th
    // configuration, 84 of them: measured 9.7e-8 v_ref at most (the cycle tolerance 1e-7 and the
    // integration's ~1e-8); bound 3e-7. (Cycles accepted after their first period: 0.1 m/s off.)
    int sticking = 0;
    CHECK(worst_against_reference(sc, f, 7, 0, false, sticking) < 3e-7);
    CHECK(sticking == 0);
}

TEST_CASE("Fig. 6: the field rotates the part everywhere with no holes and sticks only near the plate centre",
          "[field][paper][stick]") {
    const Scene sc = scene("fig6");
    const Field f = compute_field(sc, GridSpec{});
    int sticking = 0;
    for (const auto& p : f.points) {
        REQUIRE(p.converged);    // stick-slip: no configuration is undefined because of sticking
        CHECK(p.twist[2] < 0);   // one sense of rotation everywhere (Section V: "rotates the part")
        const double held = std::max({p.stick_fraction[0], p.stick_fraction[1], p.stick_fraction[2]});
        if (held == 0) continue;
        ++sticking;
        // Section IV-E: sticking happens where a contact is near the plate centre, where u6 (a
        // spin about z) gives little horizontal acceleration (150 rad/s^2 x r < mu g for
        // r < 1.1 cm). A second class: the centre of mass near the centre, where the part mostly
        // spins, its relative spin reverses when the spin acceleration is small, and friction
        // (up to mu m g r / J_zz = 93 rad/s^2, raised by half when p''_z peaks) can hold it.
        const Mat3 R2 = Eigen::AngleAxisd(p.q[2], Vec3::UnitZ()).toRotationMatrix();
        double r_min = 1e9;
        for (const auto& c : sc.part.c) r_min = std::min(r_min, (p.q.head<2>() + (R2 * c).head<2>()).norm());
        INFO("sticks at " << p.q.transpose() << ": nearest contact " << r_min << " m from the centre");
        CHECK(std::min(r_min, p.q.head<2>().norm()) < 0.03);
        // Nowhere stuck as a whole all period long: the spin always breaks the part away. (A single
        // contact can be held all period: at (0, -0.05, 0) contact 1 lies 2 mm from the centre and the
        // part swings about it, turning both ways -- the regularised-friction limit gives the same twist
        // to 1.2e-7 v_ref.)
        CHECK(std::min({p.stick_fraction[0], p.stick_fraction[1], p.stick_fraction[2]}) < 1);
    }
    CHECK(sticking > 0);   // the paper: Fig. 6 is the field with sticking configurations
    CHECK(find_fixed_points(sc, f).points.empty());
    // Against the outside reference, the regularised-friction limit, at every 17th configuration and
    // every 12th of the sticking ones (28 in all, 10 of them sticking): measured 1.2e-7 v_ref at most
    // beyond the reference's own error (up to 1.1e-7); bound 4e-7. (Cycles accepted after their first
    // period: 1e-2 m/s off.)
    int sampled_sticking = 0;
    CHECK(worst_against_reference(sc, f, 17, 12, true, sampled_sticking) < 4e-7);
    CHECK(sampled_sticking >= 8);

    // Every configuration against the same field at rtol 1e-10, cycle tolerance 1e-9 (itself within
    // 6e-8 of rtol 1e-11, tol 1e-10): the default's error is the cycle tolerance (1e-7) plus the
    // integration's noise (~60 rtol, measured at fig1's stable line): bound 1e-6 v_ref, the study's
    // target accuracy. (A shooting step accepted after a full stick with no contraction measured
    // once passed a residual of 0.03 here: 4.5e-5 off.)
    FieldOptions tight;
    tight.cycle.integration.rtol = 1e-10;
    tight.cycle.integration.large_slip_factor = 1;   // one tolerance everywhere
    tight.cycle.tol = 1e-9;
    const Field ref = compute_field(sc, GridSpec{}, tight);
    const Vec3 S(sc.v_ref(), sc.v_ref(), sc.v_ref() / sc.part.rho());
    for (std::size_t i = 0; i < f.points.size(); ++i) {
        INFO("at " << f.points[i].q.transpose());
        CHECK((f.points[i].twist - ref.points[i].twist).cwiseQuotient(S).cwiseAbs().maxCoeff() < 1e-6);
    }
    // The cycle solver's own error, with the integration's noise taken out (rtol 1e-10 for both):
    // the default cycle tolerance 1e-7 against 1e-9, bound 3e-7 (the tolerance, with the estimate's
    // factor of up to ~3 seen on fig6). An estimate without Pa's own error gave 1.1e-6 here.
    FieldOptions fine = tight;
    fine.cycle.tol = LimitCycleOptions{}.tol;
    const Field solver = compute_field(sc, GridSpec{}, fine);
    for (std::size_t i = 0; i < f.points.size(); ++i) {
        INFO("cycle tolerance only, at " << f.points[i].q.transpose());
        CHECK((solver.points[i].twist - ref.points[i].twist).cwiseQuotient(S).cwiseAbs().maxCoeff() < 3e-7);
    }
}

TEST_CASE("shooting: steps where every slip is large take 10 rtol, and the field keeps its accuracy", "[field][shooting]") {
    // IntegrationOptions::large_slip_factor (the cycles' default 10): a step that starts with every slip
    // above 3e-2 v_ref is held to 10 rtol. Each field against itself at rtol 1e-10, cycle tolerance
    // 1e-9, with one tolerance everywhere.
    auto reference = [](const Scene& sc) {
        FieldOptions tight;
        tight.cycle.integration.rtol = 1e-10;
        tight.cycle.integration.large_slip_factor = 1;
        tight.cycle.tol = 1e-9;
        return compute_field(sc, GridSpec{}, tight);
    };
    auto worst = [](const Scene& sc, const Field& f, const Field& ref) {
        const Vec3 S(sc.v_ref(), sc.v_ref(), sc.v_ref() / sc.part.rho());
        double e = 0;
        for (std::size_t i = 0; i < f.points.size(); ++i) {
            REQUIRE(f.points[i].converged);
            REQUIRE(ref.points[i].converged);
            e = std::max(e, (f.points[i].twist - ref.points[i].twist).cwiseQuotient(S).cwiseAbs().maxCoeff());
        }
        return e;
    };
    // fig4 never sticks, so nearly every step is a large-slip one. Bound: three cycle tolerances, the
    // solver's own error (the cycle-tolerance check above). Measured 1.4e-7 (1.9e-8 at factor 1); at
    // factor 30 4.7e-7, at 100 3.1e-6 -- the integration's error then outweighs the tolerance.
    const Scene fig4 = scene("fig4");
    const Field f4 = compute_field(fig4, GridSpec{}, FieldOptions{});
    CHECK(worst(fig4, f4, reference(fig4)) < 3e-7);
    FieldOptions one;
    one.cycle.integration.large_slip_factor = 1;
    const Field f4_one = compute_field(fig4, GridSpec{}, one);
    CHECK(f4.rhs_evals < 0.8 * f4_one.rhs_evals);   // measured 139 040 against 199 988
    // Where a slip is small the steps stay at rtol: fig6's field (78 sticking configurations) costs
    // less than with one tolerance (1.30e6 against 1.44e6 right-hand sides); loosened at every slip
    // it took 2.07e6 (its sticking cycles twice as much) and fig1's field was 1.1e-6 v_ref off.
    const Scene fig6 = scene("fig6");
    CHECK(compute_field(fig6, GridSpec{}, FieldOptions{}).rhs_evals < compute_field(fig6, GridSpec{}, one).rhs_evals);
    // The cap (1e-6): fig4's cycle at (0.02, -0.01, 0.5) shot at rtol 1e-6, cycle tolerance 1e-5, from a
    // start 0.05 v_ref off the cycle's: within twice the tolerance (the bound of the loose-tolerance
    // test, test_trajectory.cpp). Measured 0.27 tolerances; uncapped (1e-5 steps) 8.9.
    {
        const Vec3 q(0.02, -0.01, 0.5);
        const Vec3 S(fig4.v_ref(), fig4.v_ref(), fig4.v_ref() / fig4.part.rho());
        LimitCycleOptions ref;
        ref.tol = 1e-9;
        ref.integration.rtol = 1e-10;
        ref.integration.large_slip_factor = 1;
        const LimitCycleSummary r = limit_cycle(fig4, q, ref);
        REQUIRE(r.converged);
        LimitCycleOptions loose;
        loose.integration.rtol = 1e-6;
        loose.tol = 1e-5;
        const LimitCycleSummary l = limit_cycle(fig4, q, loose, r.qd_start + 0.05 * S);
        REQUIRE(l.converged);
        CHECK((l.twist - r.twist).cwiseQuotient(S).cwiseAbs().maxCoeff() < 2 * loose.tol);
    }
    // foot.json pivots on its lone contact for a tenth of the period at every configuration. Its
    // sticking cycles' error comes from the hold threshold (8.6e-7 v_ref at factor 1). A cycle that
    // changes mode goes on tight after the first such period and is not accepted on a loose one, and
    // in a field its first period is tight after a neighbour that changed mode: with none of the three,
    // 1.21e-6 here; the first or the third alone passes; the second alone keeps the cycle loose where it
    // may not accept it (fig6's field above then took 1.47e7 right-hand sides). Bound: the study's
    // target, 1e-6 v_ref.
    const Scene foot = scene("foot");
    CHECK(worst(foot, compute_field(foot, GridSpec{}, FieldOptions{}), reference(foot)) < 1e-6);
}

TEST_CASE("shooting fields: predicted warm starts, the same field on any number of threads", "[field][shooting]") {
    const Scene sc = scene("fig4");
    GridSpec g;
    g.nx = g.ny = g.nth = 4;
    FieldOptions o1, o2, oa;
    o1.threads = 1;
    o2.threads = 2;
    oa.cycle.solver = CycleSolver::Anderson;
    const Field f1 = compute_field(sc, g, o1), f2 = compute_field(sc, g, o2), fa = compute_field(sc, g, oa);
    double periods = 0;
    for (int i = 0; i < g.size(); ++i) {
        REQUIRE(f1.points[i].converged);
        // Every prediction reads points solved before it in the same task: bit for bit the same.
        CHECK(f1.points[i].twist == f2.points[i].twist);
        // Both within tol = 1e-7 v_ref of the cycle (times |d xi_a/dx| <= 1.5), integration ~1e-8.
        CHECK((f1.points[i].twist - fa.points[i].twist).head<2>().norm() < 1e-6 * sc.v_ref());
        periods += f1.points[i].periods;
    }
    // Two periods for most points (the variational one, then a chord step to confirm); Anderson
    // needs about 6.5 on fig4.
    CHECK(periods / g.size() < 3.5);
}

TEST_CASE(
    "a plate moving only along and about z: the field turns with the part, and its predicted starts keep it "
    "the same on any number of threads",
    "[field][shooting][stick]") {
    // fig6 (z and rz harmonics) looks the same turned about the plate's origin, so the cycle at
    // (R_a s, theta + a) is the one at (s, theta) turned: twist (R_a v, theta'). Checked on cycles solved
    // from rest (no predictor) at a sliding and a sticking configuration, turned by 1 and 2.5 rad: within
    // the two cycles' accuracy, 2 (tol + 3e2 rtol) v_ref (the zero band counts where it sticks).
    // A sign error in the turn, or a turn about the wrong point, is off by the twist itself.
    const Scene sc = scene("fig6");
    LimitCycleOptions lo;
    const double v = sc.v_ref(), rho = sc.part.rho();
    for (const Vec3& q : {Vec3(0.03, -0.01, 0.4), Vec3(-0.05, 0.0167, 4.49)}) {
        const LimitCycleSummary a = limit_cycle(sc, q, lo);
        REQUIRE(a.converged);
        CHECK((*std::max_element(a.stick_fraction.begin(), a.stick_fraction.end()) > 0) == (q[0] < 0));   // (the second sticks)
        for (double turn : {1.0, 2.5}) {
            const Vec2 s = Eigen::Rotation2Dd(turn) * Vec2(q[0], q[1]);
            const LimitCycleSummary b = limit_cycle(sc, Vec3(s[0], s[1], q[2] + turn), lo);
            REQUIRE(b.converged);
            const Vec2 va = Eigen::Rotation2Dd(turn) * Vec2(a.twist[0], a.twist[1]);
            const double allowed = 2 * (lo.tol + 3e2 * lo.integration.rtol);
            INFO("at (" << q.transpose() << ") turned by " << turn << "; sticks " << a.stick_fraction[0] << ", "
                        << a.stick_fraction[1] << ", " << a.stick_fraction[2]);
            CHECK((Vec2(b.twist[0], b.twist[1]) - va).norm() / v <= allowed);
            CHECK(std::abs(b.twist[2] - a.twist[2]) * rho / v <= allowed);
        }
    }
    // The field predicts each start from this symmetry (field.cpp): from points solved before it in
    // every schedule, so the field is the same on one thread and on two, bit for bit.
    GridSpec g;
    g.nx = g.ny = g.nth = 5;
    FieldOptions o1, o2;
    o1.threads = 1;
    o2.threads = 2;
    const Field f1 = compute_field(sc, g, o1), f2 = compute_field(sc, g, o2);
    int sticking = 0;
    for (int i = 0; i < g.size(); ++i) {
        REQUIRE(f1.points[i].converged);
        CHECK(f1.points[i].twist == f2.points[i].twist);
        CHECK(f1.points[i].rhs_evals == f2.points[i].rhs_evals);
        sticking += *std::max_element(f1.points[i].stick_fraction.begin(), f1.points[i].stick_fraction.end()) > 0;
    }
    CHECK(sticking > 0);
}

TEST_CASE("fixed points: regions where the part is stuck all period are not refined, and work is bounded", "[field][stick]") {
    // heave_yaw_point: the point part is stuck all period at 9 of 49 configurations (twist exactly 0:
    // every such configuration is fixed). Their cells are counted and said, not searched by Newton.
    const Scene hp = scene("heave_yaw_point");
    const Field fh = compute_field(hp, GridSpec{});
    int stuck = 0;
    for (const auto& p : fh.points) stuck += p.converged && p.twist.isZero(0) && p.stick_fraction[0] == 1;
    REQUIRE(stuck > 0);
    const FixedPoints fp = find_fixed_points(hp, fh);
    CHECK(fp.stuck_cells > 0);
    CHECK(fp.stuck_cells <= 4 * stuck);   // each configuration is a corner of at most 4 cells
    CHECK(fixed_points_sentence(fp).find("a region where the part sticks") != std::string::npos);
    CHECK(fp.stuck_regions.size() == 1u);
    // Bounded work: fig1's search needs ~1.4e6 right-hand sides; with 1e5 it stops, and says so.
    const Scene f1 = scene("fig1");
    const Field ff = compute_field(f1, GridSpec{});
    FixedPointOptions o;
    o.max_rhs_evaluations = 100'000;
    const FixedPoints cut = find_fixed_points(f1, ff, o);
    CHECK(cut.unsearched_cells > 0);
    CHECK(cut.cells == 6 * 6 * 7);
    CHECK(cut.rhs_evaluations < 100'000 + 50'000);   // at most one field evaluation beyond the budget
    CHECK(fixed_points_sentence(cut).find("work budget") != std::string::npos);
}

namespace {

// A task runner that records the tasks' texts (running them in reverse order), and one that only
// replays recorded texts through done() without running anything: what a rank that computed none
// of the tasks sees under MPI. A field through the replay is whatever the texts carry.
struct Recorder {
    std::vector<std::vector<std::string>> calls;   // per runner call, per task
    TaskRunner record() {
        return
            [this](int n, const std::function<std::string(int)>& work, const std::function<void(int, const std::string&)>& done) {
                calls.emplace_back(static_cast<std::size_t>(n));
                for (int i = n - 1; i >= 0; --i) {
                    calls.back()[static_cast<std::size_t>(i)] = work(i);
                    done(i, calls.back()[static_cast<std::size_t>(i)]);
                }
            };
    }
    TaskRunner replay() {
        return [this, call = std::size_t{0}](int n, const std::function<std::string(int)>&,
                                             const std::function<void(int, const std::string&)>& done) mutable {
            REQUIRE(call < calls.size());
            REQUIRE(calls[call].size() == static_cast<std::size_t>(n));
            for (int i = 0; i < n; ++i) done(i, calls[call][static_cast<std::size_t>(i)]);
            ++call;
        };
    }
};

bool same(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }

void require_same_field(const Field& a, const Field& b) {
    REQUIRE(a.points.size() == b.points.size());
    for (std::size_t i = 0; i < a.points.size(); ++i) {
        const FieldPoint &p = a.points[i], &r = b.points[i];
        INFO("point " << i << " at " << p.q.transpose());
        CHECK(p.q == r.q);
        for (int c = 0; c < 3; ++c) {
            CHECK(same(p.twist[c], r.twist[c]));
            CHECK(same(p.stick_fraction[c], r.stick_fraction[c]));
        }
        CHECK(same(p.residual, r.residual));
        CHECK(same(p.min_normal_force, r.min_normal_force));
        CHECK(p.converged == r.converged);
        CHECK(p.periods == r.periods);
        CHECK(p.stop == r.stop);
        CHECK(p.rhs_evals == r.rhs_evals);
    }
    CHECK(a.rhs_evals == b.rhs_evals);
}

}   // namespace

// Issue 20: a field shared over processes (plate field under mpirun) is the field of one process,
// bit for bit, because every task's points are solved from the same inputs wherever it runs and
// travel exactly. fig6 at 5x5x5 sticks in part (stick fractions, undefined points: NaN twists).
TEST_CASE("field: its tasks, run anywhere and sent as text, give the one-process field bit for bit", "[field][tasks]") {
    const Scene sc = scene("fig6");
    GridSpec g;
    g.nx = g.ny = g.nth = 5;
    for (CycleSolver solver : {CycleSolver::Shooting, CycleSolver::Anderson}) {
        INFO(cycle_solver_name(solver));
        FieldOptions o;
        o.cycle.solver = solver;
        const Field one = compute_field(sc, g, o);
        bool sticks = false;
        for (const auto& p : one.points)
            sticks = sticks || p.stick_fraction[0] > 0 || p.stick_fraction[1] > 0 || p.stick_fraction[2] > 0;
        REQUIRE(sticks);   // (the texts must carry stick fractions)
        Recorder rec;
        o.tasks = rec.record();
        require_same_field(one, compute_field(sc, g, o));
        REQUIRE(rec.calls.size() == 1);
        // Shooting: the lines (x, y_0, theta), (x, y, theta_0) in every process, then a task per plane
        // x_i; otherwise a task per line along theta.
        CHECK(rec.calls[0].size() == static_cast<std::size_t>(solver == CycleSolver::Shooting ? g.nx : g.nx * g.ny));
        o.tasks = rec.replay();
        const Field replayed = compute_field(sc, g, o);
        require_same_field(one, replayed);
        CHECK(replayed.threads == 0);
    }
}

TEST_CASE("exact_text reads back to the same double, nan and infinities included", "[tasks]") {
    for (double x : {0.1, -1.0 / 3, 5e-324, 2.2250738585072014e-308, 1.7976931348623157e308, -0.0, 1e-17}) {
        const double y = exact_value(exact_text(x));
        CHECK(std::memcmp(&x, &y, sizeof x) == 0);
    }
    CHECK(std::isnan(exact_value(exact_text(std::nan("")))));
    CHECK(exact_value(exact_text(HUGE_VAL)) == HUGE_VAL);
    CHECK(exact_value(exact_text(-HUGE_VAL)) == -HUGE_VAL);
    CHECK_THROWS_AS(exact_value("0.1x"), std::invalid_argument);
    CHECK_THROWS_AS(exact_value(""), std::invalid_argument);
}

// Differences of field_curve's ends at steps h, h/2, h/4 shrink by 2^p for a method of order p:
// 16 for classical RK4. From (0.04, -0.04, 1) over 4 s (fig4's part reaches the centre, fig1_point's
// slides 4 cm) at h = 0.25, 0.125, 0.0625 s the ratio d(h, h/2) / d(h/2, h/4) was 20.2 (fig4) and 18.8
// (fig1_point), still above 16 (the next term); at h/8 fig4's difference falls to the cycles' noise
// (1.6e-9 m). Between 8 (third order) and 32 (fifth): 12 to 32.
TEST_CASE("field_curve is fourth order: its ends at steps h to h/4 differ by ratios near 16", "[field][trajectory]") {
    for (const char* name : {"fig4", "fig1_point"}) {
        const Scene sc = scene(name);
        const Vec3 q0(0.04, -0.04, sc.part.point ? 0.0 : 1.0);
        const double dur = 4;
        std::vector<Vec3> ends;
        for (double h : {0.25, 0.125, 0.0625}) {
            const Trajectory c = field_curve(sc, q0, dur, dur, {}, h);
            REQUIRE(c.stop.reason == StopReason::None);
            ends.push_back(c.samples.back().q);
        }
        const double d1 = (ends[0] - ends[1]).norm(), d2 = (ends[1] - ends[2]).norm();
        INFO(name << ": differences " << d1 << ", " << d2 << " m");
        CHECK(d1 / d2 > 12);
        CHECK(d1 / d2 < 32);
    }
}
