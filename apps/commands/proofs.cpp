// plate proofs: the numerical checks of Theorem 1 (contraction, Floquet, limit surfaces, A), JSON.
#include "commands.hpp"

#include "plate/output.hpp"
#include "theorem1.hpp"

#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace plate::cli {
namespace {

struct ProofsArgs : Options {
    int thin = 10000, thick = 1000, surfaces = 200, threads = 0;
    std::uint64_t seed = 1;
    std::string out = "-", wrong_model = "none";
    explicit ProofsArgs(CLI::App& app)
        : Options(app, "proofs", "the numerical checks of Theorem 1 (contraction, Floquet, limit surfaces, A), JSON",
                  "Numerical checks of Theorem 1 on seeded random parts and plate motions: Lyapunov contraction\n"
                  "of the relative twist against its integration-error bound, convergence, uniqueness of the\n"
                  "cycle from further initial twists, Floquet multipliers (N thin parts, default 10000; M thick\n"
                  "parts beyond the theorem, default 1000); limit surfaces of K thin parts (default 200); the\n"
                  "conditioning of A as a contact approaches the line of the other two (e/L = 1 ... 0).\n"
                  "Checks that hold by construction (max work and (40) on the limit surfaces) are listed apart.\n"
                  "Thin parts and limit surfaces carry verdicts; thick parts are beyond the theorem: their\n"
                  "checks are observations and never set the exit code.\n"
                  "JSON to stdout or --out FILE (written in every case); exit code 5 when a verdict fails (the\n"
                  "failed checks on stderr and under \"failed\" in the JSON), 0 when all pass.\n"
                  "--wrong-model runs the checks on a deliberately wrong model, to see them fail: pushing-friction\n"
                  "(mu -> -mu in the parts: the contraction fails), mu3 (contact 3's mu x 1.01 in the dynamics\n"
                  "under test: the tie to the limit surface fails).\n") {
        whole("--thin", thin, 0, 1000000, "thin parts");
        whole("--thick", thick, 0, 100000, "thick parts");
        whole("--surfaces", surfaces, 0, 20000, "limit surfaces");
        whole("--seed", seed, 0, 1L << 40, "the first seed");
        whole("--threads", threads, 0, 256, "threads (0: all cores)");
        text("--out", out, "FILE", "the JSON file (default: standard output)");
        text("--wrong-model", wrong_model, "none|pushing-friction|mu3", "a deliberately wrong model (default none)");
    }
};

// The checks that tie Theorem 1's to the dynamics (statics, limit-surface wrench).
nlohmann::json tie_json(const proofs::DynamicsTie& t) {
    return {{"samples", t.samples},
            {"worst_statics_over_mg", t.worst_statics},
            {"worst_wrench_over_mg", t.worst_wrench},
            {"tolerance", proofs::kTieTolerance},
            {"failure", t.failure},
            {"passed", t.passed()}};
}

// A double for the JSON (nlohmann writes infinities as null): a margin with nothing to measure.
nlohmann::json finite_or_null(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(); }

// Theorem 1's campaign (thin parts: a verdict) or the same beyond it (thick parts: observations).
nlohmann::json contraction_json(const proofs::ContractionSummary& s) {
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

nlohmann::json limit_surfaces_json(const proofs::LimitSurfaceCampaign& ls) {
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
            {"margin_tolerance", proofs::kSurfaceTolerance},
            {"dynamics_tie", tie_json(ls.tie)},
            {"passed", ls.passed()}};
}

// A contraction case as the MPI ranks send it: what summarize_contraction reads, doubles exact
// (nlohmann writes 17 digits; NaN and infinities as text).
nlohmann::json exact(double x) {
    if (std::isnan(x)) return "nan";
    if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
    return x;
}
double exact(const nlohmann::json& j) {
    if (j.is_number()) return j.get<double>();
    const std::string s = j.get<std::string>();
    return s == "nan" ? std::nan("") : s == "inf" ? HUGE_VAL : -HUGE_VAL;
}
std::string case_text(const proofs::ContractionCase& c) {
    return nlohmann::json{{"seed", c.seed},
                          {"valid", c.valid},
                          {"why_invalid", c.why_invalid},
                          {"monotone", c.monotone},
                          {"converged", c.converged},
                          {"unique", c.unique},
                          {"V0", exact(c.V0)},
                          {"V_end", exact(c.V_end)},
                          {"cycle_spread", exact(c.cycle_spread)},
                          {"starts_reached", c.starts_reached},
                          {"starts_left_model", c.starts_left_model},
                          {"spectral_radius", exact(c.spectral_radius)},
                          {"worst_increase", exact(c.worst_increase)},
                          {"rate", exact(c.rate)},
                          {"tie_samples", c.tie.samples},
                          {"tie_statics", exact(c.tie.worst_statics)},
                          {"tie_wrench", exact(c.tie.worst_wrench)},
                          {"tie_failure", c.tie.failure}}
        .dump();
}
proofs::ContractionCase case_from_text(const std::string& text) {
    const nlohmann::json j = nlohmann::json::parse(text);
    proofs::ContractionCase c;
    c.seed = j["seed"].get<std::uint64_t>();
    c.valid = j["valid"].get<bool>();
    c.why_invalid = j["why_invalid"].get<std::string>();
    c.monotone = j["monotone"].get<bool>();
    c.converged = j["converged"].get<bool>();
    c.unique = j["unique"].get<bool>();
    c.V0 = exact(j["V0"]);
    c.V_end = exact(j["V_end"]);
    c.cycle_spread = exact(j["cycle_spread"]);
    c.starts_reached = j["starts_reached"].get<int>();
    c.starts_left_model = j["starts_left_model"].get<int>();
    c.spectral_radius = exact(j["spectral_radius"]);
    c.worst_increase = exact(j["worst_increase"]);
    c.rate = exact(j["rate"]);
    c.tie.samples = j["tie_samples"].get<int>();
    c.tie.worst_statics = exact(j["tie_statics"]);
    c.tie.worst_wrench = exact(j["tie_wrench"]);
    c.tie.failure = j["tie_failure"].get<std::string>();
    return c;
}

// --wrong-model: a change to the parts (contraction) and to the dynamics under test (ties).
struct WrongModel {
    std::function<void(Scene&)> modify;
    proofs::DynamicsUnderTest dynamics;
};
WrongModel wrong_model(const std::string& name) {
    WrongModel w;
    if (name == "pushing-friction") {
        w.modify = [](Scene& sc) { sc.part.mu = -sc.part.mu; };
    } else if (name == "mu3") {
        w.dynamics = [](const Scene& sc, const Vec3& q, const Vec3& qd, const PlateState& ps, Vec3& qdd, Vec3& n) {
            Scene wrong = sc;
            wrong.part.mu[2] *= 1.01;
            proofs::production_dynamics()(wrong, q, qd, ps, qdd, n);
        };
    } else if (name != "none") {
        throw UsageError("--wrong-model: expected none, pushing-friction or mu3, not '" + name + "'");
    }
    return w;
}

int cmd_proofs(const ProofsArgs& a, Io& cio) {
    const std::uint64_t seed = a.seed;
    const int threads = a.threads;
    const WrongModel wrong = wrong_model(a.wrong_model);
    // Under mpirun the contraction cases (the bulk of the work) are shared over the ranks, one at a
    // time; the summary is the single-process one to the bit (but for its wall time). Rank 0 alone
    // checks the limit surfaces and A and writes the output.
    sweep::Farm* const farm = launched_farm(cio, threads);
    const bool root = !farm || farm->root();
    nlohmann::json j;
    j["seed"] = seed;
    auto campaign = [&](bool thin, int n, std::uint64_t s0) {
        proofs::ContractionOptions o;
        o.cases = n;
        o.seed = s0;
        o.thin = thin;
        o.threads = threads;
        o.modify = wrong.modify;
        o.dynamics = wrong.dynamics;
        ProgressPrinter prog{thin ? "proofs, thin parts" : "proofs, thick parts", 10.0};
        if (!root) prog.to = nullptr;
        o.progress = prog;
        if (!farm) return contraction_json(proofs::check_contraction(o));
        const auto t0 = std::chrono::steady_clock::now();
        std::vector<proofs::ContractionCase> cases(static_cast<std::size_t>(n));
        std::vector<int> todo;
        for (int k = 0; root && k < n; ++k) todo.push_back(k);
        int done = 0;
        farm->run(
            todo, [&](int k) { return case_text(proofs::contraction_random_case(o, k)); },
            [&](int k, const std::string& text) {
                cases[static_cast<std::size_t>(k)] = case_from_text(text);
                prog(++done, n);
            });
        if (!root) return nlohmann::json();
        return contraction_json(proofs::summarize_contraction(
            o, std::move(cases), std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()));
    };
    j["thin"] = campaign(true, a.thin, seed);
    j["thick"] = campaign(false, a.thick, seed + 50'000'000);
    if (!root) return 0;
    if (farm) j["mpi"] = farm->describe();
    // Limit surfaces of random thin parts at random plate times.
    const proofs::LimitSurfaceCampaign ls = proofs::check_limit_surfaces(a.surfaces, seed, wrong.dynamics);
    j["limit_surfaces"] = limit_surfaces_json(ls);
    // A's conditioning toward collinear contacts (dimensionless A, 20 sampled states per part).
    j["conditioning_of_A"] = nlohmann::json::array();
    for (const auto& cs : proofs::collinear_scenes({1.0, 0.1, 0.01, 0.001, 0.0})) {
        const proofs::Conditioning c = proofs::condition_of_A(cs.scene, 20, seed);
        j["conditioning_of_A"].push_back(
            {{"e_over_L", cs.e_over_L}, {"max_condition", c.max_condition}, {"min_singular_over_max", c.min_singular}});
    }
    // The verdicts: Theorem 1 on thin parts and the limit surfaces, each when it ran.
    nlohmann::json failed = nlohmann::json::array();
    if (a.thin > 0 && !j["thin"]["passed"].get<bool>()) failed.push_back("thin");
    if (a.surfaces > 0 && !ls.passed()) failed.push_back("limit_surfaces");
    if (a.wrong_model != "none") j["wrong_model"] = a.wrong_model;
    j["failed"] = failed;
    j["passed"] = failed.empty();
    write_file_atomic(
        a.out, [&](std::ostream& out) { out << j.dump(2) << "\n"; }, cio.out);
    if (failed.empty()) return 0;
    cio.err << "plate proofs: failed: " << failed.dump() << " (see \"passed\" and the counter-examples in the JSON)" << std::endl;
    return 5;
}

}   // namespace

Command add_proofs(CLI::App& app) { return make_command<ProofsArgs>(app, cmd_proofs); }

}   // namespace plate::cli
