// Symbolic derivation (GiNaC) of the equations of motion of Section III, from the frames and
// rotations (1)-(9), the contact kinematics and Coulomb forces (12)-(17), and Newton's and
// Euler's laws (15), (21). Time derivatives are taken by a jet rule (a total derivative that
// knows p' = pd, R1' = w1^ R1 (7), theta' = thd, ...), so nothing of the paper's results is
// typed in: the printed forms appear only as the comparisons in `findings`.
//
// Orthogonality of R1 and R2 is used twice, each time checked exactly (rational points on SO(3)
// from the Cayley map and on the unit circle, Schwartz-Zippel style): R1^T R1 s'' = s'' in
// Newton's law, and Q^T w^ Q = (Q^T w)^ for the angular velocity of the part.
#pragma once

#include <ginac/ginac.h>

#include <array>
#include <string>
#include <vector>

namespace plate::symbolic {

using GiNaC::ex;
using GiNaC::matrix;
using GiNaC::realsymbol;

struct Symbols {
    Symbols();
    realsymbol m, g;
    realsymbol Jxx, Jxy, Jxz, Jyy, Jyz, Jzz;
    std::array<realsymbol, 3> cx, cy;   // contacts c_i in S
    realsymbol cz;                      // their common z
    std::array<realsymbol, 3> mu;       // kinetic coefficients mu_ki: sliding contacts (17)
    std::array<realsymbol, 3> mus;      // static coefficients mu_si: the disks of held contacts
    realsymbol ct, st, thd, thdd;       // cos theta, sin theta, theta', theta''
    realsymbol sx, sy, sz, sxd, syd, sxdd, sydd;
    std::array<realsymbol, 3> N;
    std::array<realsymbol, 3> ux, uy;             // unit slip directions (inputs, so entries stay polynomial)
    std::array<realsymbol, 3> p, pd, pdd;         // plate position, velocity, acceleration (W)
    std::array<std::array<realsymbol, 3>, 3> R;   // R1 entries
    std::array<realsymbol, 3> w, wd;              // omega1, omega1' (W)
    // limit surface: twist relative to the plate in scaled coordinates, contact positions in P
    realsymbol vx, vy, xith, rho;
    std::array<realsymbol, 3> rx, ry;
    // stick-slip: a pivot's static friction (P frame); a stuck part's needed friction wrench
    realsymbol fx, fy, Fx, Fy, tauz;

    std::vector<realsymbol> unknowns() const { return {sxdd, sydd, thdd, N[0], N[1], N[2]}; }
};

// A comparison of a derived equation with the paper's printed form.
struct Finding {
    std::string equation;   // e.g. "(28)"
    bool agrees = false;
    std::string printed;   // the printed form (text)
    std::string derived;   // the derived / corrected form (text)
    std::string reason;
};

struct Derivation {
    Symbols S;
    matrix slip[3];              // sliding velocity s' + w2^ R2 c_i of each contact (P frame), 3x1
    matrix A;                    // 6x6, (31): rows Newton x y z, Euler x y z; columns s_x'', s_y'', theta'', N1..3
    matrix b_full;               // 6x1, [f_dagger (19); tau_dagger (30)]
    matrix b_U;                  // 6x1, [f~_dagger (33); tau~_dagger (34)]
    matrix omega3, omega3_dot;   // (27), (28) as derived
    // Point part: z = [s_x'', s_y'', N], A_point z = b (first three rows of b with s_z = 0).
    matrix A_point;                   // 3x3
    matrix point_solution;            // 3x1: s_x'', s_y'', N in terms of b0..b2 symbols
    std::array<realsymbol, 6> bsym;   // symbols standing for b entries in solutions
    // Thick part: Schur reduction of A z = b to a 3x3 system M n = r (rows 1-2 and 6 eliminated).
    matrix M_reduced, r_reduced;   // r in terms of bsym
    matrix back_substitution;      // q'' in terms of n (N symbols) and bsym
    // The same, staged for code generation: in terms of placeholders a_rk for A's non-constant
    // entries (A_placeholders lists them with their expressions).
    matrix M_staged, r_staged, back_staged;
    std::vector<std::pair<realsymbol, ex>> A_placeholders;
    // b of the full dynamics rewritten in plate-frame vectors Omega = R1^T w1, alpha = R1^T w1',
    // a = R1^T p'', gamma = R1^T e_z (identities on SO(3), checked exactly against b_full).
    matrix b_full_staged;
    std::vector<std::pair<realsymbol, ex>> plate_frame_placeholders;
    // Thin part (Appendix A): A after swapping rows 3 and 6, and the normal-force system (38).
    matrix A_thin_swapped;
    matrix M38, r38_U;   // (38): M38 n = r38 (U-dynamics right-hand side)
    // Thick part: the coupling that the thin part loses.
    matrix A_thick_swapped;
    // Limit surface (Appendix B): frictional wrench on a thin part from its relative twist,
    // scaled: xi = (v_x, v_y, rho omega), w = (F_x, F_y, tau / rho); and its dissipation power.
    matrix wrench;   // 3x1
    ex power;        // sum mu_i N_i |v_i| (the wrench is -grad of it)
    // Stick-slip modes (modes.hpp). Pivot k, unknowns z = (s_x'', s_y'', theta'', N1..3, f_x, f_y):
    // pivot_A[k] z = [b; pivot_c[k]], rows Newton x y z, Euler x y z, then contact k's relative
    // acceleration s'' + theta'' e_z x r_k - theta'^2 r_k = 0; pivot_c[k] = theta'^2 r_k (turning
    // configuration; zero in the reduced U-dynamics, checked).
    std::array<matrix, 3> pivot_A, pivot_c;
    // Stuck (q'' = 0): (N1, N2, N3, F_x, F_y, tau_z) = stuck_solution / stuck_det in terms of bsym
    // (stuck_det: the contacts' determinant, zero for collinear contacts).
    matrix stuck_solution;
    ex stuck_det;
    // Support function of the friction set, P(d) = sum support_term[i] (Appendix B's power), with
    // support_speed[i] = |v_i| = |G_i^T d|; limit-surface symbols (vx, vy, xith, rho, r_i).
    std::array<ex, 3> support_term, support_speed;
    std::vector<Finding> findings;
};

Derivation derive();

// Exact check that e vanishes on SO(3) x S^1: substitute R1 = Cayley(k) and (ct, st) on the unit
// circle with random rationals for every symbol, `trials` times. Returns true if all are zero.
bool vanishes_on_rotations(const ex& e, const Symbols& S, int trials = 4, unsigned seed = 1);

// LaTeX of the derived equations (for the verification report).
std::string latex_report(const Derivation& d);
// The findings as Markdown.
std::string findings_markdown(const Derivation& d);

}   // namespace plate::symbolic
