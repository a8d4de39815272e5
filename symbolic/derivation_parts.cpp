// The symbolic derivation's later stages (derive() in derivation.cpp runs them): the stick-slip
// modes (pivot and stuck, with the friction set's support function), the solutions of A z = b for a
// point and a thick part, the staged forms the kernels are generated from, the thin part
// (Appendix A, (37), (38)) and the limit surface (Appendix B).
#include "derivation_steps.hpp"

#include <stdexcept>

namespace plate::symbolic::detail {

namespace {

// Eliminates s'' (rows 1, 2) and theta'' (row 6) from A z = b: returns M, r of the 3x3 system
// M n = r (rows 3, 4, 5) and q'' in terms of n and b.
struct Reduced {
    matrix M, r, back;
};
Reduced reduce(const matrix& A, const std::array<realsymbol, 6>& b, const std::array<realsymbol, 3>& N) {
    Reduced out{matrix(3, 3), matrix(3, 1), matrix(3, 1)};
    const ex inv52 = 1 / A(5, 2);
    const int rows[3] = {2, 3, 4};
    for (int i = 0; i < 3; ++i) {
        const int r = rows[i];
        for (int k = 0; k < 3; ++k) out.M(i, k) = A(r, 3 + k) - A(r, 2) * inv52 * A(5, 3 + k);
        out.r(i, 0) = b[r] - A(r, 2) * inv52 * b[5];
    }
    ex nx = b[0], ny = b[1], nt = b[5];
    for (int k = 0; k < 3; ++k) {
        nx -= A(0, 3 + k) * N[k];
        ny -= A(1, 3 + k) * N[k];
        nt -= A(5, 3 + k) * N[k];
    }
    out.back(0, 0) = nx / A(0, 0);
    out.back(1, 0) = ny / A(1, 1);
    out.back(2, 0) = nt * inv52;
    return out;
}

}   // namespace

// --- Stick-slip modes (numeric/include/plate/modes.hpp) -------------------------------------
// Pivot k: contact k carries an unknown static friction f = (f_x, f_y) (P frame) instead of
// (17), and its slip stays zero, so its relative acceleration, the derivative of its sliding
// velocity, vanishes: two more rows. In the reduced U-dynamics (35) the configuration is
// frozen (R2 does not turn), so the same derivative is taken with theta' acting on nothing.
void pivot_modes(Derivation& d, const Frames& F, const std::array<matrix, 3>& kinetic) {
    const Symbols& S = d.S;
    const Jet& J = F.J;
    Jet frozen;
    for (const auto& rule : J.rules)
        if (!rule.first.is_equal(S.ct) && !rule.first.is_equal(S.st)) frozen.rules.push_back(rule);
    const std::vector<realsymbol> zk = {S.sxdd, S.sydd, S.thdd, S.N[0], S.N[1], S.N[2], S.fx, S.fy};
    exmap zero;
    for (const auto& u : zk) zero[u] = 0;
    for (int k = 0; k < 3; ++k) {
        std::array<matrix, 3> f = kinetic;
        f[k] = col(S.fx, S.fy, 0);
        const matrix E = newton_euler(d, F, f);
        const matrix c = J.D(d.slip[k]), cf = frozen.D(d.slip[k]);
        if (!c(2, 0).is_zero()) throw std::logic_error("pivot constraint out of the plane");
        matrix& A = d.pivot_A[k];
        A = matrix(8, 8);
        d.pivot_c[k] = matrix(2, 1);
        for (int r = 0; r < 8; ++r) {
            const ex e = r < 6 ? E(r, 0) : c(r - 6, 0);
            ex lin = 0;
            for (int j = 0; j < 8; ++j) {
                A(r, j) = e.diff(zk[j]).expand();
                lin += A(r, j) * zk[j];
            }
            const ex rest = (e - lin).expand();
            if (!rest.subs(zero).is_equal(rest)) throw std::logic_error("pivot equations not linear in the unknowns");
            // Friction does not enter b: the pivot's right side is the sliding one, (19)/(30).
            if (r < 6 && !(rest + d.b_full(r, 0)).expand().is_zero())
                throw std::logic_error("pivot right-hand side differs from b");
            // As for A: Newton's s'' coefficients are -m R1^T R1 = -m I on SO(3).
            for (int j = 0; j < 2 && r < 3; ++j) {
                const ex expect = r == j ? ex(-S.m) : ex(0);
                if (!vanishes_on_rotations(A(r, j) - expect, S))
                    throw std::logic_error("pivot: Newton's s'' coefficients are not -m I on SO(3)");
                A(r, j) = expect;
            }
            if (r >= 6) {
                d.pivot_c[k](r - 6, 0) = (-rest).expand();
                const ex ef = cf(r - 6, 0);
                for (int j = 0; j < 8; ++j)
                    if (!(ef.diff(zk[j]) - A(r, j)).expand().is_zero())
                        throw std::logic_error("frozen pivot constraint has other coefficients");
                if (!ef.subs(zero).expand().is_zero()) throw std::logic_error("frozen pivot constraint has a right side");
            }
        }
    }
    // The constraint is s'' + theta'' e_z x r_k - theta'^2 r_k = 0 (r_k = R2 c_k): check it.
    {
        const matrix rk = F.R2.mul(col(S.cx[0], S.cy[0], S.cz));
        const matrix expect =
            col(S.sxdd - S.thdd * rk(1, 0) - S.thd * S.thd * rk(0, 0), S.sydd + S.thdd * rk(0, 0) - S.thd * S.thd * rk(1, 0), 0);
        add_finding(d, "pivot constraint", is_zero(sub(J.D(d.slip[0]), expect)), "(not in the paper)",
                    "d/dt (s' + w2^ R2 c_k) = s'' + theta'' e_z x r_k - theta'^2 r_k = 0",
                    "a contact held by static friction does not accelerate relative to the plate; the centripetal "
                    "term theta'^2 r_k is absent in the reduced U-dynamics (35), whose configuration is frozen");
    }
}

// Stuck: q'' = 0 and friction forces f_i = (f_ix, f_iy) of unknown distribution. The
// equations depend on the f_i only through the total F = sum f_i and the moment
// tau_z = sum r_i x f_i: every internal pair (equal and opposite forces along the line
// between two contacts) leaves them unchanged. So the normal forces and the needed friction
// wrench (F, tau_z) are determinate although the distribution is not.
void stuck_mode(Derivation& d, const Frames& F) {
    const Symbols& S = d.S;
    const matrix& R2 = F.R2;
    std::array<realsymbol, 3> gx, gy;
    std::array<matrix, 3> f;
    for (int i = 0; i < 3; ++i) {
        gx[i] = realsymbol(idx("f", i, "x"));
        gy[i] = realsymbol(idx("f", i, "y"));
        f[i] = col(gx[i], gy[i], 0);
    }
    exmap at_rest{{S.sxdd, 0}, {S.sydd, 0}, {S.thdd, 0}, {S.sxd, 0}, {S.syd, 0}, {S.thd, 0}};
    const matrix E = newton_euler(d, F, f);
    matrix lin(6, 1);   // the contact forces' part: E = lin - b at zero relative motion
    for (int r = 0; r < 6; ++r) lin(r, 0) = (E(r, 0).subs(at_rest) + d.b_full(r, 0).subs(at_rest)).expand();
    std::array<matrix, 3> r2;
    for (int i = 0; i < 3; ++i) r2[i] = R2.mul(col(S.cx[i], S.cy[i], S.cz));
    bool internal_ok = true;
    for (int i = 0; i < 3; ++i) {
        const int j = (i + 1) % 3;
        exmap pair;
        const ex ex_ = r2[j](0, 0) - r2[i](0, 0), ey = r2[j](1, 0) - r2[i](1, 0);
        const realsymbol t("t");
        pair[gx[i]] = gx[i] + t * ex_;
        pair[gy[i]] = gy[i] + t * ey;
        pair[gx[j]] = gx[j] - t * ex_;
        pair[gy[j]] = gy[j] - t * ey;
        for (int r = 0; r < 6; ++r) internal_ok = internal_ok && vanishes_on_rotations(lin(r, 0).subs(pair) - lin(r, 0), S);
    }
    if (!internal_ok) throw std::logic_error("the stuck equations depend on the friction distribution");
    // f_1 = F - f_2 - f_3; then rows 1-5 hold F alone and row 6 is tau_z.
    exmap total{{gx[0], S.Fx - gx[1] - gx[2]}, {gy[0], S.Fy - gy[1] - gy[2]}};
    ex tau = 0;
    for (int i = 0; i < 3; ++i) tau += r2[i](0, 0) * gy[i] - r2[i](1, 0) * gx[i];
    lst eqs;
    for (int r = 0; r < 6; ++r) {
        ex e = lin(r, 0).subs(total).expand();
        if (r == 5) {
            const ex rest = (e - tau.subs(total)).expand();
            if (!vanishes_on_rotations(rest.diff(gx[1]), S) || !vanishes_on_rotations(rest.diff(gy[1]), S) ||
                !vanishes_on_rotations(rest.diff(gx[2]), S) || !vanishes_on_rotations(rest.diff(gy[2]), S) ||
                !vanishes_on_rotations(rest.diff(S.Fx), S) || !vanishes_on_rotations(rest.diff(S.Fy), S))
                throw std::logic_error("the stuck yaw equation is not tau_z plus normal-force terms");
            e = (rest.subs(exmap{{gx[1], 0}, {gy[1], 0}, {gx[2], 0}, {gy[2], 0}}) + S.tauz).expand();
        }
        for (int i = 1; i < 3; ++i)
            if (!e.diff(gx[i]).is_zero() || !e.diff(gy[i]).is_zero())
                throw std::logic_error("the stuck equations depend on the friction distribution");
        eqs.append(e == d.bsym[r]);
    }
    const ex sol = lsolve(eqs, lst{S.N[0], S.N[1], S.N[2], S.Fx, S.Fy, S.tauz});
    // Written over the contacts' determinant (fixed here: normal() picks the sign of a
    // denominator from GiNaC's run-dependent term order).
    d.stuck_det =
        (S.cx[1] * S.cy[2] - S.cx[2] * S.cy[1] - S.cx[0] * S.cy[2] + S.cx[2] * S.cy[0] + S.cx[0] * S.cy[1] - S.cx[1] * S.cy[0])
            .expand();
    d.stuck_solution = matrix(6, 1);
    for (int r = 0; r < 6; ++r) {
        const ex num = (sol.op(r).rhs() * d.stuck_det).normal().expand();
        if (!is_a<add>(num) && !is_a<mul>(num) && !is_a<symbol>(num) && !is_a<numeric>(num))
            throw std::logic_error("stuck solution: unexpected form");
        if (!(num / d.stuck_det - sol.op(r).rhs()).normal().is_zero() || num.denom() != 1)
            throw std::logic_error("stuck solution is not polynomial over the contacts' determinant");
        d.stuck_solution(r, 0) = num;
    }
    add_finding(d, "stuck mode", internal_ok, "(not in the paper)",
                "N (3), F = sum f_i, tau_z = sum r_i x f_i from Newton-Euler with q'' = 0",
                "the friction distribution of a stuck part is indeterminate, but Newton-Euler depends on it only "
                "through (F, tau_z): internal pairs of equal and opposite forces along the lines between contacts "
                "change nothing (checked exactly). The part stays stuck while (F, tau_z) lies in the friction set, "
                "whose support function is the dissipation power P of Appendix B");
}

// Break-away from stuck: the gauge max_d (d . w) / P(d) of the needed wrench w against the
// friction set, P(d) = sum_i mu_si N_i |G_i^T d| (the support function, Appendix B, of the static
// disks). Each term with its gradient and Hessian in d = (vx, vy, xith) drives the gauge's Newton
// iteration.
void support_function(Derivation& d) {
    const Symbols& S = d.S;
    for (int i = 0; i < 3; ++i) {
        const ex om = S.xith / S.rho;
        const ex vix = S.vx - om * S.ry[i], viy = S.vy + om * S.rx[i];
        d.support_speed[i] = sqrt(vix * vix + viy * viy);
        d.support_term[i] = S.mus[i] * S.N[i] * d.support_speed[i];
    }
}

// Static and kinetic friction: a sliding contact's force is mu_ki N_i (17), a held contact's force
// lies in its disk mu_si N_i. Checked exactly on the derived equations: the slide system holds every
// mu_ki and no mu_si; pivot k's system holds the sliding contacts' mu_ki, not its own (contact k
// enters through its unknown force f_k alone, bounded by mu_sk N_k in the hold margin) and no mu_si;
// the stuck part's normal forces and needed wrench hold no coefficient at all (the gauge judges them
// against the static disks); the support function holds the static coefficients only. So a contact
// that breaks away (|f_k| = mu_sk N_k) slides on at mu_kk N_k: with mu_s > mu_k its friction drops at
// the event, and a slip that reaches zero re-sticks where the needed force fits the static disk.
void friction_roles(Derivation& d) {
    const Symbols& S = d.S;
    const auto holds = [](const matrix& M, const realsymbol& s) {
        for (unsigned r = 0; r < M.rows(); ++r)
            for (unsigned c = 0; c < M.cols(); ++c)
                if (M(r, c).has(s)) return true;
        return false;
    };
    bool ok = true;
    for (int i = 0; i < 3; ++i) {
        ok = ok && holds(d.A, S.mu[i]) && !holds(d.A, S.mus[i]);
        ok = ok && !holds(d.stuck_solution, S.mu[i]) && !holds(d.stuck_solution, S.mus[i]);
        ok = ok && d.support_term[i].has(S.mus[i]) && !d.support_term[i].has(S.mu[i]);
        for (int k = 0; k < 3; ++k) {
            const bool own = holds(d.pivot_A[k], S.mu[i]) || holds(d.pivot_c[k], S.mu[i]);
            ok = ok && own == (i != k) && !holds(d.pivot_A[k], S.mus[i]) && !holds(d.pivot_c[k], S.mus[i]);
        }
    }
    if (!ok) throw std::logic_error("a mode's equations hold the wrong friction coefficients");
    add_finding(d, "static and kinetic friction", ok, "(not in the paper: one coefficient per contact)",
                "slide: mu_k1..3; pivot k: mu_ki of the sliding contacts i != k, contact k's force bounded by mu_sk N_k; "
                "stuck: no coefficient in N, F, tau_z, judged against the static disks; support function: mu_s1..3",
                "a held contact's friction lies in its static disk |f_k| <= mu_sk N_k and a sliding one's is mu_kk N_k "
                "(17): the static coefficients enter only the hold margins and the gauge, so a break-away drops the "
                "contact's friction from mu_sk N_k to mu_kk N_k, and a slip re-sticks where the needed force fits the "
                "static disk (checked exactly on the derived equations)");
}

// --- Point part -----------------------------------------------------------------------------
// One contact at the centre of mass: (s_x'', s_y'', N) from the first three rows of b.
void point_part(Derivation& d, const Frames& F) {
    const Symbols& S = d.S;
    const matrix& ez = F.ez;
    const realsymbol &sxdd = S.sxdd, &sydd = S.sydd, &N = S.N[0];
    const matrix Fc = ez.sub(col(S.mu[0] * S.ux[0], S.mu[0] * S.uy[0], 0)).mul_scalar(N);
    const matrix E = Fc.sub(col(sxdd, sydd, 0).mul_scalar(S.m));   // = b (first three rows)
    d.A_point = matrix(3, 3);
    const ex zp[3] = {sxdd, sydd, N};
    for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) d.A_point(r, k) = E(r, 0).diff(ex_to<symbol>(zp[k])).expand();
    lst eqs, unk{sxdd, sydd, N};
    for (int r = 0; r < 3; ++r) eqs.append(E(r, 0) == d.bsym[r]);
    const ex sol = lsolve(eqs, unk);
    d.point_solution = matrix(3, 1);
    for (int k = 0; k < 3; ++k) d.point_solution(k, 0) = sol.op(k).rhs().expand();
}

