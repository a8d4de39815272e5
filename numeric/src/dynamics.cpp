#include "plate/dynamics.hpp"

#include "workspace.hpp"

#include <cmath>
#include <limits>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#include <stdexcept>

namespace plate {

const char* dynamics_name(Dynamics d) {
    switch (d) {
        case Dynamics::Full:
            return "full";
        case Dynamics::U:
            return "u";
        case Dynamics::ReducedU:
            return "reduced-u";
    }
    return "?";
}

PlateState plate_state(const PlateMotion& plate, double t, Dynamics level, const Mat3& R1) {
    PlateState ps;
    plate.acceleration(t, ps.pdd, ps.wd);
    if (level == Dynamics::Full) {
        Vec3 pd;
        plate.velocity(t, pd, ps.w1);
        ps.R1 = R1;
    }
    return ps;
}

void contact_offsets(const Part& part, double theta, std::array<Vec2, 3>& r) {
    const double c = std::cos(theta), s = std::sin(theta);
    for (int i = 0; i < 3; ++i)
        r[i] = Vec2(c * part.c[i].x() - s * part.c[i].y(), s * part.c[i].x() + c * part.c[i].y());   // R2 c_i
}

void slip_velocities_at(const Part& part, const std::array<Vec2, 3>& r, const Vec3& qd, std::array<Vec2, 3>& v) {
    if (part.point) {
        v[0] = qd.head<2>();
        v[1].setZero();
        v[2].setZero();
        return;
    }
    for (int i = 0; i < 3; ++i) v[i] = Vec2(qd[0] - qd[2] * r[i].y(), qd[1] + qd[2] * r[i].x());   // s' + w2^ R2 c_i
}

void slip_velocities(const Part& part, const Vec3& q, const Vec3& qd, std::array<Vec2, 3>& v) {
    std::array<Vec2, 3> r;
    if (!part.point) contact_offsets(part, q[2], r);
    slip_velocities_at(part, r, qd, v);
}

Vec6 rhs_b(const Scene& sc, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& ps) {
    return detail::rhs_b(sc, level, q, qd, ps, std::cos(q[2]), std::sin(q[2]));
}

namespace detail {
Vec6 rhs_b(const Scene& sc, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& ps, double ct, double st) {
    const Part& P = sc.part;
    Mat3 R2;   // rot_z(q[2])
    R2 << ct, -st, 0, st, ct, 0, 0, 0, 1;
    const Vec3 s(q[0], q[1], P.s_z());
    const Vec3 ez = Vec3::UnitZ();
    Vec6 b;
    if (level != Dynamics::Full) {
        // (33), (34)
        b.head<3>() = P.m * (ps.pdd + ps.wd.cross(s) + sc.g * ez);
        b.tail<3>() = P.point ? Vec3::Zero() : Vec3(P.J * (R2.transpose() * ps.wd));
        return b;
    }
    // (19): f_dagger = m R1^T (p'' + w1^ w1^ R1 s + w1'^ R1 s + 2 w1^ R1 s' + g e_z)
    const Mat3& R1 = ps.R1;
    const Vec3 sd(qd[0], qd[1], 0);
    const Vec3 Rs = R1 * s, Rsd = R1 * sd;
    b.head<3>() =
        P.m * (R1.transpose() * (ps.pdd + ps.w1.cross(ps.w1.cross(Rs)) + ps.wd.cross(Rs) + 2 * ps.w1.cross(Rsd) + sc.g * ez));
    if (P.point) {
        b.tail<3>().setZero();
        return b;
    }
    // (30) with (28) corrected: d/dt(R2^T R1^T w1) = -R2^T w2^ R1^T w1 + R2^T R1^T w1'.
    const Mat3 R2t = R2.transpose();
    const Vec3 w2(0, 0, qd[2]);
    const Vec3 R1tw1 = R1.transpose() * ps.w1;
    const Vec3 w3 = w2 + R2t * R1tw1;   // (27)
    b.tail<3>() = P.J * (-(R2t * w2.cross(R1tw1)) + R2t * (R1.transpose() * ps.wd)) + w3.cross(P.J * w3);
    return b;
}
}   // namespace detail

Workspace::Workspace() = default;
Workspace::Workspace(const Workspace& o) = default;
Workspace& Workspace::operator=(const Workspace& o) = default;
Workspace::~Workspace() = default;

void Workspace::prepare(const Scene& sc) {
    detail::KernelScratch& ks = detail::kernels(*this);
    const Part& P = sc.part;
    ks.prepared = &sc;
    ks.pivot_k = -1;   // (the part's parameters are in the pivot's matrix)
    ks.in = gen::KernelInput{};
    ks.in.m = P.m;
    ks.in.g = sc.g;
    ks.in.Jxx = P.J(0, 0);
    ks.in.Jxy = P.J(0, 1);
    ks.in.Jxz = P.J(0, 2);
    ks.in.Jyy = P.J(1, 1);
    ks.in.Jyz = P.J(1, 2);
    ks.in.Jzz = P.J(2, 2);
    ks.in.c1x = P.c[0].x();
    ks.in.c1y = P.c[0].y();
    ks.in.c2x = P.c[1].x();
    ks.in.c2y = P.c[1].y();
    ks.in.c3x = P.c[2].x();
    ks.in.c3y = P.c[2].y();
    ks.in.cz = P.point ? 0.0 : P.c[0].z();
    ks.in.sz = P.s_z();
    const ContactFriction fr = P.friction();   // (the kernels' slides take the kinetic coefficients)
    ks.in.mu1 = fr.kinetic(0);
    ks.in.mu2 = fr.kinetic(1);
    ks.in.mu3 = fr.kinetic(2);
    ks.in.R11 = ks.in.R22 = ks.in.R33 = 1;
    ks.theta = std::numeric_limits<double>::quiet_NaN();
    ks.C_q = Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
    ks.thin = P.thin();
    if (ks.thin) {
        double M[9];
        gen::thin_M38(ks.in, M);
        ks.M38_inv = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(M).inverse();
        Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(ks.M38_inv_rowmajor.data()) = ks.M38_inv;
    }
    // det of the reduced system ~ (contact spread)^2: below 1e-9 of that, fall back to LU.
    double size = 0;
    for (int i = 0; i < 3; ++i) size = std::max(size, P.c[i].head<2>().norm());
    ks.det_floor = 1e-9 * size * size;
}

namespace {

// The plate's inputs of the kernels: u(t) = (p'', omega1') in the plate frame.
inline void set_plate_accelerations(const PlateState& ps, gen::KernelInput& in) {
    in.pddx = ps.pdd.x();
    in.pddy = ps.pdd.y();
    in.pddz = ps.pdd.z();
    in.wdx = ps.wd.x();
    in.wdy = ps.wd.y();
    in.wdz = ps.wd.z();
}

// Configuration inputs of the kernels: s, and cos/sin theta with R2 c_i (cached: constant in the
// reduced U-dynamics).
inline void set_configuration(const Part& P, const Vec3& q, Workspace& ws) {
    detail::KernelScratch& ks = detail::kernels(ws);
    gen::KernelInput& in = ks.in;
    const double theta = q[2];   // (a local: the stores below could alias q, which would keep sin and cos apart)
    if (theta != ks.theta) {
        ks.theta = theta;
        in.ct = std::cos(theta);
        in.st = std::sin(theta);
        for (int i = 0; i < 3; ++i)
            ws.r[i] = Vec2(in.ct * P.c[i].x() - in.st * P.c[i].y(), in.st * P.c[i].x() + in.ct * P.c[i].y());
    }
    in.sx = q[0];
    in.sy = q[1];
}

// Sliding velocities v_i = s' + w2^ R2 c_i of the first nc contacts (into ws.slip) and their unit
// directions u_i = f_i v_i (zero at zero slip; the regularised laws scale instead). The contacts
// are independent: computed side by side, so their square roots and divisions overlap.
inline void slip_directions(int nc, const Vec3& qd, Workspace& ws, double* ux, double* uy) {
    const detail::StickSlipState& ss = detail::stick_slip(ws);
    const double w = nc == 1 ? 0.0 : qd[2];
    double vx[3], vy[3], f[3];
    for (int i = 0; i < nc; ++i) {
        vx[i] = qd[0] - w * ws.r[i].y();
        vy[i] = qd[1] + w * ws.r[i].x();
    }
    double sp[3];   // |v_i|^2 (Coulomb's directions and the hints below)
    for (int i = 0; i < nc; ++i) sp[i] = vx[i] * vx[i] + vy[i] * vy[i];
    if (ws.law == FrictionLaw::Coulomb) {
        int packed = 0;
#if defined(__SSE2__)
        if (nc == 3) {
            // The square roots and divisions share one unit and dominate an evaluation: contacts
            // 1 and 2 in packed instructions (a zero speed gives 1/0 = inf, masked to 0).
            const __m128d s01 = _mm_set_pd(sp[1], sp[0]);
            const __m128d pos = _mm_cmpgt_pd(s01, _mm_setzero_pd());
            _mm_storeu_pd(f, _mm_and_pd(pos, _mm_div_pd(_mm_set1_pd(1.0), _mm_sqrt_pd(s01))));
            packed = 2;
        }
#endif
        for (int i = packed; i < nc; ++i) f[i] = sp[i] > 0 ? 1.0 / std::sqrt(sp[i]) : 0.0;
    } else {
        for (int i = 0; i < nc; ++i) f[i] = regularised_factor(ws.law, ws.law_eps, std::hypot(vx[i], vy[i]));
    }
    for (int i = 0; i < nc; ++i) {
        ws.slip[i] = Vec2(vx[i], vy[i]);
        ux[i] = vx[i] * f[i];
        uy[i] = vy[i] * f[i];
    }
    if (ss.use_hints) {
        const double hs2 = ss.hint_speed * ss.hint_speed;
        for (int i = 0; i < nc; ++i) {
            const double s2 = sp[i];
            const double along = vx[i] * ss.hint[i].x() + vy[i] * ss.hint[i].y();
            const bool past_zero = s2 < 0.01 * ss.hint_from[i] * ss.hint_from[i] && (along <= 0 || along * along <= 0.25 * s2);
            if (s2 <= hs2 || past_zero || (ss.creep >> i & 1u)) {
                ux[i] = ss.hint[i].x();
                uy[i] = ss.hint[i].y();
            }
        }
    }
    for (int i = nc; i < 3; ++i) ws.slip[i].setZero();
}

// A point part's reduced U-dynamics (35) at the configuration whose slots are cached
// (accelerations_reduced_U), with Jq as there.
inline void reduced_U_point(const Vec3& qd, const PlateState& ps, Workspace& ws, Mat3* Jq) {
    detail::KernelScratch& ks = detail::kernels(ws);
    // The staged kernels read only the slip directions and u(t): those fields are written here.
    gen::KernelInput& k = ks.staged;
    set_plate_accelerations(ps, k);
    double ux[1], uy[1];
    slip_directions(1, qd, ws, ux, uy);
    k.u1x = ux[0];
    k.u1y = uy[0];
    double z[3];
    double dq[4];   // d s''_r / d u_j, row-major (2 x 2)
    if (Jq)
        gen::reduced_U_point_du(k, ks.C.data(), z, dq);
    else
        gen::reduced_U_point(k, ks.C.data(), z);
    ws.qdd = Vec3(z[0], z[1], 0);
    ws.n = Vec3(z[2], 0, 0);
    if (Jq) {
        Jq->setZero();
        Jq->topLeftCorner<2, 2>() = Eigen::Map<const Eigen::Matrix<double, 2, 2, Eigen::RowMajor>>(dq) *
                                    direction_derivative(ws.law, ws.law_eps, ws.slip[0]);
    }
}

// Reduced U-dynamics (35) on the staged kernels: the slots of the frozen configuration once, then
// per evaluation only the slip directions and u(t). Returns false when a thick part's reduced
// system is near singular (the caller then takes the direct path with its pivoted LU). With Jq,
// also d q''/d q' = sum_i (d q''/d u_i) (d u_i/d v_i) (d v_i/d q'): the first factor from the
// generated *_du kernels, the second the friction law's, the third [I, (-r_iy, r_ix)] with
// r_i = R2 c_i (v_i = s' + theta' e_z x r_i).
bool accelerations_reduced_U(const Part& P, const Vec3& q, const Vec3& qd, const PlateState& ps, Workspace& ws,
                             Mat3* Jq = nullptr) {
    detail::KernelScratch& ks = detail::kernels(ws);
    if (q[0] != ks.C_q[0] || q[1] != ks.C_q[1] || q[2] != ks.C_q[2]) {
        set_configuration(P, q, ws);
        ks.C_q = q;
        if (P.point)
            gen::reduced_U_point_config(ks.in, ks.C.data());
        else if (ks.thin)
            gen::reduced_U_thin_config(ks.in, ks.M38_inv_rowmajor.data(), ks.C.data());
        else
            gen::reduced_U_thick_config(ks.in, ks.C.data());
    }
    if (P.point) {
        reduced_U_point(qd, ps, ws, Jq);
        return true;
    }
    // The staged kernels read only the slip directions and u(t): those fields are written here.
    gen::KernelInput& k = ks.staged;
    set_plate_accelerations(ps, k);
    double ux[3], uy[3];
    double dq[18];   // d q''_r / d u_j, row-major (3 x 6)
    slip_directions(3, qd, ws, ux, uy);
    k.u1x = ux[0];
    k.u1y = uy[0];
    k.u2x = ux[1];
    k.u2y = uy[1];
    k.u3x = ux[2];
    k.u3y = uy[2];
    bool regular = true;
    if (ks.thin) {
        if (Jq)
            gen::reduced_U_thin_du(k, ks.C.data(), ws.n.data(), ws.qdd.data(), dq);
        else
            gen::reduced_U_thin(k, ks.C.data(), ws.n.data(), ws.qdd.data());
    } else {
        double det;
        if (Jq)
            gen::reduced_U_thick_du(k, ks.C.data(), ws.n.data(), ws.qdd.data(), &det, dq);
        else
            gen::reduced_U_thick(k, ks.C.data(), ws.n.data(), ws.qdd.data(), &det);
        regular = std::abs(det) > ks.det_floor;
    }
    if (Jq && regular) {
        const Eigen::Map<const Eigen::Matrix<double, 3, 6, Eigen::RowMajor>> dqdd_du(dq);
        Jq->setZero();
        for (int i = 0; i < 3; ++i) {
            if (ws.law == FrictionLaw::Coulomb) {
                // d u/d v = e_perp e_perp^T / |v| (e_perp = (-u_y, u_x)): each contact adds the rank-1
                // (d q''/d u_i e_perp) (V_i^T e_perp)^T / |v_i|, V_i^T e_perp = (-u_y, u_x, r . u).
                const double s = ws.slip[i].norm();
                if (s == 0) continue;   // at zero slip the Coulomb term has no derivative
                const Vec3 a = dqdd_du.col(2 * i + 1) * ux[i] - dqdd_du.col(2 * i) * uy[i];
                const Vec3 b(-uy[i], ux[i], ws.r[i].x() * ux[i] + ws.r[i].y() * uy[i]);
                *Jq += a * (b / s).transpose();
                continue;
            }
            Eigen::Matrix<double, 2, 3> V;
            V << 1, 0, -ws.r[i].y(), 0, 1, ws.r[i].x();
            *Jq += dqdd_du.middleCols<2>(2 * i) * (direction_derivative(ws.law, ws.law_eps, ws.slip[i]) * V);
        }
    }
    return regular;
}

}   // namespace

namespace detail {
// The engine's most frequent evaluation (models.hpp): a slide without creep in the reduced
// U-dynamics, straight to the staged kernels -- what mode_accelerations and accelerations do for it,
// without their dispatch. False where that path declines (an unprepared workspace, a near-singular
// thick part): the caller then takes mode_accelerations. (docs/decisions.md, Per-evaluation cuts in
// the right-hand side)
bool reduced_U_slide(const Scene& sc, const Vec3& q, const Vec3& qd, const PlateState& ps, Workspace& ws) {
    detail::KernelScratch& ks = detail::kernels(ws);
    if (ks.prepared != &sc) return false;
    // (a point part at the configuration cached -- all period long -- straight to its branch)
    if (sc.part.point && q[0] == ks.C_q[0] && q[1] == ks.C_q[1] && q[2] == ks.C_q[2])
        reduced_U_point(qd, ps, ws, nullptr);
    else if (!accelerations_reduced_U(sc.part, q, qd, ps, ws))
        return false;
    ++ws.evals;
    return true;
}
}   // namespace detail

void accelerations(const Scene& sc, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& ps, Workspace& ws) {
    detail::KernelScratch& ks = detail::kernels(ws);
    const Part& P = sc.part;
    ++ws.evals;
    if (ks.prepared != &sc) ws.prepare(sc);
    if (level == Dynamics::ReducedU && accelerations_reduced_U(P, q, qd, ps, ws)) return;
    gen::KernelInput& in = ks.in;
    set_configuration(P, q, ws);
    in.sxd = qd[0];
    in.syd = qd[1];
    in.thd = P.point ? 0.0 : qd[2];
    {
        double ux[3], uy[3];
        slip_directions(P.point ? 1 : 3, qd, ws, ux, uy);
        in.u1x = ux[0];
        in.u1y = uy[0];
        if (!P.point) {
            in.u2x = ux[1];
            in.u2y = uy[1];
            in.u3x = ux[2];
            in.u3y = uy[2];
        }
    }
    set_plate_accelerations(ps, in);
    double b[6];
    if (ks.thin && level != Dynamics::Full) {   // the thin part's specialised kernel does it all
        double n[3], qdd[3];
        gen::thin_solve_U(in, ks.M38_inv_rowmajor.data(), b, n, qdd);
        ws.b = Eigen::Map<const Vec6>(b);
        ws.n = Vec3(n[0], n[1], n[2]);
        ws.qdd = Vec3(qdd[0], qdd[1], qdd[2]);
        return;
    }
    if (level == Dynamics::Full) {
        in.wx = ps.w1.x();
        in.wy = ps.w1.y();
        in.wz = ps.w1.z();
        in.R11 = ps.R1(0, 0);
        in.R12 = ps.R1(0, 1);
        in.R13 = ps.R1(0, 2);
        in.R21 = ps.R1(1, 0);
        in.R22 = ps.R1(1, 1);
        in.R23 = ps.R1(1, 2);
        in.R31 = ps.R1(2, 0);
        in.R32 = ps.R1(2, 1);
        in.R33 = ps.R1(2, 2);
        gen::b_full(in, b);
    } else {
        gen::b_U(in, b);
    }
    ws.b = Eigen::Map<const Vec6>(b);
    if (P.point) {
        double z[3];
        gen::point_solve(in, b, z);
        ws.qdd = Vec3(z[0], z[1], 0);
        ws.n = Vec3(z[2], 0, 0);
        return;
    }
    double n[3], qdd[3];
    if (ks.thin) {
        gen::thin_solve(in, b, ks.M38_inv_rowmajor.data(), n, qdd);   // (38)
    } else {
        double det;
        gen::thick_solve(in, b, n, qdd, &det);
        if (!(std::abs(det) > ks.det_floor)) {
            // Near-collinear contacts: the cofactor solution loses accuracy; use a pivoted LU instead.
            double M[9], r[3];
            gen::thick_reduced(in, b, M, r);
            const Vec3 nn =
                Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(M).partialPivLu().solve(Eigen::Map<const Vec3>(r));
            for (int i = 0; i < 3; ++i) n[i] = nn[i];
            gen::back_substitution(in, b, n, qdd);
        }
    }
    ws.n = Vec3(n[0], n[1], n[2]);
    ws.qdd = Vec3(qdd[0], qdd[1], qdd[2]);
}

void twist_jacobian(const Scene& sc, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& ps, Workspace& ws,
                    Mat3& Jq) {
    detail::KernelScratch& ks = detail::kernels(ws);
    if (level == Dynamics::Full) throw std::invalid_argument("twist_jacobian: U- and reduced U-dynamics only");
    if (level == Dynamics::ReducedU) {
        ++ws.evals;
        if (ks.prepared != &sc) ws.prepare(sc);
        if (accelerations_reduced_U(sc.part, q, qd, ps, ws, &Jq)) return;
    }
    // At one instant the U- and reduced U-dynamics coincide; the U path leaves every input of the
    // factor kernels (slip directions included) in the kernels' inputs.
    accelerations(sc, Dynamics::U, q, qd, ps, ws);
    const Part& P = sc.part;
    if (P.point) {
        // s'' = -(mu N u(v) + b_xy)/m with N = b_z independent of the twist.
        Jq.setZero();
        Jq.topLeftCorner<2, 2>() =
            -P.friction().kinetic(0) * ws.n[0] / P.m * direction_derivative(ws.law, ws.law_eps, ws.slip[0]);
        return;
    }
    double A[36], D[36], V[18];
    const double n[3] = {ws.n[0], ws.n[1], ws.n[2]};
    gen::thick_A(ks.in, A);
    gen::dA_du(ks.in, n, D);
    gen::dslip_dqd(ks.in, V);
    Mat6 U = Mat6::Zero();
    for (int i = 0; i < 3; ++i) U.block<2, 2>(2 * i, 2 * i) = direction_derivative(ws.law, ws.law_eps, ws.slip[i]);
    const Eigen::Matrix<double, 6, 3> G = Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(D) * U *
                                          Eigen::Map<const Eigen::Matrix<double, 6, 3, Eigen::RowMajor>>(V);
    const Eigen::Matrix<double, 6, 3> dz =
        -Eigen::Map<const Eigen::Matrix<double, 6, 6, Eigen::RowMajor>>(A).partialPivLu().solve(G);
    Jq = dz.topRows<3>();
}

void accelerations_reference(const Scene& sc, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& ps,
                             Workspace& ws) {
    detail::KernelScratch& ks = detail::kernels(ws);
    const Part& P = sc.part;
    ++ws.evals;
    slip_velocities(P, q, qd, ws.slip);
    ws.b = rhs_b(sc, level, q, qd, ps);

    if (P.point) {
        // One contact at s: -m s'' + d N = f, d = e_z - mu v/|v| (17). Row z gives N.
        const double N = ws.b[2];
        const double v = ws.slip[0].norm();
        const Vec2 dir = v > 0 ? Vec2(ws.slip[0] / v) : Vec2::Zero();
        const Vec2 sdd = (-P.friction().kinetic(0) * N * dir - ws.b.head<2>()) / P.m;
        ws.qdd = Vec3(sdd.x(), sdd.y(), 0);
        ws.n = Vec3(N, 0, 0);
        return;
    }

    // A of (31): [-M' D; -J' H], M' = m(e_x e_x^T + e_y e_y^T), J' = J e_z e_z^T.
    const double c = std::cos(q[2]), s = std::sin(q[2]);
    Mat6& A = ws.A;
    A.setZero();
    A(0, 0) = -P.m;
    A(1, 1) = -P.m;
    A.block<3, 1>(3, 2) = -P.J.col(2);
    const ContactFriction fr = P.friction();
    for (int i = 0; i < 3; ++i) {
        const double v = ws.slip[i].norm();
        const Vec2 u = v > 0 ? Vec2(ws.slip[i] / v) : Vec2::Zero();
        const Vec3 d(-fr.kinetic(i) * u.x(), -fr.kinetic(i) * u.y(), 1.0);     // (17)
        const Vec3 dS(c * d.x() + s * d.y(), -s * d.x() + c * d.y(), d.z());   // R2^T d_i
        A.block<3, 1>(0, 3 + i) = d;
        A.block<3, 1>(3, 3 + i) = P.c[i].cross(dS);   // h_i (23)
    }
    ks.lu.compute(A);
    ks.z = ks.lu.solve(ws.b);
    ws.qdd = ks.z.head<3>();
    ws.n = ks.z.tail<3>();
}

}   // namespace plate
