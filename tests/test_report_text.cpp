// The report's sentences that state a result are computed from the run's data (issue 15, point 4):
// rendered from deliberately failing counts, they change.
#include "report.hpp"

#include <catch2/catch.hpp>

using plate::report::observation1_sentence;

TEST_CASE("report: the Observation 1 sentence follows the campaign's counts", "[report][text]") {
    const std::string all = observation1_sentence(1000, 1000, 1000, 1000);
    CHECK(all.find("every cycle found was unique and attracting") != std::string::npos);
    CHECK(all.find("1000 cases") != std::string::npos);
    // One case reaching another cycle from other initial twists: the claim is gone, the count is said.
    const std::string two = observation1_sentence(1000, 1000, 999, 1000);
    CHECK(two.find("every cycle found") == std::string::npos);
    CHECK(two.find("1 reached another cycle") != std::string::npos);
    // Not attracting, or not converging, are said too.
    CHECK(observation1_sentence(1000, 1000, 1000, 997).find("3 had a Floquet multiplier") != std::string::npos);
    CHECK(observation1_sentence(1000, 990, 990, 990).find("10 reached no cycle") != std::string::npos);
    CHECK(observation1_sentence(0, 0, 0, 0).find("says nothing") != std::string::npos);
}