// --- Thick part: reduce A z = b to 3x3 in n --------------------------------------------------
void thick_reduction(Derivation& d) {
    const Symbols& S = d.S;
    const matrix& A = d.A;
    for (int r : {0, 1, 2, 3, 4, 5})
        for (int k : {0, 1})
            if (r != k && !A(r, k).is_zero()) throw std::logic_error("unexpected structure of A");
    if (!A(0, 2).is_zero() || !A(1, 2).is_zero() || !A(2, 2).is_zero()) throw std::logic_error("theta'' in Newton");
    // Row 6 (index 5) gives theta''; rows 1, 2 give s''; rows 3, 4, 5 then hold only n.
    const Reduced red = reduce(A, d.bsym, S.N);
    d.M_reduced = expand_all(red.M);
    d.r_reduced = expand_all(red.r);
    d.back_substitution = expand_all(red.back);
}

// --- Staged forms for code generation ----------------------------------------------------------
// The thick reduction again, with placeholders a_rk for A's non-constant entries, so that the
// kernels compute each entry once; checked against the derived reduction.
void staged_reduction(Derivation& d, const Frames& F) {
    const Symbols& S = d.S;
    const matrix& R2 = F.R2;
    const matrix& A = d.A;
    // The torque rows through the friction directions in the part frame, dS_i = R2^T d_i:
    // h_i = c_i x dS_i (23) is then of degree 2 instead of a sum of degree-5 monomials.
    std::array<matrix, 3> hS;
    for (int i = 0; i < 3; ++i) {
        const matrix dS = R2.transpose().mul(col(-S.mu[i] * S.ux[i], -S.mu[i] * S.uy[i], 1));
        const realsymbol dx("dS" + std::to_string(i + 1) + "x"), dy("dS" + std::to_string(i + 1) + "y");
        d.A_placeholders.push_back({dx, dS(0, 0).expand()});
        d.A_placeholders.push_back({dy, dS(1, 0).expand()});
        hS[i] = cross(col(S.cx[i], S.cy[i], S.cz), col(dx, dy, 1));
        exmap back{{dx, dS(0, 0)}, {dy, dS(1, 0)}};
        for (int r = 0; r < 3; ++r)
            if (!(hS[i](r, 0).subs(back) - A(3 + r, 3 + i)).expand().is_zero())
                throw std::logic_error("h_i through dS_i differs from A");
    }
    matrix G(6, 6);
    for (int r = 0; r < 6; ++r)
        for (int k = 0; k < 6; ++k) {
            const ex e = r >= 3 && k >= 3 ? hS[k - 3](r - 3, 0).expand() : A(r, k);
            if (is_a<numeric>(e) || is_a<symbol>(e) || is_a<symbol>(-e)) {
                G(r, k) = e;
            } else {
                const realsymbol a("a" + std::to_string(r) + std::to_string(k));
                d.A_placeholders.push_back({a, e});
                G(r, k) = a;
            }
        }
    const Reduced staged = reduce(G, d.bsym, S.N);
    d.M_staged = staged.M;
    d.r_staged = staged.r;
    d.back_staged = staged.back;
    // The staged forms are the derived ones once the placeholders are filled in.
    exmap fill;   // later placeholders may use earlier ones: fill in order
    for (const auto& [a, e] : d.A_placeholders) fill[a] = e.subs(fill);
    for (int i = 0; i < 3; ++i) {
        for (int k = 0; k < 3; ++k)
            if (!(d.M_staged(i, k).subs(fill) - d.M_reduced(i, k)).expand().is_zero())
                throw std::logic_error("staged reduction differs");
        if (!(d.back_staged(i, 0).subs(fill) - d.back_substitution(i, 0)).expand().is_zero())
            throw std::logic_error("staged back substitution differs");
    }
}

