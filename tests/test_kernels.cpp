// The generated kernels (numeric/generated/) against the hand-written reference implementation
// and against GiNaC's own evaluation of the symbolic expressions they were generated from.
#include "derivation.hpp"
#include "plate/dynamics.hpp"
#include "plate/random_scene.hpp"

#include "so3.hpp"         // exp_so3
#include "workspace.hpp"   // detail::kernels (numeric/src)

#include <catch2/catch.hpp>

#include <cmath>

using namespace plate;

namespace {

struct RandomState {
    Vec3 q, qd;
    PlateState ps;
};

RandomState random_state(Rng& r, bool tilt) {
    RandomState s;
    s.q = Vec3{r.uniform(-0.03, 0.03), r.uniform(-0.03, 0.03), r.uniform(-kPi, kPi)};
    s.qd = Vec3{r.uniform(-0.3, 0.3), r.uniform(-0.3, 0.3), r.uniform(-20, 20)};
    s.ps.pdd = Vec3{r.uniform(-25, 25), r.uniform(-25, 25), r.uniform(-3, 3)};
    s.ps.wd = Vec3{r.uniform(-60, 60), r.uniform(-60, 60), r.uniform(-150, 150)};
    if (tilt) {
        s.ps.R1 = detail::exp_so3(Vec3{r.uniform(-0.1, 0.1), r.uniform(-0.1, 0.1), r.uniform(-0.5, 0.5)});
        s.ps.w1 = Vec3{r.uniform(-3, 3), r.uniform(-3, 3), r.uniform(-3, 3)};
    }
    return s;
}

// A random kernel input IN (a part, its contacts, a state, a plate motion) and SUB, the same values for
// the derivation's symbols S.
void random_input(Rng& r, const symbolic::Symbols& S, gen::KernelInput& in, GiNaC::exmap& sub) {
    using namespace GiNaC;
    auto set = [&](double& field, const realsymbol& s, double v) {
        field = v;
        sub[s] = v;
    };
    set(in.m, S.m, r.uniform(0.01, 0.1));
    set(in.g, S.g, 9.81);
    set(in.Jxx, S.Jxx, r.uniform(1e-5, 5e-5));
    set(in.Jxy, S.Jxy, r.uniform(-1e-6, 1e-6));
    set(in.Jxz, S.Jxz, r.uniform(-1e-6, 1e-6));
    set(in.Jyy, S.Jyy, r.uniform(1e-5, 5e-5));
    set(in.Jyz, S.Jyz, r.uniform(-1e-6, 1e-6));
    set(in.Jzz, S.Jzz, r.uniform(2e-5, 6e-5));
    double* cx[3] = {&in.c1x, &in.c2x, &in.c3x};
    double* cy[3] = {&in.c1y, &in.c2y, &in.c3y};
    double* mu[3] = {&in.mu1, &in.mu2, &in.mu3};
    double* ux[3] = {&in.u1x, &in.u2x, &in.u3x};
    double* uy[3] = {&in.u1y, &in.u2y, &in.u3y};
    for (int i = 0; i < 3; ++i) {
        const double a = 2 * kPi * i / 3 + r.uniform(-0.3, 0.3), rad = r.uniform(0.01, 0.05);
        set(*cx[i], S.cx[i], rad * std::cos(a));
        set(*cy[i], S.cy[i], rad * std::sin(a));
        set(*mu[i], S.mu[i], r.uniform(0.1, 0.4));
        const double b = r.uniform(-kPi, kPi);
        set(*ux[i], S.ux[i], std::cos(b));
        set(*uy[i], S.uy[i], std::sin(b));
    }
    set(in.cz, S.cz, -r.uniform(0.001, 0.01));
    set(in.sz, S.sz, -in.cz);
    const double th = r.uniform(-kPi, kPi);
    set(in.ct, S.ct, std::cos(th));
    set(in.st, S.st, std::sin(th));
    set(in.thd, S.thd, r.uniform(-20, 20));
    set(in.sx, S.sx, r.uniform(-0.03, 0.03));
    set(in.sy, S.sy, r.uniform(-0.03, 0.03));
    set(in.sxd, S.sxd, r.uniform(-0.3, 0.3));
    set(in.syd, S.syd, r.uniform(-0.3, 0.3));
    double* pdd[3] = {&in.pddx, &in.pddy, &in.pddz};
    double* w[3] = {&in.wx, &in.wy, &in.wz};
    double* wd[3] = {&in.wdx, &in.wdy, &in.wdz};
    for (int i = 0; i < 3; ++i) {
        set(*pdd[i], S.pdd[i], r.uniform(-20, 20));
        set(*w[i], S.w[i], r.uniform(-3, 3));
        set(*wd[i], S.wd[i], r.uniform(-100, 100));
    }
    const Mat3 R1 = detail::exp_so3(Vec3{r.uniform(-0.2, 0.2), r.uniform(-0.2, 0.2), r.uniform(-1, 1)});
    double* Rf[9] = {&in.R11, &in.R12, &in.R13, &in.R21, &in.R22, &in.R23, &in.R31, &in.R32, &in.R33};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) set(*Rf[3 * i + j], S.R[i][j], R1(i, j));
}

}   // namespace

