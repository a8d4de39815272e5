// `plate proofs` as JSON, for the command line and Python alike: Theorem 1's contraction on thin parts
// (a verdict), the same beyond it on thick parts (observations), limit surfaces (a verdict) and A's
// conditioning toward collinear contacts, with the failed verdicts named.
#pragma once

#include "theorem1.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <functional>
#include <string>

namespace plate::proofs {

// A deliberately wrong model, to see the checks fail: "pushing-friction" (mu -> -mu in the parts: the
// contraction fails), "mu3" (contact 3's mu x 1.01 in the dynamics under test: the tie to the limit
// surface fails), "none". Throws std::invalid_argument for another name.
struct WrongModel {
    std::string name = "none";
    std::function<void(Scene&)> modify;
    DynamicsUnderTest dynamics;
};
WrongModel wrong_model(const std::string& name);

struct ProofsOptions {
    int thin = 10000, thick = 1000, surfaces = 200;   // thin parts, thick parts, limit surfaces
    std::uint64_t seed = 1;                           // the first seed (thick parts: seed + 5e7)
    int threads = 0;                                  // 0: all cores
    WrongModel wrong;
};

// The contraction campaign's options: thin or thick parts of `o` (progress left unset).
ContractionOptions contraction_options(const ProofsOptions& o, bool thin);
// A contraction campaign's JSON: its counts, signed margins, counter-example seeds; thin parts with
// their tie to the dynamics and "passed", thick parts with "observation" instead.
nlohmann::json contraction_json(const ContractionSummary& s);
// The whole JSON from the two contraction campaigns' (computed however the caller shares the work):
// "seed", "thin", "thick", "limit_surfaces", "conditioning_of_A", "failed" (the verdicts that failed
// among those that ran) and "passed".
nlohmann::json proofs_json(const ProofsOptions& o, nlohmann::json thin, nlohmann::json thick);

}   // namespace plate::proofs