// Full dynamics in plate-frame vectors: b of (31) through Om = R1^T w1, al = R1^T w1',
// ap = R1^T p'', ga = R1^T e_z, checked against b on SO(3).
void staged_plate_frame_b(Derivation& d, const Frames& F) {
    const Symbols& S = d.S;
    const matrix &R1 = F.R1, &R2 = F.R2, &w1 = F.w1, &wd1 = F.wd1, &w2 = F.w2, &ez = F.ez, &s = F.s, &sd = F.sd, &Jm = F.Jm;
    const char* ax[] = {"x", "y", "z"};
    matrix Om(3, 1), al(3, 1), ap(3, 1), ga(3, 1);
    const matrix R1tw = R1.transpose().mul(w1), R1twd = R1.transpose().mul(wd1);
    const matrix R1tp = R1.transpose().mul(col(S.pdd[0], S.pdd[1], S.pdd[2])), R1tez = R1.transpose().mul(ez);
    for (int i = 0; i < 3; ++i) {
        const realsymbol o(std::string("Om") + ax[i]), a(std::string("al") + ax[i]), p(std::string("ap") + ax[i]),
            gm(std::string("ga") + ax[i]);
        d.plate_frame_placeholders.push_back({o, R1tw(i, 0)});
        d.plate_frame_placeholders.push_back({a, R1twd(i, 0)});
        d.plate_frame_placeholders.push_back({p, R1tp(i, 0)});
        d.plate_frame_placeholders.push_back({gm, R1tez(i, 0)});
        Om(i, 0) = o;
        al(i, 0) = a;
        ap(i, 0) = p;
        ga(i, 0) = gm;
    }
    // R1^T (w^ w^ R1 s) = Om^ Om^ s, R1^T (w'^ R1 s) = al^ s, R1^T (w^ R1 s') = Om^ s'.
    const matrix f = ap.add(cross(Om, cross(Om, s)))
                         .add(cross(al, s))
                         .add(cross(Om, sd).mul_scalar(2))
                         .add(ga.mul_scalar(S.g))
                         .mul_scalar(S.m);
    const matrix R2t = R2.transpose();
    const matrix w3 = w2.add(R2t.mul(Om));
    const matrix tau = Jm.mul(R2t.mul(cross(w2, Om)).mul_scalar(-1).add(R2t.mul(al))).add(cross(w3, Jm.mul(w3)));
    d.b_full_staged = matrix(6, 1);
    exmap fillp;
    for (const auto& [a, e] : d.plate_frame_placeholders) fillp[a] = e;
    for (int r = 0; r < 3; ++r) {
        d.b_full_staged(r, 0) = f(r, 0);
        d.b_full_staged(3 + r, 0) = tau(r, 0);
    }
    for (int r = 0; r < 6; ++r)
        if (!vanishes_on_rotations(d.b_full_staged(r, 0).subs(fillp) - d.b_full(r, 0), S))
            throw std::logic_error("plate-frame form of b differs on SO(3), row " + std::to_string(r));
}

