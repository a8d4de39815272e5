#include "plate/modes.hpp"

#include "workspace.hpp"

#include <cmath>
#include <limits>

namespace plate {
namespace {

inline Vec2 perp(const Vec2& v) { return Vec2(-v.y(), v.x()); }   // e_z x v
inline Vec2 horizontal_offset(const Part& P, double theta, int i) {
    const double c = std::cos(theta), s = std::sin(theta);
    return Vec2(c * P.c[i].x() - s * P.c[i].y(), s * P.c[i].x() + c * P.c[i].y());   // r_i = R2 c_i
}
// r_i from the workspace's cache where it holds theta (detail::cos_sin), else computed.
inline Vec2 horizontal_offset(const Part& P, const Workspace& ws, double theta, int i) {
    return theta == detail::kernels(ws).theta ? ws.r[i] : horizontal_offset(P, theta, i);
}
// The contacts' slips, r_i from the cache where it holds theta.
inline void slip_velocities_cached(const Part& P, const Workspace& ws, const Vec3& q, const Vec3& qd, std::array<Vec2, 3>& v) {
    if (!P.point && q[2] == detail::kernels(ws).theta)
        slip_velocities_at(P, ws.r, qd, v);
    else
        slip_velocities(P, q, qd, v);
}
inline Vec6 rhs_b_cached(const Scene& sc, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& ps,
                         const Workspace& ws) {
    double c, s;
    detail::cos_sin(ws, q[2], c, s);
    return detail::rhs_b(sc, level, q, qd, ps, c, s);
}
inline double kappa(Dynamics level) { return level == Dynamics::ReducedU ? 0.0 : 1.0; }

// The generated kernels' inputs for the current configuration and twist (ws prepared).
gen::KernelInput mode_input(const Vec3& q, const Vec3& qd, const Workspace& ws) {
    const detail::KernelScratch& ks = detail::kernels(ws);
    gen::KernelInput in = ks.in;
    if (q[2] != ks.theta) {   // (else in holds them: the workspace's cache of theta's cos and sin)
        in.ct = std::cos(q[2]);
        in.st = std::sin(q[2]);
    }
    in.sx = q[0];
    in.sy = q[1];
    in.sxd = qd[0];
    in.syd = qd[1];
    in.thd = qd[2];
    return in;
}

// Newton-Euler with contact k held (unknown f_k) and the others sliding along u_i: the derived
// system pivotK_system (symbolic/derivation_parts.cpp, pivot_modes), unknowns [s_x'', s_y'', theta'', N1, N2, N3, f_kx, f_ky].
void pivot_solve(const Scene& sc, Dynamics level, int k, const Vec3& q, const Vec3& qd, const PlateState& ps,
                 const std::array<Vec2, 3>& u, Workspace& ws) {
    detail::KernelScratch& ks = detail::kernels(ws);
    const Part& P = sc.part;
    const Vec6 b = rhs_b_cached(sc, level, q, qd, ps, ws);
    gen::KernelInput in = mode_input(q, qd, ws);
    in.u1x = u[0].x();
    in.u1y = u[0].y();
    in.u2x = u[1].x();
    in.u2y = u[1].y();
    in.u3x = u[2].x();
    in.u3y = u[2].y();
    Eigen::Matrix<double, 8, 8, Eigen::RowMajor> M;
    double c[2] = {0, 0};
    using System = void (*)(const gen::KernelInput&, double*, double*);
    static constexpr System system[3] = {gen::pivot1_system, gen::pivot2_system, gen::pivot3_system};
    // The matrix depends on theta, k and u only (the generated code reads no twist there): factorised
    // once per pivot of the reduced U-dynamics, and reused while they stay equal, which gives the same
    // factors bit for bit. c (theta'^2 r_k) only where kappa is not 0. (docs/decisions.md,
    // Per-evaluation cuts in the right-hand side)
    const bool same = ks.pivot_k == k && ks.pivot_ct == in.ct && ks.pivot_st == in.st && ks.pivot_u == u;
    if (!same || kappa(level) != 0) system[k](in, M.data(), c);
    if (!same) {
        ks.pivot_lu.compute(M);
        ks.pivot_k = k;
        ks.pivot_ct = in.ct;
        ks.pivot_st = in.st;
        ks.pivot_u = u;
    }
    Eigen::Matrix<double, 8, 1> rhs;
    rhs.head<6>() = b;
    rhs[6] = kappa(level) * c[0];   // theta'^2 r_k; the reduced U-dynamics' frozen configuration has none
    rhs[7] = kappa(level) * c[1];
    const Eigen::Matrix<double, 8, 1> z = ks.pivot_lu.solve(rhs);
    ws.b = b;
    ws.qdd = z.head<3>();
    ws.n = z.segment<3>(3);
    const ContactFriction fr = P.friction();
    for (int i = 0; i < 3; ++i) ws.f_held[i] = i == k ? Vec2(z[6], z[7]) : Vec2(-fr.kinetic(i) * ws.n[i] * u[i]);
}

// q'' = 0: the needed friction total and moment, and the normal forces (generated stuck_solve).
void stuck_solve(const Scene& sc, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& ps, Workspace& ws) {
    const Part& P = sc.part;
    const Vec6 b = rhs_b_cached(sc, level, q, qd, ps, ws);
    ws.b = b;
    ws.qdd.setZero();
    if (P.point) {   // one contact: N = b_z, F = b_xy (point_solve with s'' = 0)
        ws.F_needed = b.head<2>();
        ws.tau_needed = 0;
        ws.n = Vec3(b[2], 0, 0);
        return;
    }
    double n[3], w[3];
    gen::stuck_solve(mode_input(q, qd, ws), b.data(), n, w);
    ws.n = Vec3(n[0], n[1], n[2]);
    ws.F_needed = Vec2(w[0], w[1]);
    ws.tau_needed = w[2];
}

}   // namespace

std::string mode_name(const Mode& m) {
    switch (m.kind) {
        case ModeKind::Slide:
            return "slide";
        case ModeKind::Pivot:
            return "pivot" + std::to_string(m.k + 1);
        case ModeKind::Stuck:
            return "stuck";
    }
    return "?";
}

namespace {
// A rigid part's contact at r = R2 c_i: s'' + theta'' e_z x r - kappa theta'^2 r.
Vec2 contact_acceleration_at(const Vec2& r, Dynamics level, const Vec3& qd, const Vec3& qdd) {
    return qdd.head<2>() + qdd[2] * perp(r) - kappa(level) * qd[2] * qd[2] * r;
}
}   // namespace

Vec2 contact_acceleration(const Part& P, Dynamics level, int i, const Vec3& q, const Vec3& qd, const Vec3& qdd) {
    if (P.point) return qdd.head<2>();
    return contact_acceleration_at(horizontal_offset(P, q[2], i), level, qd, qdd);
}

namespace {

// The unit slip directions of the twist xi (scaled: s_x', s_y', rho theta') as the contacts' hints.
void set_twist_hints(const Part& P, double theta, const Vec3& xi, Workspace& ws) {
    detail::StickSlipState& ss = detail::stick_slip(ws);
    const double rho = P.rho();
    for (int i = 0; i < P.contacts(); ++i) {
        const Vec2 r = horizontal_offset(P, ws, theta, i);
        const Vec2 v(xi[0] - xi[2] / rho * r.y(), xi[1] + xi[2] / rho * r.x());
        ss.hint[i] = v.norm() > 0 ? Vec2(v / v.norm()) : Vec2::Zero();
    }
}
Vec3 scaled_qdd(const Part& P, const Workspace& ws) { return Vec3(ws.qdd[0], ws.qdd[1], P.rho() * ws.qdd[2]); }
void tangent_basis(const Vec3& xi, Vec3& e1, Vec3& e2) {
    e1 = std::abs(xi[0]) < 0.9 ? Vec3::UnitX().cross(xi).normalized() : Vec3::UnitY().cross(xi).normalized();
    e2 = xi.cross(e1);
}

// Every contact creeping: the unknown is the direction xi of the twist, the contacts' directions are its
// slips', and it is consistent when q'' (scaled) is parallel to xi, less the turn the engine measured
// (StickSlipState::creep_twist_rate; Newton on two angles about xi,
// forward-difference Jacobian). Three independent angles would also admit directions no rigid motion
// has (a contact decelerating while the twist grows).
void twist_creep_accelerations(const Scene& sc, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& ps,
                               Workspace& ws) {
    detail::StickSlipState& ss = detail::stick_slip(ws);
    const Part& P = sc.part;
    Vec3& xi = ss.creep_twist;
    const Vec3 qs(qd[0], qd[1], P.rho() * qd[2]);
    if (xi.isZero()) xi = qs.norm() > 0 ? Vec3(qs.normalized()) : Vec3::UnitX();
    Vec3 e1, e2;
    tangent_basis(xi, e1, e2);
    auto at = [&](double a, double b) { return Vec3((xi + a * e1 + b * e2).normalized()); };
    auto residual = [&](const Vec3& x) {
        set_twist_hints(P, q[2], x, ws);
        accelerations(sc, level, q, qd, ps, ws);
        const Vec3 Q = scaled_qdd(P, ws);
        // zero iff q'' less |q'| times the measured turn of the direction is parallel to x (as a point
        // part's contact, u x a = |v| rate: with no turn a slide at the rim of the disk, under a
        // turning drive, is held at the zero threshold; docs/decisions.md, Creeps carry the slip's turn)
        const Vec3 D = Q - qs.norm() * ss.creep_twist_rate.cross(x);
        const Vec3 r = D - x.dot(D) * x;
        return Eigen::Vector2d(r.dot(e1), r.dot(e2));
    };
    double a = 0, b = 0;
    Eigen::Vector2d c = residual(xi);
    constexpr double d = 1e-7;
    for (int it = 0; it < 8; ++it) {
        Eigen::Matrix2d J;
        J.col(0) = (residual(at(a + d, b)) - c) / d;
        J.col(1) = (residual(at(a, b + d)) - c) / d;
        Eigen::Vector2d step = -J.partialPivLu().solve(c);
        if (!step.allFinite()) step.setZero();
        step = step.cwiseMax(-0.3).cwiseMin(0.3);
        a += step[0];
        b += step[1];
        c = residual(at(a, b));
        ++ws.creep_iterations;
        if (step.cwiseAbs().maxCoeff() < 1e-11) break;
    }
    xi = at(a, b);
}

// creep_accelerations for a point part in the reduced U-dynamics, its one contact creeping, the
// hints in use, after its first evaluation (ws holds it): the same Newton on the angle, with the same
// operations in the same order, so the same bits. What an evaluation changes there is only the
// direction: the configuration's slots are cached, u(t) and the slip are the first evaluation's (in
// the staged inputs and ws.slip), and a creeping contact takes its hint as the direction -- so each
// evaluation is the generated kernel on the new direction alone, without the slip's square root and
// division whose result the hint replaces, and the slip's speed in the residual is taken once.
// (docs/decisions/web.md, A point part's creep and slide without the general path)
void point_creep(Workspace& ws) {
    detail::KernelScratch& ks = detail::kernels(ws);
    detail::StickSlipState& ss = detail::stick_slip(ws);
    gen::KernelInput& k = ks.staged;
    Vec2& u = ss.hint[0];
    const double speed_turn = ws.slip[0].norm() * ss.creep_rate[0];
    auto evaluate = [&] {   // (accelerations_reduced_U's point branch on the direction u)
        ++ws.evals;
        k.u1x = u.x();
        k.u1y = u.y();
        double z[3];
        gen::reduced_U_point(k, ks.C.data(), z);
        ws.qdd = Vec3(z[0], z[1], 0);
        ws.n = Vec3(z[2], 0, 0);
    };
    auto residual = [&] { return ws.qdd[0] * u.y() - ws.qdd[1] * u.x() + speed_turn; };
    double phi = std::atan2(u.y(), u.x());
    double c = residual();
    constexpr double dphi = 1e-7;
    for (int it = 0; it < 8; ++it) {
        const double p = phi + dphi;
        u = Vec2(std::cos(p), std::sin(p));
        evaluate();
        const double J = (residual() - c) / dphi;
        double step = -c / J;
        if (!std::isfinite(step)) step = 0;
        step = std::min(std::max(step, -0.5), 0.5);
        phi += step;
        u = Vec2(std::cos(phi), std::sin(phi));
        evaluate();
        ++ws.creep_iterations;
        c = residual();
        if (std::abs(step) < 1e-11) break;
    }
}

// Slide with creeping contacts (StickSlipState::creep): the direction u_j = (cos phi_j, sin phi_j) of each
// creeping contact j is the one along which it then accelerates, c_j = a_j x u_j = 0 (the consistent
// slip direction at the rim of the friction disk; at a located break-away a_j = 0 and c_j vanishes to
// first order at the rim's direction). Newton's method on the angles, from the last solution
// (StickSlipState::hint), with a forward-difference Jacobian; leaves ws evaluated at the solution.
void creep_accelerations(const Scene& sc, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& ps, Workspace& ws) {
    detail::KernelScratch& ks = detail::kernels(ws);
    detail::StickSlipState& ss = detail::stick_slip(ws);
    const Part& P = sc.part;
    if (!P.point && (ss.creep & 7u) == 7u) {
        ws.creep_iterations = 0;
        twist_creep_accelerations(sc, level, q, qd, ps, ws);
        return;
    }
    int idx[3], m = 0;
    for (int i = 0; i < P.contacts(); ++i)
        if ((ss.creep >> i & 1u) && ss.hint[i].norm() > 0) idx[m++] = i;
    ws.creep_iterations = 0;
    accelerations(sc, level, q, qd, ps, ws);
    if (m == 0) return;
    if (P.point && level == Dynamics::ReducedU && ss.use_hints) {
        point_creep(ws);
        return;
    }
    // (a_j x u_j + |v_j| rate_j: the slip turns with its direction at the rate the engine measured,
    // d(v/|v|)/dt = (u x a) / |v|; with rate 0 the slip could not turn with a turning drive, and a
    // slide at the rim of the disk would stay at the zero threshold, far below the exact speed.)
    // (r_i from the workspace's cache when it holds this theta: no cosine and sine per contact and
    // evaluation)
    const bool cached = !P.point && q[2] == ks.theta;
    auto residual = [&](Eigen::Vector3d& c) {
        for (int j = 0; j < m; ++j) {
            const Vec2 a = cached ? contact_acceleration_at(ws.r[idx[j]], level, qd, ws.qdd)
                                  : contact_acceleration(P, level, idx[j], q, qd, ws.qdd);
            const Vec2& u = ss.hint[idx[j]];
            c[j] = a.x() * u.y() - a.y() * u.x() + ws.slip[idx[j]].norm() * ss.creep_rate[idx[j]];
        }
    };
    auto set_angles = [&](const Eigen::Vector3d& phi) {
        for (int j = 0; j < m; ++j) ss.hint[idx[j]] = Vec2(std::cos(phi[j]), std::sin(phi[j]));
    };
    Eigen::Vector3d phi, c, cj;
    for (int j = 0; j < m; ++j) phi[j] = std::atan2(ss.hint[idx[j]].y(), ss.hint[idx[j]].x());
    residual(c);
    constexpr double dphi = 1e-7;
    for (int it = 0; it < 8; ++it) {
        Eigen::Matrix3d J = Eigen::Matrix3d::Identity();
        for (int l = 0; l < m; ++l) {
            Eigen::Vector3d p = phi;
            p[l] += dphi;
            set_angles(p);
            accelerations(sc, level, q, qd, ps, ws);
            residual(cj);
            for (int j = 0; j < m; ++j) J(j, l) = (cj[j] - c[j]) / dphi;
        }
        Eigen::Vector3d step = Eigen::Vector3d::Zero();
        if (m == 1)
            step[0] = -c[0] / J(0, 0);   // (one creeping contact, the usual case: no LU)
        else
            step.head(m) = -J.topLeftCorner(m, m).partialPivLu().solve(c.head(m));
        if (!step.allFinite()) step.setZero();      // a singular Jacobian: keep the last directions
        step = step.cwiseMax(-0.5).cwiseMin(0.5);   // (a Newton step of at most ~30 degrees)
        phi += step;
        set_angles(phi);
        accelerations(sc, level, q, qd, ps, ws);
        ++ws.creep_iterations;
        residual(c);
        if (step.cwiseAbs().maxCoeff() < 1e-11) break;
    }
}

// A rigid part that breaks away off the stick boundary (choose_mode): the twist that starts, the
// direction xi (scaled) along which q'' points when the slips are xi's -- found by relaxing xi along
// q''(xi) (the direction a part released at rest takes, q' ~ t q''; the fixed-point iteration
// xi <- q''(xi) flips back and forth near the stick boundary), from the twist the needed friction
// opposes, reversed (the creep twist choose_mode set). Leaves the hints and the creep twist at xi.
void release_twist(const Scene& sc, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& ps, Workspace& ws) {
    const Part& P = sc.part;
    detail::StickSlipState& ss = detail::stick_slip(ws);
    Vec3 xi = ss.creep_twist.isZero() ? Vec3(Vec3::UnitX()) : ss.creep_twist;
    // (The relaxation step shrinks where the residual grows: near a contact whose slip
    // nearly vanishes -- a slide close to a pivot -- the flow is stiff.)
    auto misfit = [&](const Vec3& x, Vec3& Q) {
        set_twist_hints(P, q[2], x, ws);
        mode_accelerations(sc, level, q, qd, ps, Mode{}, ws);
        Q = scaled_qdd(P, ws);
        const double lam = x.dot(Q);
        return Q.norm() > 0 ? ((Q - lam * x).norm() + std::max(-lam, 0.0)) / Q.norm() : 0.0;
    };
    Vec3 Q;
    double r = misfit(xi, Q), tau = 0.2;
    for (int it = 0; it < 2000 && r > 1e-10 && tau > 1e-14; ++it) {
        const Vec3 next = (xi + tau * Q.normalized()).normalized();
        Vec3 Qn;
        const double rn = misfit(next, Qn);
        if (rn <= r) {
            xi = next;
            Q = Qn;
            r = rn;
            tau = std::min(0.5, 1.5 * tau);
        } else {
            tau *= 0.3;
        }
    }
    set_twist_hints(P, q[2], xi, ws);
    ss.creep_twist = xi;
}

}   // namespace

void mode_accelerations(const Scene& sc, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& ps, const Mode& mode,
                        Workspace& ws) {
    detail::KernelScratch& ks = detail::kernels(ws);
    detail::StickSlipState& ss = detail::stick_slip(ws);
    const Part& P = sc.part;
    if (ks.prepared != &sc) ws.prepare(sc);
    switch (mode.kind) {
        case ModeKind::Slide:
            if (ss.creep)
                creep_accelerations(sc, level, q, qd, ps, ws);
            else
                accelerations(sc, level, q, qd, ps, ws);
            return;
        case ModeKind::Stuck:
            ++ws.evals;
            slip_velocities_cached(P, ws, q, qd, ws.slip);
            stuck_solve(sc, level, q, qd, ps, ws);
            return;
        case ModeKind::Pivot: {
            ++ws.evals;
            slip_velocities_cached(P, ws, q, qd, ws.slip);
            // The sliding contacts move on circles about c_k: v_j = theta' e_z x (r_j - r_k), whose
            // direction is the mode's sense times e_z x (r_j - r_k) (exact even at theta' = 0).
            std::array<Vec2, 3> u = zeros<Vec2>();
            const Vec2 rk = horizontal_offset(P, ws, q[2], mode.k);
            for (int j = 0; j < 3; ++j)
                if (j != mode.k) u[j] = mode.sense * perp(horizontal_offset(P, ws, q[2], j) - rk).normalized();
            pivot_solve(sc, level, mode.k, q, qd, ps, u, ws);
            return;
        }
    }
}

namespace {

// Is the pivot ws has just evaluated consistent: its contact k's static friction fits its disk while the
// others slide at their kinetic coefficients, every N_i >= 0, and theta'' has the pivot's sense?
bool pivot_consistent(const Part& P, const Mode& pivot, const Workspace& ws) {
    const int k = pivot.k;
    return ws.n.minCoeff() >= 0 && ws.f_held[k].norm() <= P.friction().static_(k) * ws.n[k] && pivot.sense * ws.qdd[2] > 0;
}

// Does the pivot hold from the stuck state's boundary (pivot_consistent)? ws holds the stuck state's
// evaluation again afterwards where it does not.
bool pivot_holds(const Scene& sc, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& ps, const Mode& pivot,
                 Workspace& ws) {
    mode_accelerations(sc, level, q, qd, ps, pivot, ws);
    if (pivot_consistent(sc.part, pivot, ws)) return true;
    mode_accelerations(sc, level, q, qd, ps, Mode{ModeKind::Stuck}, ws);
    return false;
}

// A stick exit (the gauge g at 1, its optimum on no kink) of a part whose static friction exceeds its
// kinetic friction somewhere. At the boundary every contact is at the rim of its static disk and the
// boundary twist -d would slip each at its own rate; the contacts that slip drop to their kinetic disks,
// and the motion that follows can be a pivot. Offered: the pivot about the contact strictly the slowest
// under -d (none on a tie), turning as -d does, taken where it holds (pivot_holds). A rule checked against
// a smooth Stribeck law's limit on fig4's part, not derived: the Coulomb model with mu_s > mu_k can have
// several consistent motions here (docs/decisions/engine.md, "A stick exit with static above kinetic
// friction", and the cases it leaves untested). Returns a slide where no pivot is taken.
ModeChoice exit_pivot(const Scene& sc, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& ps,
                      const FrictionGauge& g, Workspace& ws) {
    const Part& P = sc.part;
    std::array<Vec2, 3> v;
    slip_velocities(P, q, Vec3(-g.direction), v);
    int k = 0;
    for (int i = 1; i < 3; ++i)
        if (v[i].norm() < v[k].norm()) k = i;
    ModeChoice out;
    for (int j = 0; j < 3; ++j)
        if (j != k && v[k].norm() >= (1 - 1e-6) * v[j].norm()) return out;   // no contact strictly the slowest
    const Mode pivot{ModeKind::Pivot, k, g.direction[2] > 0 ? -1.0 : 1.0};
    if (pivot_holds(sc, level, q, qd, ps, pivot, ws)) {
        out.mode = pivot;
        out.gamma = g.gamma;
    }
    return out;
}

}   // namespace

ModeChoice choose_mode(const Scene& sc, Dynamics level, const Vec3& q, Vec3& qd, const PlateState& ps, unsigned zero,
                       Workspace& ws, bool hold) {
    detail::StickSlipState& ss = detail::stick_slip(ws);
    const Part& P = sc.part;
    const int nc = P.contacts();
    ss.creep = 0;   // every slide below has its directions set here
    ss.creep_rate = {};
    ss.creep_twist.setZero();
    ss.creep_twist_rate.setZero();
    ModeChoice out;
    int count = 0, k = -1;
    for (int i = 0; i < nc; ++i)
        if (zero & (1u << i)) {
            ++count;
            k = i;
        }
    auto normal_ok = [&]() {
        int arg = 0;
        if (ws.n.head(nc).minCoeff(&arg) < 0) {
            out.lost = true;
            out.lost_contact = arg;
            return false;
        }
        return true;
    };
    // Slip directions that a break-away starts with, made consistent with the sliding dynamics:
    // contact i's relative acceleration along its own slip direction (u_i <- a_i/|a_i|). Needed only
    // when the state is off the stick boundary (a start at rest where friction cannot hold, a slip
    // reversal); at a located event the rim's friction direction is already consistent.
    auto refine_hints = [&](unsigned which) {
        Mode slide;
        for (int it = 0; it < 40; ++it) {
            mode_accelerations(sc, level, q, qd, ps, slide, ws);
            double change = 0;
            for (int i = 0; i < nc; ++i) {
                if (!(which & (1u << i))) continue;
                const Vec2 a = contact_acceleration(P, level, i, q, qd, ws.qdd);
                if (!(a.norm() > 0)) continue;
                const Vec2 u = a / a.norm();
                change = std::max(change, (u - ss.hint[i]).norm());
                ss.hint[i] = u;
            }
            if (change < 1e-12) break;
        }
    };
    ss.use_hints = true;
    if (count == 1 && !P.point) {
        // One contact at zero slip: project onto v_k = 0 (s' -= v_k), then can contact k pivot?
        std::array<Vec2, 3> v;
        slip_velocities(P, q, qd, v);
        qd.head<2>() -= v[k];
        if (qd[2] == 0)
            count = 3;   // the others are then at rest too
        else {
            Mode pivot{ModeKind::Pivot, k, qd[2] > 0 ? 1.0 : -1.0};
            mode_accelerations(sc, level, q, qd, ps, pivot, ws);
            const double cap = P.friction().disk(k, ws.n[k]), need = ws.f_held[k].norm();
            out.gamma = cap > 0 ? need / cap : std::numeric_limits<double>::infinity();
            if (need <= cap * (1 + 1e-12)) {
                // Held; a negative normal force elsewhere then means the part would tip.
                if (!normal_ok()) return out;
                out.mode = pivot;
                return out;
            }
            // A slip reversal: contact k slides on, opposite the friction it would have needed.
            ss.hint[k] = -ws.f_held[k] / need;
            refine_hints(1u << k);
            out.mode = Mode{};
            return out;
        }
    }
    // Every slip zero: held if the friction disks can supply the needed wrench.
    qd.setZero();
    // The normal forces of the stuck state assume the needed friction total; where that friction
    // cannot be had (gauge > 1) the part slides and its own normal forces decide contact.
    mode_accelerations(sc, level, q, qd, ps, Mode{ModeKind::Stuck}, ws);
    const FrictionGauge g = friction_gauge(P, q[2], ws.n, ws.F_needed, ws.tau_needed);
    out.gamma = g.gamma;
    if (hold && g.gamma <= 1 + 1e-12) {
        if (!normal_ok()) return out;   // held, but the part would tip
        out.mode = Mode{ModeKind::Stuck};
        return out;
    }
    if (!hold && !P.point && !P.friction().single() && g.pivot < 0 && g.gamma <= 1 + 1e-6) {
        const ModeChoice held = exit_pivot(sc, level, q, qd, ps, g, ws);
        if (held.mode.kind == ModeKind::Pivot) return held;
    }
    // Off the stick boundary (a start at rest where friction cannot hold, the twist passing through
    // zero): the motion that starts is the consistent one -- a pivot about contact k turning with
    // sense s whose static friction fits its disk and whose theta'' has sign s, or a slide whose every
    // contact accelerates along its own slip direction. (At a located stick exit, gauge = 1 to
    // rounding, the boundary point below is that motion.)
    if (g.gamma > 1 + 1e-6 && !P.point) {
        for (int kk = 0; kk < 3; ++kk)
            for (double sense : {1.0, -1.0}) {
                const Mode pv{ModeKind::Pivot, kk, sense};
                mode_accelerations(sc, level, q, qd, ps, pv, ws);
                if (pivot_consistent(P, pv, ws)) {
                    out.mode = pv;
                    return out;
                }
            }
    }
    // Break-away: the emerging twist is opposite the direction the needed friction opposes.
    if (g.pivot >= 0 && g.gamma <= 1 + 1e-6) {
        out.mode = Mode{ModeKind::Pivot, g.pivot, g.direction[2] > 0 ? -1.0 : 1.0};
        return out;
    }
    unsigned all = 0;
    for (int i = 0; i < nc; ++i) {
        const double fn = g.f[i].norm();
        ss.hint[i] = fn > 0 ? Vec2(-g.f[i] / fn) : Vec2::Zero();
        all |= 1u << i;
    }
    if (!P.point) {
        // At a located stick exit (gauge 1) the twist that starts is opposite the one the rim's
        // friction opposes; the creep's Newton refines it from there (engine.hpp).
        const Vec3 d(g.direction[0], g.direction[1], P.rho() * g.direction[2]);
        ss.creep_twist = d.norm() > 0 ? Vec3(-d.normalized()) : Vec3::Zero();
    }
    if (g.gamma > 1 + 1e-6) {
        if (P.point)
            refine_hints(all);
        else
            release_twist(sc, level, q, qd, ps, ws);
    }
    out.mode = Mode{};
    return out;
}

StickTest stick_test(const Scene& sc, Dynamics level, int k, const Vec3& q, const Vec3& qd, const PlateState& ps) {
    const Part& P = sc.part;
    Workspace ws;
    StickTest r;
    if (P.point) {   // s'' = 0: friction must supply f_xy, and N = f_z
        mode_accelerations(sc, level, q, qd, ps, Mode{ModeKind::Stuck}, ws);
        r.friction_needed = ws.F_needed.norm();
        r.friction_available = P.friction().static_(0) * ws.n[0];
        r.sticks = ws.n[0] > 0 && r.friction_needed <= r.friction_available;
        return r;
    }
    // The others turn about c_k with theta' (sense 0 at rest: no kinetic friction there).
    const double sense = qd[2] > 0 ? 1.0 : qd[2] < 0 ? -1.0 : 0.0;
    mode_accelerations(sc, level, q, qd, ps, Mode{ModeKind::Pivot, k, sense}, ws);
    r.friction_needed = ws.f_held[k].norm();
    r.friction_available = P.friction().static_(k) * ws.n[k];
    r.sticks = ws.n.minCoeff() >= 0 && r.friction_needed <= r.friction_available;
    return r;
}

StickTest stick_test_all(const Scene& sc, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& ps) {
    // The stuck mode's statics and the exact friction-disk gauge (friction.hpp).
    Workspace ws;
    mode_accelerations(sc, level, q, qd, ps, Mode{ModeKind::Stuck}, ws);
    const int nc = sc.part.contacts();
    StickTest r;
    r.friction_needed = ws.F_needed.norm();
    const ContactFriction fr = sc.part.friction();
    for (int i = 0; i < nc; ++i) r.friction_available += fr.disk(i, ws.n[i]);
    r.sticks = ws.n.head(nc).minCoeff() >= 0 && friction_gauge(sc.part, q[2], ws.n, ws.F_needed, ws.tau_needed).gamma <= 1;
    return r;
}

}   // namespace plate
