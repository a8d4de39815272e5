// C++ code generation from GiNaC expressions, with common subexpressions shared.
//
// Every distinct non-trivial subexpression (by GiNaC's structural equality) becomes one
// `const double tN = ...;`, so a subexpression used by several outputs is computed once.
// Powers are written out: integer exponents as products (negative ones as a reciprocal),
// half-integer exponents through std::sqrt. Any other exponent, or a function other than
// those, is an error -- the GiNaC 1.8 C printer's silent loss of reciprocals with inexact
// exponents cannot happen here.
#pragma once

#include <ginac/ginac.h>

#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace plate::symbolic {

class Emitter {
public:
    // inputs: symbol name -> C++ expression that reads it (e.g. "in.m").
    explicit Emitter(std::map<std::string, std::string> inputs) : inputs_(std::move(inputs)) {}
    // Emits what e needs and returns a C++ expression for its value.
    std::string operator()(const GiNaC::ex& e);
    // Assigns e to `target` (e.g. "out[3]").
    void assign(const std::string& target, const GiNaC::ex& e);
    // Computes e once and lets later expressions use it through the symbol named `name`.
    void bind(const std::string& name, const GiNaC::ex& e) { inputs_[name] = (*this)(e); }
    std::string code() const { return body_.str(); }
    int temporaries() const { return next_; }

private:
    std::string temp(const std::string& rhs);
    std::string emit_power(const GiNaC::ex& base, const GiNaC::numeric& exponent);
    std::map<std::string, std::string> inputs_;
    std::map<GiNaC::ex, std::string, GiNaC::ex_is_less> memo_;
    std::ostringstream body_;
    int next_ = 0;
};

// Staged evaluation for a frozen configuration (reduced U-dynamics (35)). An expression that is a
// polynomial in the `fast` symbols (those that change at every evaluation: unit slip directions,
// plate acceleration, normal forces) is rewritten as a sum of slot * monomial; each slot is one
// coefficient, an expression in the slow symbols only (part, configuration), computed once per
// configuration by a kernel of its own. Equal coefficients (up to sign) share one slot.
class Staging {
public:
    Staging(std::vector<GiNaC::ex> fast, std::string array) : fast_(std::move(fast)), array_(std::move(array)) {}
    GiNaC::ex operator()(const GiNaC::ex& e);
    const std::vector<std::pair<GiNaC::symbol, GiNaC::ex>>& slots() const { return slots_; }
    // slot symbol names -> "array[k]", for an Emitter's inputs
    void add_inputs(std::map<std::string, std::string>& inputs) const;

private:
    bool is_fast(const GiNaC::ex& factor) const;
    std::vector<GiNaC::ex> fast_;
    std::string array_;
    std::vector<std::pair<GiNaC::symbol, GiNaC::ex>> slots_;
    std::map<std::string, GiNaC::ex> by_text_;   // canonical text of a coefficient -> its slot symbol
};

std::string double_literal(const GiNaC::numeric& x);

// GiNaC orders the terms of sums and products by hash values seeded with type-info addresses,
// which move from run to run (ASLR). These give a run-independent order: operands sorted by
// their canonical text, itself built from sorted operands.
std::string canonical_text(const GiNaC::ex& e);
std::vector<GiNaC::ex> sorted_operands(const GiNaC::ex& e);
// LaTeX with the canonical order (symbols printed by name, u1x -> u_{1x}, ...).
std::string latex_text(const GiNaC::ex& e);

}   // namespace plate::symbolic