// --- Thin part (Appendix A) --------------------------------------------------------------------
// A with c_z = 0, J_xz = J_yz = 0 and rows 3, 6 swapped; the normal-force system (38); the
// comparisons with Appendix A's block structure, (38) and (37).
void thin_part(Derivation& d, const Frames& F) {
    const Symbols& S = d.S;
    const matrix &R2 = F.R2, &wd1 = F.wd1, &ez = F.ez;
    const exmap thin{{S.cz, 0}, {S.Jxz, 0}, {S.Jyz, 0}, {S.sz, 0}};
    auto swapped = [](const matrix& A) {
        matrix B = A;
        for (int k = 0; k < 6; ++k) std::swap(B(2, k), B(5, k));   // rows 3 and 6
        return B;
    };
    d.A_thin_swapped = swapped(map(d.A, [&](const ex& e) { return e.subs(thin).expand(); }));
    d.A_thick_swapped = swapped(d.A);
    d.M38 = matrix(3, 3);
    d.r38_U = matrix(3, 1);
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) d.M38(i, k) = d.A_thin_swapped(3 + i, 3 + k);
    // The right-hand side follows the row swap: rows 4, 5 of b, then row 3.
    const int rb[3] = {3, 4, 2};
    for (int i = 0; i < 3; ++i) d.r38_U(i, 0) = d.b_U(rb[i], 0).subs(thin).expand();
    bool lower_zero = true, upper_nonzero = false;
    for (int r = 3; r < 6; ++r)
        for (int k = 0; k < 3; ++k) lower_zero = lower_zero && d.A_thin_swapped(r, k).is_zero();
    for (int r = 0; r < 3; ++r)
        for (int k = 3; k < 6; ++k) upper_nonzero = upper_nonzero || !d.A_thin_swapped(r, k).is_zero();
    add_finding(d, "Appendix A (block diagonal)", lower_zero && !upper_nonzero, "swapping rows 3 and 6 makes A block diagonal",
                "swapping rows 3 and 6 makes A block upper triangular: [[-m I, -, D_xy], [0, -J_zz, h_z], [0, 0, M38]]",
                "the lower-left block vanishes, so n decouples (M38 n = r38), but the upper-right block "
                "holds the friction terms d_i,xy and h_i,z, which are not zero; the claim that matters, "
                "decoupled and velocity-free normal forces, holds");
    const matrix Mp{{S.cy[0], S.cy[1], S.cy[2]}, {-S.cx[0], -S.cx[1], -S.cx[2]}, {1, 1, 1}};
    const matrix Jt{{S.Jxx, S.Jxy, 0}, {S.Jxy, S.Jyy, 0}, {0, 0, S.Jzz}};
    const matrix JRw = Jt.mul(R2.transpose()).mul(wd1);
    const matrix s0 = col(S.sx, S.sy, 0);
    const ex fz = col(S.pdd[0], S.pdd[1], S.pdd[2]).add(cross(wd1, s0)).add(ez.mul_scalar(S.g)).mul_scalar(S.m)(2, 0);
    const matrix rp = col(JRw(0, 0), JRw(1, 0), fz);
    const bool matrix_ok = is_zero(sub(d.M38, Mp)), rhs_ok = is_zero(sub(d.r38_U, rp));
    // The printed form, read as written where it is well formed: row 1's J R R2^T w1' with the paper's
    // R = R1 R2 is J R1 w1', and R1 = I in the U-dynamics; row 3's g e_z^T (a row added to columns) is
    // read as g e_z, its only well-formed reading. Compared row by row with the derived system.
    const matrix JR1w = Jt.mul(wd1);
    const matrix printed = col(JR1w(0, 0), JRw(1, 0), fz);
    std::string rows_differ;
    for (int i = 0; i < 3; ++i)
        if (!(d.r38_U(i, 0) - printed(i, 0)).expand().is_zero())
            rows_differ += (rows_differ.empty() ? "" : ", ") + std::to_string(i + 1);
    const bool row1_differs = !(d.r38_U(0, 0) - printed(0, 0)).expand().is_zero();
    add_finding(
        d, "(38)", matrix_ok && rows_differ.empty(),
        "[c_y; -c_x; 1 1 1] n = [e_x^T J R R2^T w1'; e_y^T J R2^T w1'; e_z^T m(p'' + w1'^ s0 + g e_z^T)]",
        "[c_y; -c_x; 1 1 1] n = [e_x^T J R2^T w1'; e_y^T J R2^T w1'; m e_z^T (p'' + w1'^ s0 + g e_z)]",
        std::string(matrix_ok && rhs_ok ? "the derived system equals the corrected form" : "[DERIVED DIFFERS]") +
            "; the printed form, with R = R1 R2 (R1 = I in the U-dynamics) and g e_z^T read as g e_z, differs in "
            "right-hand-side rows: " +
            (rows_differ.empty() ? "none" : rows_differ) + (matrix_ok ? "" : "; and in the matrix") +
            (row1_differs
                 ? " (row 1's J R R2^T w1' is J w1': the plate's angular acceleration not turned into the part's frame by R2^T)"
                 : ""));
    {
        // (37) as printed: rows [-m 0 0 d_x], [0 -m 0 d_y], [0 0 0 1 1 1], [0 0 0 c_y], [0 0 0 -c_x],
        // [0 0 -J_zz h_z]; h_i,z is not spelled out in the paper, so row 6 is compared up to it.
        const matrix At = map(d.A, [&](const ex& e) { return e.subs(thin).expand(); });
        matrix P37(6, 6);
        P37(0, 0) = -S.m;
        P37(1, 1) = -S.m;
        P37(5, 2) = -S.Jzz;
        for (int i = 0; i < 3; ++i) {
            P37(0, 3 + i) = -S.mu[i] * S.ux[i];
            P37(1, 3 + i) = -S.mu[i] * S.uy[i];
            P37(2, 3 + i) = 1;
            P37(3, 3 + i) = S.cy[i];
            P37(4, 3 + i) = -S.cx[i];
            P37(5, 3 + i) = At(5, 3 + i);
        }
        add_finding(d, "(37)", is_zero(sub(At, P37)),
                    "thin-part A: rows [-m 0 0 d_x], [0 -m 0 d_y], [0 0 0 1], [0 0 0 c_y], [0 0 0 -c_x], [0 0 -J_zz h_z]",
                    "A with c_z = 0, J_xz = J_yz = 0", "agrees: h_i = [c_i,y, -c_i,x, h_i,z]");
    }
}

