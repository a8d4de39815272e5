// Internal to the symbolic derivation (derivation.cpp, derivation_parts.cpp): the small matrix
// helpers, the jet rule of time derivatives, the frames the stages share, and the stages that
// derivation_parts.cpp defines. derive() (derivation.hpp) runs the stages in the paper's order.
//
// GiNaC numbers symbols as they are created and orders terms by those numbers, so the stages run in
// the order of the original single function: every symbol and expression is built in the same
// sequence, and the generated kernels stay byte-identical.
#pragma once

#include "derivation.hpp"

#include <array>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace plate::symbolic::detail {

using namespace GiNaC;

inline std::string idx(const char* a, int i, const char* b = "") { return a + std::to_string(i + 1) + b; }

inline matrix col(const ex& a, const ex& b, const ex& c) { return matrix{{a}, {b}, {c}}; }
inline matrix hat(const matrix& v) { return matrix{{0, -v(2, 0), v(1, 0)}, {v(2, 0), 0, -v(0, 0)}, {-v(1, 0), v(0, 0), 0}}; }
inline matrix cross(const matrix& a, const matrix& b) { return hat(a).mul(b); }
inline matrix vee(const matrix& X) { return col(X(2, 1), X(0, 2), X(1, 0)); }

inline matrix map(const matrix& M, const std::function<ex(const ex&)>& f) {
    matrix out(M.rows(), M.cols());
    for (unsigned i = 0; i < M.rows(); ++i)
        for (unsigned j = 0; j < M.cols(); ++j) out(i, j) = f(M(i, j));
    return out;
}
inline matrix expand_all(const matrix& M) {
    return map(M, [](const ex& e) { return e.expand(); });
}
inline matrix sub(const matrix& a, const matrix& b) { return a.sub(b); }
inline bool is_zero(const matrix& M) {
    for (unsigned i = 0; i < M.rows(); ++i)
        for (unsigned j = 0; j < M.cols(); ++j)
            if (!M(i, j).expand().is_zero()) return false;
    return true;
}
inline ex to_ex(const matrix& M) { return M; }

// The total time derivative: d/dt e = sum over symbols s of (de/ds) s'.
struct Jet {
    std::vector<std::pair<realsymbol, ex>> rules;
    ex D(const ex& e) const {
        ex r = 0;
        for (const auto& [s, ds] : rules) {
            const ex de = e.diff(s);
            if (!de.is_zero()) r += de * ds;
        }
        return r.expand();
    }
    matrix D(const matrix& M) const {
        return map(M, [this](const ex& e) { return D(e); });
    }
};

// What the stages share: the frames (1)-(9), the jet rule, the part's position and velocity in P,
// W s'' for Newton's law (15) and the inertia tensor of Euler's law (21).
struct Frames {
    matrix R1, R2;        // plate and part rotations, (2)
    matrix w1, wd1, w2;   // omega1, omega1', omega2 = theta' e_z (5)
    matrix ez;
    Jet J;          // the total time derivative
    matrix s, sd;   // s and s' (s_z constant, assumption 1)
    matrix Wsdd;    // second time derivative of W s = p + R1 s
    matrix Jm;      // J in S
};

// Records a comparison of a derived equation with the paper's printed form.
inline void add_finding(Derivation& d, std::string eq, bool agrees, std::string printed, std::string derived,
                        std::string reason) {
    d.findings.push_back(Finding{std::move(eq), agrees, std::move(printed), std::move(derived), std::move(reason)});
}

// Newton's (15) and Euler's (21) laws for given friction forces f_i (P frame, z = 0), as
// [Newton; Euler] (6x1), zero on the motion (derivation.cpp).
matrix newton_euler(const Derivation& d, const Frames& F, const std::array<matrix, 3>& f);

// The stages of derivation_parts.cpp, in the order derive() runs them.
void pivot_modes(Derivation& d, const Frames& F, const std::array<matrix, 3>& kinetic);   // stick-slip: pivots
void stuck_mode(Derivation& d, const Frames& F);                                          // stick-slip: stuck
void support_function(Derivation& d);                                                     // the friction set's support function
void friction_roles(Derivation& d);                          // which coefficient, static or kinetic, each mode's equations hold
void point_part(Derivation& d, const Frames& F);             // one contact at the centre of mass
void thick_reduction(Derivation& d);                         // A z = b reduced to 3x3 in n
void staged_reduction(Derivation& d, const Frames& F);       // the same with placeholders, for codegen
void staged_plate_frame_b(Derivation& d, const Frames& F);   // b in plate-frame vectors, for codegen
void thin_part(Derivation& d, const Frames& F);              // Appendix A, (37), (38)
void limit_surface(Derivation& d);                           // Appendix B

}   // namespace plate::symbolic::detail