TEST_CASE("generated kernels equal the reference implementation on 10^4 random states", "[kernels]") {
    // Both solve the same linear system in floating point (3x3 reduced vs 6x6 LU): they differ by
    // rounding amplified by the condition number, ~1e-13 here. Bound: 1e-12 of each quantity's
    // scale (g for s'', g / rho for theta'', m g for N).
    int count[3] = {0, 0, 0};
    double worst = 0;
    for (std::uint64_t seed = 1; seed <= 200; ++seed) {
        const int kind = seed % 3;   // 0 thick, 1 thin, 2 point
        RandomSceneOptions ro;
        ro.thin = kind == 1;
        ro.point = kind == 2;
        const Scene sc = random_scene(seed, ro);
        Rng r(seed * 977);
        Workspace gen, ref;
        for (int k = 0; k < 60; ++k) {
            const bool full = k % 2 == 1;
            const RandomState st = random_state(r, full);
            const Dynamics level = full ? Dynamics::Full : (k % 4 == 0 ? Dynamics::U : Dynamics::ReducedU);
            // Reduced U-dynamics: a second state at the same configuration runs on the slots
            // computed for the first (the per-configuration cache).
            for (int again = 0; again < (level == Dynamics::ReducedU ? 2 : 1); ++again) {
                RandomState s2 = st;
                if (again) {
                    const RandomState o = random_state(r, false);
                    s2.qd = o.qd;
                    s2.ps = o.ps;
                }
                accelerations(sc, level, s2.q, s2.qd, s2.ps, gen);
                accelerations_reference(sc, level, s2.q, s2.qd, s2.ps, ref);
                const double g = sc.g, w = g / sc.part.rho(), mg = sc.part.m * g;
                const double e = std::max({std::abs(gen.qdd[0] - ref.qdd[0]) / g, std::abs(gen.qdd[1] - ref.qdd[1]) / g,
                                           std::abs(gen.qdd[2] - ref.qdd[2]) / w, (gen.n - ref.n).cwiseAbs().maxCoeff() / mg});
                worst = std::max(worst, e);
                CHECK(e < 1e-12);
                ++count[kind];
            }
        }
        CHECK(detail::kernels(gen).thin == (kind == 1));
    }
    CHECK(count[0] + count[1] + count[2] >= 10000);
    WARN("generated vs reference: worst difference " << worst << " (thick " << count[0] << ", thin " << count[1] << ", point "
                                                     << count[2] << " states)");
}

