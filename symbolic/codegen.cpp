#include "codegen.hpp"

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <vector>

namespace plate::symbolic {

using namespace GiNaC;

namespace {
std::string text(const numeric& x) {
    std::ostringstream o;
    o << x;
    return o.str();
}
}   // namespace

std::string double_literal(const numeric& x) {
    if (!x.is_rational()) throw std::invalid_argument("codegen: non-rational number");
    if (x.is_integer()) {
        std::string s = text(x);
        return (x < 0 ? "(" + s + ".0)" : s + ".0");
    }
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.17g", x.to_double());
    std::string s = buf;
    if (s.find_first_of(".e") == std::string::npos) s += ".0";
    return x < 0 ? "(" + s + ")" : s;
}

std::string canonical_text(const ex& e) {
    static thread_local std::map<ex, std::string, ex_is_less> memo;
    const auto it = memo.find(e);
    if (it != memo.end()) return it->second;
    std::string out;
    if (is_a<numeric>(e)) {
        out = text(ex_to<numeric>(e));
    } else if (is_a<symbol>(e)) {
        out = ex_to<symbol>(e).get_name();
    } else if (is_a<add>(e) || is_a<mul>(e)) {
        std::vector<std::string> parts;
        for (size_t i = 0; i < e.nops(); ++i) parts.push_back(canonical_text(e.op(i)));
        std::sort(parts.begin(), parts.end());
        out = is_a<add>(e) ? "(+" : "(*";
        for (const auto& p : parts) out += " " + p;
        out += ")";
    } else if (is_a<GiNaC::power>(e)) {
        out = "(^ " + canonical_text(e.op(0)) + " " + canonical_text(e.op(1)) + ")";
    } else {
        std::ostringstream o;
        o << e;
        out = "(? " + o.str() + ")";
    }
    memo.emplace(e, out);
    return out;
}

std::vector<ex> sorted_operands(const ex& e) {
    std::vector<std::pair<std::string, ex>> v;
    for (size_t i = 0; i < e.nops(); ++i) v.push_back({canonical_text(e.op(i)), e.op(i)});
    std::stable_sort(v.begin(), v.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<ex> out;
    for (auto& p : v) out.push_back(p.second);
    return out;
}

namespace {

std::string latex_symbol(const std::string& n) {
    static const std::map<std::string, std::string> special = {
        {"ct", "\\cos\\theta"},       {"st", "\\sin\\theta"},       {"thd", "\\dot\\theta"}, {"thdd", "\\ddot\\theta"},
        {"sxd", "\\dot s_x"},         {"syd", "\\dot s_y"},         {"sxdd", "\\ddot s_x"},  {"sydd", "\\ddot s_y"},
        {"wx", "\\omega_{1x}"},       {"wy", "\\omega_{1y}"},       {"wz", "\\omega_{1z}"},  {"wdx", "\\dot\\omega_{1x}"},
        {"wdy", "\\dot\\omega_{1y}"}, {"wdz", "\\dot\\omega_{1z}"}, {"pddx", "\\ddot p_x"},  {"pddy", "\\ddot p_y"},
        {"pddz", "\\ddot p_z"},       {"xith", "\\xi_\\theta"},     {"rho", "\\rho"},        {"cz", "c_z"}};
    const auto it = special.find(n);
    if (it != special.end()) return it->second;
    if (n.size() >= 2 && (n[0] == 'J' || n[0] == 's' || n[0] == 'v')) return n.substr(0, 1) + "_{" + n.substr(1) + "}";
    if (n.rfind("mu", 0) == 0) return "\\mu_{" + n.substr(2) + "}";
    if (n.size() == 3 && (n[0] == 'c' || n[0] == 'u' || n[0] == 'r' || n[0] == 'R'))
        return n.substr(0, 1) + "_{" + n.substr(1) + "}";
    if (n.size() == 2 && n[0] == 'N') return "N_{" + n.substr(1) + "}";
    return n;
}

}   // namespace

std::string latex_text(const ex& e) {
    if (is_a<numeric>(e)) {
        const numeric x = ex_to<numeric>(e);
        if (x.is_integer()) return text(x);
        return "\\frac{" + text(x.numer()) + "}{" + text(x.denom()) + "}";
    }
    if (is_a<symbol>(e)) return latex_symbol(ex_to<symbol>(e).get_name());
    if (is_a<add>(e)) {
        std::string s;
        for (const ex& t : sorted_operands(e)) {
            std::string term = latex_text(t);
            if (!s.empty() && !term.empty() && term[0] == '-')
                s += " - " + term.substr(1);
            else
                s += (s.empty() ? "" : " + ") + term;
        }
        return s;
    }
    if (is_a<mul>(e)) {
        std::string s, sign;
        for (const ex& f : sorted_operands(e)) {
            if (is_a<numeric>(f) && ex_to<numeric>(f).is_equal(-1)) {
                sign = "-";
                continue;
            }
            std::string t = latex_text(f);
            if (is_a<add>(f) || (is_a<numeric>(f) && ex_to<numeric>(f) < 0)) t = "\\left(" + t + "\\right)";
            s += (s.empty() ? "" : " ") + t;
        }
        return sign + s;
    }
    if (is_a<GiNaC::power>(e)) {
        std::string b = latex_text(e.op(0));
        if (!is_a<symbol>(e.op(0))) b = "\\left(" + b + "\\right)";
        const ex& x = e.op(1);
        if (x.is_equal(numeric(1, 2))) return "\\sqrt{" + latex_text(e.op(0)) + "}";
        if (x.is_equal(-1)) return "\\frac{1}{" + latex_text(e.op(0)) + "}";
        return b + "^{" + latex_text(x) + "}";
    }
    std::ostringstream o;
    o << e;
    return o.str();
}

std::string Emitter::temp(const std::string& rhs) {
    const std::string name = "t" + std::to_string(next_++);
    body_ << "    const double " << name << " = " << rhs << ";\n";
    return name;
}

std::string Emitter::emit_power(const ex& base, const numeric& e) {
    const std::string b = (*this)(base);
    if (e.is_integer()) {
        const long n = e.to_long();
        if (n == 0) return "1.0";
        std::string prod = b;
        for (long i = 1; i < std::labs(n); ++i) prod += " * " + b;
        if (n > 0) return std::labs(n) == 1 ? b : temp(prod);
        return temp("1.0 / (" + prod + ")");
    }
    const numeric twice = e * 2;
    if (!twice.is_integer()) throw std::invalid_argument("codegen: exponent " + text(e) + " is not a half-integer");
    const long n = twice.to_long();   // odd
    const std::string root = temp("std::sqrt(" + b + ")");
    std::string prod = root;
    for (long i = 0; i < (std::labs(n) - 1) / 2; ++i) prod += " * " + b;
    if (n > 0) return n == 1 ? root : temp(prod);
    return temp("1.0 / (" + prod + ")");
}

std::string Emitter::operator()(const ex& e) {
    if (is_a<numeric>(e)) return double_literal(ex_to<numeric>(e));
    if (is_a<symbol>(e)) {
        const auto it = inputs_.find(ex_to<symbol>(e).get_name());
        if (it == inputs_.end()) throw std::invalid_argument("codegen: no input for symbol " + ex_to<symbol>(e).get_name());
        return it->second;
    }
    const auto found = memo_.find(e);
    if (found != memo_.end()) return found->second;
    std::string out;
    if (is_a<add>(e)) {
        std::string s;
        for (const ex& t : sorted_operands(e)) {
            // a term with a negative numeric coefficient is written as a subtraction
            if (is_a<mul>(t) && is_a<numeric>(t.op(t.nops() - 1)) && ex_to<numeric>(t.op(t.nops() - 1)) < 0) {
                s += (s.empty() ? "-" : " - ") + (*this)(-t);
            } else if (is_a<numeric>(t) && ex_to<numeric>(t) < 0) {
                s += (s.empty() ? "-" : " - ") + double_literal(-ex_to<numeric>(t));
            } else {
                s += (s.empty() ? "" : " + ") + (*this)(t);
            }
        }
        out = temp(s);
    } else if (is_a<mul>(e)) {
        // Reciprocals are temporaries of their own (one division each, shared by every term that
        // needs them), so a product is only multiplications. A product is built left to right (as
        // C++ evaluates a * b * c) and every partial product is shared: a x u and a x v cost three
        // multiplications, not four.
        const std::vector<ex> fs = sorted_operands(e);
        std::string acc = (*this)(fs[0]);
        ex part = fs[0];
        for (std::size_t j = 1; j + 1 < fs.size(); ++j) {
            part = part * fs[j];
            const std::string f = (*this)(fs[j]);
            const auto known = memo_.find(part);
            if (known != memo_.end()) {
                acc = known->second;
            } else {
                acc = temp(acc + " * " + f);
                memo_[part] = acc;
            }
        }
        out = temp(acc + " * " + (*this)(fs.back()));
    } else if (is_a<GiNaC::power>(e)) {
        if (!is_a<numeric>(e.op(1))) throw std::invalid_argument("codegen: symbolic exponent");
        out = emit_power(e.op(0), ex_to<numeric>(e.op(1)));
    } else {
        std::ostringstream o;
        o << e;
        throw std::invalid_argument("codegen: cannot emit " + o.str());
    }
    memo_[e] = out;
    return out;
}

bool Staging::is_fast(const ex& f) const {
    const ex base = is_a<GiNaC::power>(f) ? f.op(0) : f;
    if (!is_a<symbol>(base)) return false;
    for (const ex& s : fast_)
        if (base.is_equal(s)) return true;
    return false;
}

ex Staging::operator()(const ex& e) {
    // Collect the coefficient of each monomial in the fast symbols.
    std::map<std::string, std::pair<ex, ex>> terms;   // canonical text of monomial -> (monomial, coefficient)
    const ex x = e.expand();
    auto take = [&](const ex& t) {
        ex mono = 1, coef = 1;
        if (is_a<mul>(t)) {
            for (size_t i = 0; i < t.nops(); ++i) (is_fast(t.op(i)) ? mono : coef) *= t.op(i);
        } else {
            (is_fast(t) ? mono : coef) *= t;
        }
        auto& slot = terms[canonical_text(mono)];
        slot.first = mono;
        slot.second += coef;
    };
    if (is_a<add>(x)) {
        for (size_t i = 0; i < x.nops(); ++i) take(x.op(i));
    } else if (!x.is_zero()) {
        take(x);
    }
    ex out = 0;
    for (auto& [text, mc] : terms) {
        const ex c = mc.second.expand();
        if (c.is_zero()) continue;
        if (is_a<numeric>(c)) {
            out += c * mc.first;
            continue;
        }
        const auto same = by_text_.find(canonical_text(c));
        if (same != by_text_.end()) {
            out += same->second * mc.first;
            continue;
        }
        const auto opposite = by_text_.find(canonical_text((-c).expand()));
        if (opposite != by_text_.end()) {
            out -= opposite->second * mc.first;
            continue;
        }
        const symbol s(array_ + std::to_string(slots_.size()));
        slots_.push_back({s, c});
        by_text_.emplace(canonical_text(c), s);
        out += s * mc.first;
    }
    return out;
}

void Staging::add_inputs(std::map<std::string, std::string>& inputs) const {
    for (std::size_t k = 0; k < slots_.size(); ++k) inputs[slots_[k].first.get_name()] = array_ + "[" + std::to_string(k) + "]";
}

void Emitter::assign(const std::string& target, const ex& e) {
    const std::string v = (*this)(e);
    body_ << "    " << target << " = " << v << ";\n";
}

}   // namespace plate::symbolic
