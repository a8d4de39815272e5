// plate proofs: the numerical checks of Theorem 1 (contraction, Floquet, limit surfaces, A), JSON.
#include "commands.hpp"

#include "plate/output.hpp"
#include "proofs_json.hpp"

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

int cmd_proofs(const ProofsArgs& a, Io& cio) {
    proofs::ProofsOptions po;
    po.thin = a.thin;
    po.thick = a.thick;
    po.surfaces = a.surfaces;
    po.seed = a.seed;
    po.threads = a.threads;
    try {
        po.wrong = proofs::wrong_model(a.wrong_model);
    } catch (const std::invalid_argument& e) {
        throw UsageError(std::string("--wrong-model: ") + e.what());
    }
    // Under mpirun the contraction cases (the bulk of the work) are shared over the ranks, one at a
    // time; the summary is the single-process one to the bit (but for its wall time). Rank 0 alone
    // checks the limit surfaces and A and writes the output.
    sweep::Farm* const farm = launched_farm(cio, po.threads);
    const bool root = !farm || farm->root();
    auto campaign = [&](bool thin) {
        proofs::ContractionOptions o = proofs::contraction_options(po, thin);
        ProgressPrinter prog{thin ? "proofs, thin parts" : "proofs, thick parts", 10.0};
        if (!root) prog.to = nullptr;
        o.progress = prog;
        if (!farm) return proofs::contraction_json(proofs::check_contraction(o));
        const auto t0 = std::chrono::steady_clock::now();
        const int n = o.cases;
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
        return proofs::contraction_json(proofs::summarize_contraction(
            o, std::move(cases), std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count()));
    };
    nlohmann::json thin = campaign(true), thick = campaign(false);
    if (!root) return 0;
    nlohmann::json j = proofs::proofs_json(po, std::move(thin), std::move(thick));
    if (farm) j["mpi"] = farm->describe();
    const nlohmann::json failed = j["failed"];
    write_file_atomic(
        a.out, [&](std::ostream& out) { out << j.dump(2) << "\n"; }, cio.out);
    if (failed.empty()) return 0;
    cio.err << "plate proofs: failed: " << failed.dump() << " (see \"passed\" and the counter-examples in the JSON)" << std::endl;
    return 5;
}

}   // namespace

Command add_proofs(CLI::App& app) { return make_command<ProofsArgs>(app, cmd_proofs); }

}   // namespace plate::cli