TEST_CASE("generated kernels equal GiNaC's evaluation of the derived expressions", "[kernels][symbolic]") {
    using namespace GiNaC;
    static const symbolic::Derivation d = symbolic::derive();
    const symbolic::Symbols& S = d.S;
    Rng r(2024);
    for (int trial = 0; trial < 30; ++trial) {
        gen::KernelInput in;
        exmap sub;
        random_input(r, S, in, sub);

        auto value = [&](const ex& e) { return ex_to<numeric>(e.subs(sub).evalf()).to_double(); };
        auto close = [](double a, double b, double scale) { return std::abs(a - b) <= 1e-12 * (std::abs(b) + scale); };
        double A[36], bU[6], bF[6];
        gen::thick_A(in, A);
        gen::b_U(in, bU);
        gen::b_full(in, bF);
        for (int i = 0; i < 6; ++i) {
            for (int k = 0; k < 6; ++k) CHECK(close(A[6 * i + k], value(d.A(i, k)), 1e-6));
            CHECK(close(bU[i], value(d.b_U(i, 0)), in.m * in.g * 1e-3));
            CHECK(close(bF[i], value(d.b_full(i, 0)), in.m * in.g * 1e-3));
        }
        // Solutions: reduced system and back substitution against GiNaC's solve of A z = b.
        double M[9], rr[3], qdd[3];
        gen::thick_reduced(in, bU, M, rr);
        const Vec3 n =
            Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(M).partialPivLu().solve(Eigen::Map<const Vec3>(rr));
        gen::back_substitution(in, bU, n.data(), qdd);
        matrix An(6, 6), bn(6, 1);
        for (int i = 0; i < 6; ++i) {
            for (int k = 0; k < 6; ++k) An(i, k) = d.A(i, k).subs(sub).evalf();
            bn(i, 0) = d.b_U(i, 0).subs(sub).evalf();
        }
        const matrix z =
            An.solve(matrix{{symbol("z0")}, {symbol("z1")}, {symbol("z2")}, {symbol("z3")}, {symbol("z4")}, {symbol("z5")}}, bn);
        double n2[3], qdd2[3], det;
        gen::thick_solve(in, bU, n2, qdd2, &det);
        for (int i = 0; i < 3; ++i) {
            const double zq = ex_to<numeric>(z(i, 0).evalf()).to_double(), zn = ex_to<numeric>(z(3 + i, 0).evalf()).to_double();
            CHECK(close(qdd[i], zq, 1.0));
            CHECK(close(n[i], zn, in.m * in.g));
            CHECK(close(qdd2[i], zq, 1.0));
            CHECK(close(n2[i], zn, in.m * in.g));
        }
        // The reduced U-dynamics' staged kernels: slots for the configuration, then one evaluation.
        {
            double C[gen::reduced_U_thick_slots], n3[3], q3[3], det3;
            gen::reduced_U_thick_config(in, C);
            gen::reduced_U_thick(in, C, n3, q3, &det3);
            CHECK(close(det3, det, 1e-12));
            for (int i = 0; i < 3; ++i) {
                CHECK(close(q3[i], ex_to<numeric>(z(i, 0).evalf()).to_double(), 1.0));
                CHECK(close(n3[i], ex_to<numeric>(z(3 + i, 0).evalf()).to_double(), in.m * in.g));
            }
        }
        {
            // Point part: the derived solution with b~ of a point (s_z = 0).
            gen::KernelInput pin = in;
            pin.sz = 0;
            exmap psub = sub;
            psub[S.sz] = 0;
            exmap b_of;
            for (int r = 0; r < 3; ++r) b_of[d.bsym[r]] = d.b_U(r, 0);
            double C[gen::reduced_U_point_slots], zp[3];
            gen::reduced_U_point_config(pin, C);
            gen::reduced_U_point(pin, C, zp);
            for (int i = 0; i < 3; ++i)
                CHECK(close(zp[i], ex_to<numeric>(d.point_solution(i, 0).subs(b_of).subs(psub).evalf()).to_double(),
                            i < 2 ? 1.0 : in.m * in.g));
        }

        // Stick-slip modes: the pivot systems and the stuck solve (with b = b_full), against GiNaC.
        {
            using System = void (*)(const gen::KernelInput&, double*, double*);
            const System pivot[3] = {gen::pivot1_system, gen::pivot2_system, gen::pivot3_system};
            for (int k = 0; k < 3; ++k) {
                double Ap[64], cp[2];
                pivot[k](in, Ap, cp);
                for (int i = 0; i < 8; ++i)
                    for (int j = 0; j < 8; ++j) {
                        INFO("pivot " << k << " A(" << i << "," << j << ") " << Ap[8 * i + j] << " vs "
                                      << value(d.pivot_A[k](i, j)));
                        CHECK(close(Ap[8 * i + j], value(d.pivot_A[k](i, j)), 1e-6));
                    }
                for (int i = 0; i < 2; ++i) CHECK(close(cp[i], value(d.pivot_c[k](i, 0)), 1e-3));
            }
            exmap bsub = sub;
            for (int i = 0; i < 6; ++i) bsub[d.bsym[i]] = bF[i];
            double ns[3], ws[3];
            gen::stuck_solve(in, bF, ns, ws);
            for (int i = 0; i < 6; ++i) {
                const double expect = ex_to<numeric>((d.stuck_solution(i, 0) / d.stuck_det).subs(bsub).evalf()).to_double();
                CHECK(close(i < 3 ? ns[i] : ws[i - 3], expect, in.m * in.g * (i == 5 ? 0.05 : 1.0)));
            }
        }

        // The thin part's specialised kernel against GiNaC's solve of the thin system.
        gen::KernelInput tin = in;
        exmap tsub = sub;
        tin.cz = tin.sz = tin.Jxz = tin.Jyz = 0;
        tsub[S.cz] = 0;
        tsub[S.sz] = 0;
        tsub[S.Jxz] = 0;
        tsub[S.Jyz] = 0;
        double M38[9];
        gen::thin_M38(tin, M38);
        Eigen::Matrix<double, 3, 3, Eigen::RowMajor> Minv =
            Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(M38).inverse();
        double bt[6], nt[3], qt[3];
        gen::thin_solve_U(tin, Minv.data(), bt, nt, qt);
        for (int i = 0; i < 6; ++i) {
            for (int k = 0; k < 6; ++k) An(i, k) = d.A(i, k).subs(tsub).evalf();
            bn(i, 0) = d.b_U(i, 0).subs(tsub).evalf();
        }
        const matrix zt =
            An.solve(matrix{{symbol("z0")}, {symbol("z1")}, {symbol("z2")}, {symbol("z3")}, {symbol("z4")}, {symbol("z5")}}, bn);
        double Ct[gen::reduced_U_thin_slots], nts[3], qts[3];
        gen::reduced_U_thin_config(tin, Minv.data(), Ct);
        gen::reduced_U_thin(tin, Ct, nts, qts);
        for (int i = 0; i < 3; ++i) {
            CHECK(close(qt[i], ex_to<numeric>(zt(i, 0).evalf()).to_double(), 1.0));
            CHECK(close(nt[i], ex_to<numeric>(zt(3 + i, 0).evalf()).to_double(), in.m * in.g));
            CHECK(close(qts[i], ex_to<numeric>(zt(i, 0).evalf()).to_double(), 1.0));
            CHECK(close(nts[i], ex_to<numeric>(zt(3 + i, 0).evalf()).to_double(), in.m * in.g));
        }
    }
}

