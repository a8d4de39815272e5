#include "proofs_json.hpp"

#include <cmath>
#include <stdexcept>
#include <utility>

namespace plate::proofs {

namespace {

// The checks that tie Theorem 1's to the dynamics (statics, limit-surface wrench).
nlohmann::json tie_json(const DynamicsTie& t) {
    return {{"samples", t.samples},
            {"worst_statics_over_mg", t.worst_statics},
            {"worst_wrench_over_mg", t.worst_wrench},
            {"tolerance", kTieTolerance},
            {"failure", t.failure},
            {"passed", t.passed()}};
}

// A double for the JSON (nlohmann writes infinities as null): a margin with nothing to measure.
nlohmann::json finite_or_null(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(); }

nlohmann::json limit_surfaces_json(const LimitSurfaceCampaign& ls) {
    return {{"parts", ls.parts},
            {"directions", 300},
            {"holds_by_construction",
             {{"why",
               "max work and (40) hold for any wrench -sum c_i G_i v_i/|v_i| with c_i >= 0 (Cauchy-Schwarz): "
               "they fail only for a kernel not of that form, never for a wrong mu or lever arm"},
              {"convex_and_normal", ls.convex},
              {"max_work_margin", ls.max_work_margin},
              {"monotonicity_margin", ls.monotonicity_margin}}},
            {"strictly_convex", ls.strict},
            {"min_separation", ls.min_separation},
            {"min_strict_margin", ls.min_strict_margin},
            {"on_friction_set", ls.on_set},
            {"support_margin", ls.support_margin},
            {"outside_margin", ls.outside_margin},
            {"margin_tolerance", kSurfaceTolerance},
            {"dynamics_tie", tie_json(ls.tie)},
            {"passed", ls.passed()}};
}

}   // namespace

WrongModel wrong_model(const std::string& name) {
    WrongModel w;
    w.name = name;
    if (name == "pushing-friction") {
        w.modify = [](Scene& sc) { sc.part.mu = -sc.part.mu; };
    } else if (name == "mu3") {
        w.dynamics = [](const Scene& sc, const Vec3& q, const Vec3& qd, const PlateState& ps, Vec3& qdd, Vec3& n) {
            Scene wrong = sc;
            wrong.part.mu[2] *= 1.01;
            production_dynamics()(wrong, q, qd, ps, qdd, n);
        };
    } else if (name != "none") {
        throw std::invalid_argument("expected none, pushing-friction or mu3, not '" + name + "'");
    }
    return w;
}

ContractionOptions contraction_options(const ProofsOptions& o, bool thin) {
    ContractionOptions c;
    c.cases = thin ? o.thin : o.thick;
    c.seed = thin ? o.seed : o.seed + 50'000'000;
    c.thin = thin;
    c.threads = o.threads;
    c.modify = o.wrong.modify;
    c.dynamics = o.wrong.dynamics;
    return c;
}

// Theorem 1's campaign (thin parts: a verdict) or the same beyond it (thick parts: observations).
nlohmann::json contraction_json(const ContractionSummary& s) {
    nlohmann::json j;
    j["cases"] = s.cases;
    j["valid"] = s.valid;
    j["monotone"] = s.monotone;
    j["converged"] = s.converged;
    j["unique_cycle"] = s.unique;
    j["floquet_below_one"] = s.floquet_below_one;
    // How close each check came (signed; each with its pass bound).
    j["worst_increase_over_bound"] = finite_or_null(s.worst_increase);   // <= 1 passes; < 0: V fell at every step
    j["worst_seed"] = s.worst_seed;
    j["worst_V_end_over_V0"] = s.worst_V_end;                                // <= 1e-12 passes
    j["max_cycle_spread_over_v_ref"] = finite_or_null(s.max_cycle_spread);   // < 1e-6 passes (null: a start found no cycle)
    j["further_starts_left_model"] = s.starts_left_model;
    j["median_rate_per_period"] = s.median_rate;
    j["max_rate_per_period"] = s.max_rate;
    j["max_floquet_radius"] = s.max_spectral_radius;   // < 1 passes
    j["counterexample_seeds"] = s.counterexamples;
    j["seconds"] = s.seconds;
    if (s.tie_required) {
        j["dynamics_tie"] = tie_json(s.tie);
        j["passed"] = s.passed();
    } else {
        j["observation"] =
            "beyond Theorem 1: V may rise (the normal forces depend on the twist); no verdict, no tie to "
            "the dynamics (the statics it solves holds for thin parts only)";
    }
    nlohmann::json invalid = nlohmann::json::object();
    for (const auto& c : s.details)
        if (!c.why_invalid.empty()) invalid[c.why_invalid] = invalid.value(c.why_invalid, 0) + 1;
    j["not_in_model"] = invalid;
    return j;
}

nlohmann::json proofs_json(const ProofsOptions& o, nlohmann::json thin, nlohmann::json thick) {
    nlohmann::json j;
    j["seed"] = o.seed;
    j["thin"] = std::move(thin);
    j["thick"] = std::move(thick);
    // Limit surfaces of random thin parts at random plate times.
    const LimitSurfaceCampaign ls = check_limit_surfaces(o.surfaces, o.seed, o.wrong.dynamics);
    j["limit_surfaces"] = limit_surfaces_json(ls);
    // A's conditioning toward collinear contacts (dimensionless A, 20 sampled states per part).
    j["conditioning_of_A"] = nlohmann::json::array();
    for (const auto& cs : collinear_scenes({1.0, 0.1, 0.01, 0.001, 0.0})) {
        const Conditioning c = condition_of_A(cs.scene, 20, o.seed);
        j["conditioning_of_A"].push_back(
            {{"e_over_L", cs.e_over_L}, {"max_condition", c.max_condition}, {"min_singular_over_max", c.min_singular}});
    }
    // The verdicts: Theorem 1 on thin parts and the limit surfaces, each when it ran.
    nlohmann::json failed = nlohmann::json::array();
    if (o.thin > 0 && !j["thin"]["passed"].get<bool>()) failed.push_back("thin");
    if (o.surfaces > 0 && !ls.passed()) failed.push_back("limit_surfaces");
    if (o.wrong.name != "none") j["wrong_model"] = o.wrong.name;
    j["failed"] = failed;
    j["passed"] = failed.empty();
    return j;
}

}   // namespace plate::proofs
