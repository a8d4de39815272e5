// The report's sentences that state a result are computed from the run's data (issue 15, point 4):
// rendered from deliberately failing counts, they change.
#include "report.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <stdexcept>

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

TEST_CASE("report: the collinear-contacts sentence follows the conditioning and the wrench gaps", "[report][text]") {
    using plate::report::collinear_sentence;
    // As measured (proofs JSON): cond(A) 3.0, 20, 199, 1995 for e/L = 1 .. 1e-3; gaps shrinking ~10x.
    const std::string good = collinear_sentence({3.0, 20, 199, 1995}, {0.5, 0.05, 0.005, 0.0005}, 1e-17);
    CHECK(good.find("grows at least") != std::string::npos);
    CHECK(good.find("singular at e = 0") != std::string::npos);
    CHECK(good.find("develops a vertex") != std::string::npos);
    // Data that do not show it: the claims are gone.
    const std::string flat = collinear_sentence({3.0, 4.0, 5.0, 6.0}, {0.5, 0.4, 0.3, 0.2}, 0.1);
    CHECK(flat.find("does not grow like L/e") != std::string::npos);
    CHECK(flat.find("develops a vertex") == std::string::npos);
    CHECK(flat.find("not singular") != std::string::npos);
}

TEST_CASE("report: user text reaching the page is escaped (a script in a scene name stays text)", "[report][text]") {
    const std::string h = plate::report::scene_heading("Fig. 6: rotation", "<script>alert(\"x\")</script>", "a'b.json");
    CHECK(h.find("<script>") == std::string::npos);
    CHECK(h.find("&lt;script&gt;alert(&quot;x&quot;)&lt;/script&gt;") != std::string::npos);
    CHECK(h.find("a&#39;b.json") != std::string::npos);
    CHECK(h.rfind("<h3>Fig. 6: rotation (<code>", 0) == 0);
}

TEST_CASE("write_report rejects an unknown section before it touches the report's folder", "[report][text]") {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / "plate-report-unknown-section";
    fs::remove_all(dir);
    plate::report::ReportOptions o;
    o.out = dir.string();
    o.source_dir = PLATE_SOURCE_DIR;
    o.sections = {"fig3", "figure4"};
    CHECK_THROWS_AS(plate::report::write_report(o), std::invalid_argument);
    CHECK_FALSE(fs::exists(dir));
    // Every section the report writes is accepted by name, and a wrong name is answered with all of them,
    // in the report's order (what `plate report --help` lists).
    CHECK_NOTHROW(plate::report::check_sections(plate::report::report_section_names()));
    std::string message;
    try {
        plate::report::check_sections({"figure4"});
    } catch (const std::invalid_argument& e) {
        message = e.what();
    }
    CHECK(message == "'figure4' is not a section (derivation, kernels, proofs, fig3, fields, design, orient, fixed-point)");
}

TEST_CASE("report: the captions that state a result follow this run's measurements", "[report][text]") {
    using namespace plate::report;
    // Fig. V: as measured by the quick report, |xi_rel| falls to at most 0.71 per period.
    CHECK(contraction_caption(5, 0.71).find("contract geometrically") != std::string::npos);
    const std::string grew = contraction_caption(5, 1.02);
    CHECK(grew.find("do not all contract geometrically") != std::string::npos);
    CHECK(grew.find("1.02") != std::string::npos);
    CHECK(contraction_caption(0, 0).find("none shown") != std::string::npos);
    // Fig. 3: as measured, the two starts 2.7 v_ref apart end 5.4e-13 apart after ten periods.
    const std::string met = fig3_caption(10, 2.7, 5.4e-13);
    CHECK(met.find("converging to one limit cycle") != std::string::npos);
    CHECK(met.find("10 periods") != std::string::npos);
    const std::string apart = fig3_caption(10, 2.7, 0.5);   // two cycles, or not yet converged
    CHECK(apart.find("not shown converging") != std::string::npos);
    // A design's runs: all within the distance and verified, or said otherwise with the failure.
    CHECK(design_runs_caption(6, 6, 0.005, true, "").find("6 of 6 end within 5 mm of the target, converging on the target") !=
          std::string::npos);
    const std::string failed = design_runs_caption(5, 6, 0.005, false, "a full-dynamics run ended 0.05 m from the <target>");
    CHECK(failed.find("converging on the target") == std::string::npos);
    CHECK(failed.find("5 of 6") != std::string::npos);
    CHECK(failed.find("the design failed verification: a full-dynamics run ended 0.05 m from the &lt;target&gt;") !=
          std::string::npos);
    CHECK(design_runs_caption(6, 6, 0.005, false, "the hold").find("converging on the target") == std::string::npos);
}