// --- Limit surface (Appendix B) ----------------------------------------------------------------
// The frictional wrench on a thin part from its scaled relative twist, and the dissipation power
// whose negative gradient it is (normality).
void limit_surface(Derivation& d) {
    const Symbols& S = d.S;
    d.wrench = matrix(3, 1);
    d.power = 0;
    ex Fx = 0, Fy = 0, tau = 0;
    for (int i = 0; i < 3; ++i) {
        const ex om = S.xith / S.rho;   // xi_theta = rho omega
        const ex vix = S.vx - om * S.ry[i], viy = S.vy + om * S.rx[i];
        const ex speed = sqrt(vix * vix + viy * viy);
        const ex fx = -S.mu[i] * S.N[i] * vix / speed, fy = -S.mu[i] * S.N[i] * viy / speed;
        Fx += fx;
        Fy += fy;
        tau += S.rx[i] * fy - S.ry[i] * fx;
        d.power += S.mu[i] * S.N[i] * speed;
    }
    // Expanded: a canonical form whose structure does not depend on GiNaC's run-dependent
    // term order (which decides, e.g., where a sign is pulled out of a sum).
    d.wrench(0, 0) = Fx.expand();
    d.wrench(1, 0) = Fy.expand();
    d.wrench(2, 0) = (tau / S.rho).expand();   // w_theta = tau / rho
    const ex n0 = (d.wrench(0, 0) + d.power.diff(S.vx)).normal();
    const ex n1 = (d.wrench(1, 0) + d.power.diff(S.vy)).normal();
    const ex n2 = (d.wrench(2, 0) + d.power.diff(S.xith)).normal();
    add_finding(d, "Appendix B (normality)", n0.is_zero() && n1.is_zero() && n2.is_zero(),
                "the relative twist is normal to the limit surface at the frictional wrench",
                "w = -grad_xi P(xi), P = sum mu_i N_i |v_i| (the dissipated power), in the footnote's scaled "
                "coordinates",
                "agrees: the wrench is minus the gradient of a convex function of the twist, so the twist is "
                "normal to the level set (the limit surface) in wrench space");
}

}   // namespace plate::symbolic::detail
