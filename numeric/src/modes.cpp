#include "plate/modes.hpp"

#include <cmath>
#include <limits>

namespace plate {
namespace {

inline Vec2 perp(const Vec2& v) { return Vec2(-v.y(), v.x()); }   // e_z x v
inline Vec2 horizontal_offset(const Part& P, double theta, int i) {
    const double c = std::cos(theta), s = std::sin(theta);
    return Vec2(c * P.c[i].x() - s * P.c[i].y(), s * P.c[i].x() + c * P.c[i].y());   // r_i = R2 c_i
}
inline double kappa(Dynamics level) { return level == Dynamics::ReducedU ? 0.0 : 1.0; }

// The generated kernels' inputs for the current configuration and twist (ws prepared).
gen::KernelInput mode_input(const Vec3& q, const Vec3& qd, const Workspace& ws) {
    gen::KernelInput in = ws.in;
    if (q[2] != ws.theta) {   // (else in holds them: the workspace's cache of theta's cos and sin)
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
// system pivotK_system (symbolic/derivation.cpp), unknowns [s_x'', s_y'', theta'', N1, N2, N3, f_kx, f_ky].
void pivot_solve(const Scene& sc, Dynamics level, int k, const Vec3& q, const Vec3& qd, const PlateState& ps,
                 const std::array<Vec2, 3>& u, Workspace& ws) {
    const Part& P = sc.part;
    const Vec6 b = rhs_b(sc, level, q, qd, ps);
    gen::KernelInput in = mode_input(q, qd, ws);
    in.u1x = u[0].x(); in.u1y = u[0].y();
    in.u2x = u[1].x(); in.u2y = u[1].y();
    in.u3x = u[2].x(); in.u3y = u[2].y();
    Eigen::Matrix<double, 8, 8, Eigen::RowMajor> M;
    double c[2] = {0, 0};
    using System = void (*)(const gen::KernelInput&, double*, double*);
    static constexpr System system[3] = {gen::pivot1_system, gen::pivot2_system, gen::pivot3_system};
    // The matrix depends on theta, k and u only (the generated code reads no twist there): factorised
    // once per pivot of the reduced U-dynamics (fig6's field: the 8 x 8 factorisation was 6 % of its
    // instructions). c (theta'^2 r_k) only where kappa is not 0.
    const bool same = ws.pivot_k == k && ws.pivot_ct == in.ct && ws.pivot_st == in.st && ws.pivot_u == u;
    if (!same || kappa(level) != 0) system[k](in, M.data(), c);
    if (!same) {
        ws.pivot_lu.compute(M);
        ws.pivot_k = k;
        ws.pivot_ct = in.ct;
        ws.pivot_st = in.st;
        ws.pivot_u = u;
    }
    Eigen::Matrix<double, 8, 1> rhs;
    rhs.head<6>() = b;
    rhs[6] = kappa(level) * c[0];   // theta'^2 r_k; the reduced U-dynamics' frozen configuration has none
    rhs[7] = kappa(level) * c[1];
    const Eigen::Matrix<double, 8, 1> z = ws.pivot_lu.solve(rhs);
    ws.b = b;
    ws.qdd = z.head<3>();
    ws.n = z.segment<3>(3);
    for (int i = 0; i < 3; ++i) ws.f_held[i] = i == k ? Vec2(z[6], z[7]) : Vec2(-P.mu[i] * ws.n[i] * u[i]);
}

// q'' = 0: the needed friction total and moment, and the normal forces (generated stuck_solve).
void stuck_solve(const Scene& sc, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& ps, Workspace& ws) {
    const Part& P = sc.part;
    const Vec6 b = rhs_b(sc, level, q, qd, ps);
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

}  // namespace

std::string mode_name(const Mode& m) {
    switch (m.kind) {
        case ModeKind::Slide: return "slide";
        case ModeKind::Pivot: return "pivot" + std::to_string(m.k + 1);
        case ModeKind::Stuck: return "stuck";
    }
    return "?";
}

FrictionGauge friction_gauge(const Part& P, double theta, const Vec3& n, const Vec2& F, double tau) {
    FrictionGauge g;
    const double inf = std::numeric_limits<double>::infinity();
    if (P.point) {
        const double cap = P.mu[0] * std::max(n[0], 0.0);
        const double need = F.norm();
        g.gamma = need == 0 ? 0.0 : cap > 0 ? need / cap : inf;
        g.f[0] = F;
        if (need > 0) g.direction = Vec3(F.x() / need, F.y() / need, 0);
        return g;
    }
    // Scaled coordinates of the Appendix: w = (F, tau / rho), R_i = r_i / rho.
    const double rg = P.rho();
    const Vec3 w(F.x(), F.y(), tau / rg);
    const double wn = w.norm();
    if (wn == 0) return g;
    std::array<Vec2, 3> R;
    std::array<double, 3> cap;
    for (int i = 0; i < 3; ++i) {
        R[i] = horizontal_offset(P, theta, i) / rg;
        cap[i] = P.mu[i] * std::max(n[i], 0.0);
    }
    auto Gt = [&](int i, const Vec3& d) { return Vec2(d.x() - R[i].y() * d.z(), d.y() + R[i].x() * d.z()); };
    auto Gf = [&](int i, const Vec2& f) { return Vec3(f.x(), f.y(), R[i].x() * f.y() - R[i].y() * f.x()); };
    auto finish = [&](const Vec3& d, double h) {
        g.gamma = h > 0 ? 1 / h : inf;
        g.direction = Vec3(d.x(), d.y(), d.z() / rg);
        g.direction /= g.direction.norm();
    };
    // Kinks: d a rotation about contact k, scaled onto d . w = 1. Optimal iff some g in the unit disk
    // and c > 0 satisfy sum_{j != k} cap_j G_j u_j + cap_k G_k g = c w (then c = h(d), gamma = 1/c).
    for (int k = 0; k < 3; ++k) {
        const Vec3 e(R[k].y(), -R[k].x(), 1);
        const double s = w.dot(e);
        if (!(std::abs(s) > 1e-14 * wn * e.norm()) || !(cap[k] > 0)) continue;
        const Vec3 d = e / s;
        Vec3 rhs = Vec3::Zero();
        double h = 0;
        std::array<Vec2, 3> u = zeros<Vec2>();
        bool ok = true;
        for (int j = 0; j < 3 && ok; ++j) {
            if (j == k) continue;
            const Vec2 v = Gt(j, d);
            const double nv = v.norm();
            if (!(nv > 0)) { ok = false; break; }
            u[j] = v / nv;
            rhs -= cap[j] * Gf(j, u[j]);
            h += cap[j] * nv;
        }
        if (!ok) continue;
        Mat3 A;
        A.col(0) = cap[k] * Gf(k, Vec2::UnitX());
        A.col(1) = cap[k] * Gf(k, Vec2::UnitY());
        A.col(2) = -w;
        const Eigen::FullPivLU<Mat3> lu(A);
        if (!lu.isInvertible()) continue;
        const Vec3 x = lu.solve(rhs);
        if (!(x[2] > 0) || x.head<2>().norm() > 1 + 1e-12) continue;
        finish(d, h);
        for (int j = 0; j < 3; ++j) g.f[j] = g.gamma * cap[j] * (j == k ? Vec2(x.head<2>()) : u[j]);
        g.pivot = k;
        return g;
    }
    // Smooth optimum: Newton on h(d0 + B y), d0 = w/|w|^2, B an orthonormal basis of w's complement.
    const Vec3 d0 = w / (wn * wn);
    const Vec3 a = w / wn;
    const Vec3 t1 = (std::abs(a.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY()).cross(a).normalized();
    Eigen::Matrix<double, 3, 2> B;
    B.col(0) = t1;
    B.col(1) = a.cross(t1);
    // The support function P(d) = sum_i mu_i N_i |G_i^T d| with its gradient and Hessian: the
    // generated friction_support (a term is left out where its contact is at rest, a kink of P,
    // where its subgradient 0 is a valid choice).
    gen::WrenchInput win = wrench_input({R[0] * rg, R[1] * rg, R[2] * rg}, n.cwiseMax(0.0), P.mu, rg);
    double sp[3], term[3], gr[9], he[18];
    auto support = [&](const Vec3& d) {
        win.vx = d.x();
        win.vy = d.y();
        win.xith = d.z();
        gen::friction_support(win, sp, term, gr, he);
    };
    auto h_at = [&](const Vec3& d) {
        support(d);
        double h = 0;
        for (int i = 0; i < 3; ++i)
            if (sp[i] > 0) h += term[i];
        return h;
    };
    Vec2 y = Vec2::Zero();
    Vec3 d = d0;
    double h = h_at(d);
    double last_gy = 0;
    for (int it = 0; it < 100; ++it) {
        g.iterations = it + 1;
        Vec3 grad = Vec3::Zero();
        Mat3 H = Mat3::Zero();
        support(d);
        for (int i = 0; i < 3; ++i) {
            if (!(sp[i] > 0) || !(cap[i] > 0)) continue;
            grad += Vec3(gr[3 * i], gr[3 * i + 1], gr[3 * i + 2]);
            const double* Hi = he + 6 * i;
            H += (Mat3() << Hi[0], Hi[1], Hi[2], Hi[1], Hi[3], Hi[4], Hi[2], Hi[4], Hi[5]).finished();
        }
        const Vec2 gy = B.transpose() * grad;
        last_gy = gy.norm();
        const Eigen::Matrix2d Hy = B.transpose() * H * B;
        Vec2 step = -Hy.ldlt().solve(gy);
        if (!step.allFinite()) step = -gy;
        double alpha = 1;
        const double slope = gy.dot(step);
        Vec2 y1;
        double h1 = h;
        for (int ls = 0; ls < 60; ++ls, alpha *= 0.5) {
            y1 = y + alpha * step;
            h1 = h_at(d0 + B * y1);
            if (h1 <= h + 1e-4 * alpha * slope) break;
        }
        const double moved = (alpha * step).norm();
        if (h1 <= h) { y = y1; d = d0 + B * y; h = h1; }
        if (moved <= 1e-14 * (1 + y.norm()) || h1 > h) break;
    }
    // Newton's quadratic model fails next to a kink of h (a contact's term |G_i^T d| near zero, its
    // Hessian unbounded): drawn there, the line search stalled with the gradient far from zero and
    // the gauge came out low (fig6 at (0.0167, 0, 2.693), t = 0.01759: 0.967 where the minimum gives
    // 0.992 -- the part was held 0.13 ms too long, its cycle's twist 1.8e-4 v_ref off the regularised
    // reference). Then the kinks and a pattern search in the plane decide (16 directions; h is convex,
    // but next to a kink its descent cone can be narrower than their spacing: repaired below).
    const bool stalled = last_gy > 1e-7 * h * wn;
    if (stalled) {
        // (the minimum may sit at a kink whose test above failed by rounding: h there first)
        for (int k = 0; k < 3; ++k) {
            const Vec3 e(R[k].y(), -R[k].x(), 1);
            const double s = w.dot(e);
            if (!(std::abs(s) > 1e-14 * wn * e.norm())) continue;
            const double hk = h_at(e / s);
            if (hk < h) {
                h = hk;
                y = B.transpose() * (e / s - d0);
            }
        }
        // Pattern search: 16 directions, the step doubled after a success and halved after a failure.
        double step = 1e-2 / wn;
        while (step > 1e-9 / wn) {   // (h then within ~1e-18 of its minimum where smooth)
            bool better = false;
            for (int k = 0; k < 16; ++k) {
                const double a = 2 * kPi * k / 16;
                const Vec2 y1 = y + step * Vec2(std::cos(a), std::sin(a));
                const double h1 = h_at(d0 + B * y1);
                if (h1 < h) {
                    h = h1;
                    y = y1;
                    better = true;
                }
            }
            step = better ? std::min(2 * step, 1 / wn) : 0.5 * step;
        }
        d = d0 + B * y;
    }
    // At the optimum the distribution f_i = gamma cap_i v_i / |v_i| (v_i = G_i^T d) supplies w exactly.
    // Where the pattern search's does not (by more than 1e-6 of |w|; its own stopping leaves less away
    // from kinks, and next to one the repair below only refines a correct optimum), it stopped at a kink that is not the optimum (its descent cone
    // narrower than the 16 directions: random scene 15 of the held-modes test, the wrench 0.22 N off
    // and the gauge 4.7997 for 4.8008), or at the optimum on a kink whose test failed by rounding (the
    // kink's force, inside its disk, is then missing). Then h is smoothed, h_delta(d) = sum cap_i
    // sqrt(|v_i|^2 + delta^2) (convex and smooth for delta > 0, within 3 cap delta of h), and minimised
    // by Newton while delta falls from 1e-2 to 1e-12 of |d0| = 1/|w|, each stage from the last. Its
    // stationary point gives f_i = cap_i v_i / (s_i h~), s_i = sqrt(|v_i|^2 + delta^2), h~ = sum cap_i
    // |v_i|^2 / s_i, whose wrench is w (grad h_delta = h~ w there), a contact at the kink included: its
    // force is then inside its disk, and it is the pivot (choose_mode breaks away about it). The repair
    // is kept only where it is at least as low as the search's h (it always was where measured). (Where
    // measured -- fig6's, heave_yaw's, fig1's and foot's fields, the [stick] and [dynamics] tests -- the
    // repair ran over a hundred times and never ended at a kink: its pivot is a guard, not a path seen.)
    Vec3 supplied = Vec3::Zero();
    for (int i = 0; i < 3 && stalled; ++i) {
        const Vec2 v = Gt(i, d);
        const double nv = v.norm();
        if (nv > 0) supplied += cap[i] * Gf(i, v / nv) / h;
    }
    if (stalled && (supplied - w).norm() > 1e-6 * wn) {
        double delta = 1e-2 / wn;
        auto h_delta = [&](const Vec2& yy) {
            const Vec3 dd = d0 + B * yy;
            double sum = 0;
            for (int i = 0; i < 3; ++i)
                if (cap[i] > 0) sum += cap[i] * std::sqrt(Gt(i, dd).squaredNorm() + delta * delta);
            return sum;
        };
        for (int stage = 0; stage < 11; ++stage, delta *= 0.1) {
            double hy = h_delta(y);
            for (int it = 0; it < 50; ++it) {
                const Vec3 dd = d0 + B * y;
                Vec3 grad = Vec3::Zero();
                Mat3 H = Mat3::Zero();
                for (int i = 0; i < 3; ++i) {
                    if (!(cap[i] > 0)) continue;
                    Eigen::Matrix<double, 3, 2> G;   // d . G = G_i^T d = Gt(i, d)
                    G << 1, 0, 0, 1, -R[i].y(), R[i].x();
                    const Vec2 v = Gt(i, dd);
                    const double si = std::sqrt(v.squaredNorm() + delta * delta);
                    grad += cap[i] * G * v / si;
                    H += cap[i] * G * (Eigen::Matrix2d::Identity() / si - v * v.transpose() / (si * si * si)) * G.transpose();
                }
                const Vec2 gy = B.transpose() * grad;
                Vec2 step = -(B.transpose() * H * B).ldlt().solve(gy);
                if (!step.allFinite()) step = -gy;
                double alpha = 1, h1 = hy;
                Vec2 y1 = y;
                for (int ls = 0; ls < 60; ++ls, alpha *= 0.5) {
                    y1 = y + alpha * step;
                    h1 = h_delta(y1);
                    if (h1 <= hy + 1e-4 * alpha * gy.dot(step)) break;
                }
                if (!(h1 <= hy)) break;
                const double moved = (y1 - y).norm();
                y = y1;
                hy = h1;
                if (moved <= 1e-15 * (1 + y.norm())) break;
            }
        }
        delta *= 10;   // the last stage's
        const Vec3 dr = d0 + B * y;
        const double hr = h_at(dr);
        if (hr <= h * (1 + 1e-12)) {   // (else the repair did not descend: the search's result stands)
            d = dr;
            h = hr;
            finish(d, h);
            double ht = 0;
            std::array<Vec2, 3> v;
            std::array<double, 3> si{};
            for (int i = 0; i < 3; ++i) {
                v[i] = Gt(i, d);
                si[i] = std::sqrt(v[i].squaredNorm() + delta * delta);
                if (cap[i] > 0) ht += cap[i] * v[i].squaredNorm() / si[i];
            }
            double least = 1 - 1e-3;   // (a sliding contact's force is at its rim to within (delta/|v|)^2)
            for (int i = 0; i < 3; ++i) {
                g.f[i] = cap[i] > 0 && ht > 0 ? Vec2(cap[i] * v[i] / (si[i] * ht)) : Vec2::Zero();
                const double used = cap[i] > 0 ? g.f[i].norm() / (g.gamma * cap[i]) : 1.0;
                if (used < least) {
                    least = used;
                    g.pivot = i;
                }
            }
            return g;
        }
    }
    finish(d, h);
    for (int i = 0; i < 3; ++i) {
        const Vec2 v = Gt(i, d);
        const double nv = v.norm();
        g.f[i] = nv > 0 ? Vec2(g.gamma * cap[i] * v / nv) : Vec2::Zero();
    }
    return g;
}

namespace {
// A rigid part's contact at r = R2 c_i: s'' + theta'' e_z x r - kappa theta'^2 r.
Vec2 contact_acceleration_at(const Vec2& r, Dynamics level, const Vec3& qd, const Vec3& qdd) {
    return qdd.head<2>() + qdd[2] * perp(r) - kappa(level) * qd[2] * qd[2] * r;
}
}  // namespace

Vec2 contact_acceleration(const Part& P, Dynamics level, int i, const Vec3& q, const Vec3& qd, const Vec3& qdd) {
    if (P.point) return qdd.head<2>();
    return contact_acceleration_at(horizontal_offset(P, q[2], i), level, qd, qdd);
}

namespace {

// The unit slip directions of the twist xi (scaled: s_x', s_y', rho theta') as the contacts' hints.
void set_twist_hints(const Part& P, double theta, const Vec3& xi, Workspace& ws) {
    const double rho = P.rho();
    for (int i = 0; i < P.contacts(); ++i) {
        const Vec2 r = horizontal_offset(P, theta, i);
        const Vec2 v(xi[0] - xi[2] / rho * r.y(), xi[1] + xi[2] / rho * r.x());
        ws.hint[i] = v.norm() > 0 ? Vec2(v / v.norm()) : Vec2::Zero();
    }
}
Vec3 scaled_qdd(const Part& P, const Workspace& ws) { return Vec3(ws.qdd[0], ws.qdd[1], P.rho() * ws.qdd[2]); }
void tangent_basis(const Vec3& xi, Vec3& e1, Vec3& e2) {
    e1 = std::abs(xi[0]) < 0.9 ? Vec3::UnitX().cross(xi).normalized() : Vec3::UnitY().cross(xi).normalized();
    e2 = xi.cross(e1);
}

// Every contact creeping: the unknown is the direction xi of the twist, the contacts' directions are its
// slips', and it is consistent when q'' (scaled) is parallel to xi, less the turn the engine measured
// (Workspace::creep_twist_rate; Newton on two angles about xi,
// forward-difference Jacobian). Three independent angles would also admit directions no rigid motion
// has (a contact decelerating while the twist grows).
void twist_creep_accelerations(const Scene& sc, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& ps,
                               Workspace& ws) {
    const Part& P = sc.part;
    Vec3& xi = ws.creep_twist;
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
        // part's contact, u x a = |v| rate: with no turn a slide at the rim of the disk is held at the
        // zero threshold -- fig4's part under a circular drive at mu g (1 + 1e-6), 9.2e5 steps and 5.5x
        // the threshold off)
        const Vec3 D = Q - qs.norm() * ws.creep_twist_rate.cross(x);
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

// Slide with creeping contacts (Workspace::creep): the direction u_j = (cos phi_j, sin phi_j) of each
// creeping contact j is the one along which it then accelerates, c_j = a_j x u_j = 0 (the consistent
// slip direction at the rim of the friction disk; at a located break-away a_j = 0 and c_j vanishes to
// first order at the rim's direction). Newton's method on the angles, from the last solution
// (ws.hint), with a forward-difference Jacobian; leaves ws evaluated at the solution.
void creep_accelerations(const Scene& sc, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& ps,
                         Workspace& ws) {
    const Part& P = sc.part;
    if (!P.point && (ws.creep & 7u) == 7u) {
        ws.creep_iterations = 0;
        twist_creep_accelerations(sc, level, q, qd, ps, ws);
        return;
    }
    int idx[3], m = 0;
    for (int i = 0; i < P.contacts(); ++i)
        if ((ws.creep >> i & 1u) && ws.hint[i].norm() > 0) idx[m++] = i;
    ws.creep_iterations = 0;
    accelerations(sc, level, q, qd, ps, ws);
    if (m == 0) return;
    // (a_j x u_j + |v_j| rate_j: the slip turns with its direction at the rate the engine measured,
    // d(v/|v|)/dt = (u x a) / |v|; with rate 0 the slip could not turn with a turning drive, and a
    // slide at the rim of the disk stayed at the zero threshold, 20x below the exact speed.)
    // (r_i from the workspace's cache when it holds this theta: no cosine and sine per contact and
    // evaluation)
    const bool cached = !P.point && q[2] == ws.theta;
    auto residual = [&](Eigen::Vector3d& c) {
        for (int j = 0; j < m; ++j) {
            const Vec2 a = cached ? contact_acceleration_at(ws.r[idx[j]], level, qd, ws.qdd)
                                  : contact_acceleration(P, level, idx[j], q, qd, ws.qdd);
            const Vec2& u = ws.hint[idx[j]];
            c[j] = a.x() * u.y() - a.y() * u.x() + ws.slip[idx[j]].norm() * ws.creep_rate[idx[j]];
        }
    };
    auto set_angles = [&](const Eigen::Vector3d& phi) {
        for (int j = 0; j < m; ++j) ws.hint[idx[j]] = Vec2(std::cos(phi[j]), std::sin(phi[j]));
    };
    Eigen::Vector3d phi, c, cj;
    for (int j = 0; j < m; ++j) phi[j] = std::atan2(ws.hint[idx[j]].y(), ws.hint[idx[j]].x());
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
        if (m == 1) step[0] = -c[0] / J(0, 0);   // (one creeping contact, the usual case: no LU)
        else step.head(m) = -J.topLeftCorner(m, m).partialPivLu().solve(c.head(m));
        if (!step.allFinite()) step.setZero();       // a singular Jacobian: keep the last directions
        step = step.cwiseMax(-0.5).cwiseMin(0.5);    // (a Newton step of at most ~30 degrees)
        phi += step;
        set_angles(phi);
        accelerations(sc, level, q, qd, ps, ws);
        ++ws.creep_iterations;
        residual(c);
        if (step.cwiseAbs().maxCoeff() < 1e-11) break;
    }
}

}  // namespace

void mode_accelerations(const Scene& sc, Dynamics level, const Vec3& q, const Vec3& qd, const PlateState& ps,
                        const Mode& mode, Workspace& ws) {
    const Part& P = sc.part;
    if (ws.prepared != &sc) ws.prepare(sc);
    switch (mode.kind) {
        case ModeKind::Slide:
            if (ws.creep) creep_accelerations(sc, level, q, qd, ps, ws);
            else accelerations(sc, level, q, qd, ps, ws);
            return;
        case ModeKind::Stuck:
            ++ws.evals;
            slip_velocities(P, q, qd, ws.slip);
            stuck_solve(sc, level, q, qd, ps, ws);
            return;
        case ModeKind::Pivot: {
            ++ws.evals;
            slip_velocities(P, q, qd, ws.slip);
            // The sliding contacts move on circles about c_k: v_j = theta' e_z x (r_j - r_k), whose
            // direction is the mode's sense times e_z x (r_j - r_k) (exact even at theta' = 0).
            std::array<Vec2, 3> u = zeros<Vec2>();
            const Vec2 rk = horizontal_offset(P, q[2], mode.k);
            for (int j = 0; j < 3; ++j)
                if (j != mode.k) u[j] = mode.sense * perp(horizontal_offset(P, q[2], j) - rk).normalized();
            pivot_solve(sc, level, mode.k, q, qd, ps, u, ws);
            return;
        }
    }
}

ModeChoice choose_mode(const Scene& sc, Dynamics level, const Vec3& q, Vec3& qd, const PlateState& ps, unsigned zero,
                       Workspace& ws, bool hold) {
    const Part& P = sc.part;
    const int nc = P.contacts();
    ws.creep = 0;   // every slide below has its directions set here
    ws.creep_rate = {};
    ws.creep_twist.setZero();
    ws.creep_twist_rate.setZero();
    ModeChoice out;
    int count = 0, k = -1;
    for (int i = 0; i < nc; ++i)
        if (zero & (1u << i)) { ++count; k = i; }
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
                change = std::max(change, (u - ws.hint[i]).norm());
                ws.hint[i] = u;
            }
            if (change < 1e-12) break;
        }
    };
    ws.use_hints = true;
    if (count == 1 && !P.point) {
        // One contact at zero slip: project onto v_k = 0 (s' -= v_k), then can contact k pivot?
        std::array<Vec2, 3> v;
        slip_velocities(P, q, qd, v);
        qd.head<2>() -= v[k];
        if (qd[2] == 0) count = 3;   // the others are then at rest too
        else {
            Mode pivot{ModeKind::Pivot, k, qd[2] > 0 ? 1.0 : -1.0};
            mode_accelerations(sc, level, q, qd, ps, pivot, ws);
            const double cap = P.mu[k] * std::max(ws.n[k], 0.0), need = ws.f_held[k].norm();
            out.gamma = cap > 0 ? need / cap : std::numeric_limits<double>::infinity();
            if (need <= cap * (1 + 1e-12)) {
                // Held; a negative normal force elsewhere then means the part would tip.
                if (!normal_ok()) return out;
                out.mode = pivot;
                return out;
            }
            // A slip reversal: contact k slides on, opposite the friction it would have needed.
            ws.hint[k] = -ws.f_held[k] / need;
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
                if (ws.n.minCoeff() >= 0 && ws.f_held[kk].norm() <= P.mu[kk] * ws.n[kk] && sense * ws.qdd[2] > 0) {
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
        ws.hint[i] = fn > 0 ? Vec2(-g.f[i] / fn) : Vec2::Zero();
        all |= 1u << i;
    }
    if (!P.point) {
        // At a located stick exit (gauge 1) the twist that starts is opposite the one the rim's
        // friction opposes; the creep's Newton refines it from there (engine.hpp).
        const Vec3 d(g.direction[0], g.direction[1], P.rho() * g.direction[2]);
        ws.creep_twist = d.norm() > 0 ? Vec3(-d.normalized()) : Vec3::Zero();
    }
    if (g.gamma > 1 + 1e-6) {
        if (P.point) refine_hints(all);
        else {
            // The twist that starts: the direction xi (scaled) along which q'' points when the slips
            // are xi's -- found by relaxing xi along q''(xi) (the direction a part released at rest
            // takes, q' ~ t q''; the fixed-point iteration xi <- q''(xi) flips back and forth near the
            // stick boundary), from the twist the needed friction opposes, reversed.
            Vec3 xi = ws.creep_twist.isZero() ? Vec3(Vec3::UnitX()) : ws.creep_twist;
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
                    xi = next; Q = Qn; r = rn;
                    tau = std::min(0.5, 1.5 * tau);
                } else {
                    tau *= 0.3;
                }
            }
            set_twist_hints(P, q[2], xi, ws);
            ws.creep_twist = xi;
        }
    }
    out.mode = Mode{};
    return out;
}

}  // namespace plate
