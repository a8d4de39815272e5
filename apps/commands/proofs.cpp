// plate proofs: the numerical checks of Theorem 1 (contraction, Floquet, limit surfaces, A), JSON.
#include "commands.hpp"

#include "plate/output.hpp"
#include "theorem1.hpp"

#include <chrono>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace plate::cli {
namespace {

struct ProofsArgs : Options {
    int thin = 10000, thick = 1000, surfaces = 200, threads = 0;
    std::uint64_t seed = 1;
    std::string out = "-";
    explicit ProofsArgs(CLI::App& app)
        : Options(app, "proofs", "the numerical checks of Theorem 1 (contraction, Floquet, limit surfaces, A), JSON",
                  "Numerical checks of Theorem 1 on seeded random parts and plate motions: Lyapunov contraction\n"
                  "of the relative twist against its integration-error bound, convergence, uniqueness of the\n"
                  "cycle from further initial twists, Floquet multipliers (N thin parts, default 10000; M thick\n"
                  "parts beyond the theorem, default 1000); limit surfaces of K thin parts (default 200); the\n"
                  "conditioning of A as a contact approaches the line of the other two (e/L = 1 ... 0).\n"
                  "JSON to stdout or --out FILE; exit code 0 even when a check fails.\n") {
        whole("--thin", thin, 0, 1000000, "thin parts");
        whole("--thick", thick, 0, 100000, "thick parts");
        whole("--surfaces", surfaces, 0, 20000, "limit surfaces");
        whole("--seed", seed, 0, 1L << 40, "the first seed");
        whole("--threads", threads, 0, 256, "threads (0: all cores)");
        text("--out", out, "FILE", "the JSON file (default: standard output)");
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

nlohmann::json contraction_json(const proofs::ContractionSummary& s) {
    nlohmann::json j;
    j["cases"] = s.cases;
    j["valid"] = s.valid;
    j["monotone"] = s.monotone;
    j["converged"] = s.converged;
    j["unique_cycle"] = s.unique;
    j["floquet_below_one"] = s.floquet_below_one;
    j["worst_increase_over_bound"] = s.worst_increase;
    j["worst_seed"] = s.worst_seed;
    j["median_rate_per_period"] = s.median_rate;
    j["max_rate_per_period"] = s.max_rate;
    j["max_floquet_radius"] = s.max_spectral_radius;
    j["counterexample_seeds"] = s.counterexamples;
    j["seconds"] = s.seconds;
    j["dynamics_tie"] = tie_json(s.tie);
    j["passed"] = s.passed();
    nlohmann::json invalid = nlohmann::json::object();
    for (const auto& c : s.details)
        if (!c.why_invalid.empty()) invalid[c.why_invalid] = invalid.value(c.why_invalid, 0) + 1;
    j["not_in_model"] = invalid;
    return j;
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
    c.spectral_radius = exact(j["spectral_radius"]);
    c.worst_increase = exact(j["worst_increase"]);
    c.rate = exact(j["rate"]);
    c.tie.samples = j["tie_samples"].get<int>();
    c.tie.worst_statics = exact(j["tie_statics"]);
    c.tie.worst_wrench = exact(j["tie_wrench"]);
    c.tie.failure = j["tie_failure"].get<std::string>();
    return c;
}

int cmd_proofs(const ProofsArgs& a, Io& cio) {
    const std::uint64_t seed = a.seed;
    const int threads = a.threads;
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
    const proofs::LimitSurfaceCampaign ls = proofs::check_limit_surfaces(a.surfaces, seed);
    j["limit_surfaces"] = {{"parts", ls.parts},
                           {"directions", 300},
                           {"convex_and_normal", ls.convex},
                           {"strictly_convex", ls.strict},
                           {"worst_max_work_violation", ls.worst_max_work},
                           {"worst_monotonicity_violation", ls.worst_monotonicity},
                           {"min_separation", ls.min_separation},
                           {"min_strict_margin", ls.min_strict_margin},
                           {"on_friction_set", ls.on_set},
                           {"worst_support_violation", ls.worst_support},
                           {"worst_outside_violation", ls.worst_outside},
                           {"dynamics_tie", tie_json(ls.tie)},
                           {"passed", ls.passed()}};
    // A's conditioning toward collinear contacts (dimensionless A, 20 sampled states per part).
    j["conditioning_of_A"] = nlohmann::json::array();
    for (const auto& cs : proofs::collinear_scenes({1.0, 0.1, 0.01, 0.001, 0.0})) {
        const proofs::Conditioning c = proofs::condition_of_A(cs.scene, 20, seed);
        j["conditioning_of_A"].push_back(
            {{"e_over_L", cs.e_over_L}, {"max_condition", c.max_condition}, {"min_singular_over_max", c.min_singular}});
    }
    write_file_atomic(
        a.out, [&](std::ostream& out) { out << j.dump(2) << "\n"; }, cio.out);
    return 0;
}

}   // namespace

Command add_proofs(CLI::App& app) { return make_command<ProofsArgs>(app, cmd_proofs); }

}   // namespace plate::cli