TEST_CASE("the limit-surface kernel is the derived wrench", "[kernels][symbolic]") {
    using namespace GiNaC;
    static const symbolic::Derivation d = symbolic::derive();
    const symbolic::Symbols& S = d.S;
    Rng r(7);
    for (int trial = 0; trial < 50; ++trial) {
        gen::WrenchInput in;
        exmap sub;
        double* N[3] = {&in.N1, &in.N2, &in.N3};
        double* rx[3] = {&in.r1x, &in.r2x, &in.r3x};
        double* ry[3] = {&in.r1y, &in.r2y, &in.r3y};
        double* mu[3] = {&in.mu1, &in.mu2, &in.mu3};
        double* mus[3] = {&in.mus1, &in.mus2, &in.mus3};   // static above kinetic: the kernels must read each
        for (int i = 0; i < 3; ++i) {
            *N[i] = r.uniform(0.01, 0.2);
            *rx[i] = r.uniform(-0.05, 0.05);
            *ry[i] = r.uniform(-0.05, 0.05);
            *mu[i] = r.uniform(0.1, 0.4);
            *mus[i] = *mu[i] * r.uniform(1.1, 1.5);
            sub[S.N[i]] = *N[i];
            sub[S.rx[i]] = *rx[i];
            sub[S.ry[i]] = *ry[i];
            sub[S.mu[i]] = *mu[i];
            sub[S.mus[i]] = *mus[i];
        }
        in.rho = r.uniform(0.01, 0.04);
        in.vx = r.uniform(-0.3, 0.3);
        in.vy = r.uniform(-0.3, 0.3);
        in.xith = r.uniform(-0.3, 0.3);
        sub[S.rho] = in.rho;
        sub[S.vx] = in.vx;
        sub[S.vy] = in.vy;
        sub[S.xith] = in.xith;
        double w[3];
        gen::thin_wrench(in, w);
        const double scale = 0.4 * (in.N1 + in.N2 + in.N3);
        for (int i = 0; i < 3; ++i) {
            const double expect = ex_to<numeric>(d.wrench(i, 0).subs(sub).evalf()).to_double();
            CHECK(std::abs(w[i] - expect) <= 1e-12 * scale);
        }
        // The support function's terms (the stuck part's break-away test) with gradient and Hessian.
        double sp[3], tm[3], gr[9], he[18];
        gen::friction_support(in, sp, tm, gr, he);
        const realsymbol dv[3] = {S.vx, S.vy, S.xith};
        for (int i = 0; i < 3; ++i) {
            const double cap = *mus[i] * *N[i];
            CHECK(std::abs(sp[i] - ex_to<numeric>(d.support_speed[i].subs(sub).evalf()).to_double()) <= 1e-12 * sp[i]);
            CHECK(std::abs(tm[i] - ex_to<numeric>(d.support_term[i].subs(sub).evalf()).to_double()) <= 1e-12 * tm[i]);
            int h = 0;
            for (int a = 0; a < 3; ++a) {
                const ex ga = d.support_term[i].diff(dv[a]);
                CHECK(std::abs(gr[3 * i + a] - ex_to<numeric>(ga.subs(sub).evalf()).to_double()) <= 1e-12 * cap * 10);
                for (int b = a; b < 3; ++b, ++h)
                    CHECK(std::abs(he[6 * i + h] - ex_to<numeric>(ga.diff(dv[b]).subs(sub).evalf()).to_double()) <=
                          1e-11 * cap * 100 / sp[i]);
            }
        }
        // The support function is the power the static disks would dissipate, whose gradient is minus the
        // wrench with mu_si in place of mu_ki: each contact's term scaled by mu_ki / mu_si gives the wrench.
        for (int a = 0; a < 3; ++a) {
            double sum = 0;
            for (int i = 0; i < 3; ++i) sum += gr[3 * i + a] * *mu[i] / *mus[i];
            CHECK(std::abs(sum + w[a]) <= 1e-12 * scale);
        }
        // Coulomb: each contact's force is mu_i N_i against its own slip v_i = (v_x - xi r_iy / rho, v_y +
        // xi r_ix / rho), so the wrench's power is minus the sum of mu_i N_i |v_i| (written out here).
        double dissipated = 0;
        for (int i = 0; i < 3; ++i)
            dissipated += *mu[i] * *N[i] * std::hypot(in.vx - in.xith * *ry[i] / in.rho, in.vy + in.xith * *rx[i] / in.rho);
        // (Rounding: measured 1.7e-16 of scale at most; bound 5e-16.)
        CHECK(std::abs(w[0] * in.vx + w[1] * in.vy + w[2] * in.xith + dissipated) <= 5e-16 * scale);
    }
}
