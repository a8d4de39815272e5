// The report's sentences that state a result are computed from the run's data (issue 15, point 4):
// rendered from deliberately failing counts, they change.
#include "report.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <string>
#include <stdexcept>
#include <vector>

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
    CHECK(message ==
          "'figure4' is not a section (derivation, kernels, proofs, fig3, fields, design, orient, fixed-point, robustness, "
          "identify, control)");
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

TEST_CASE("report: the robustness section's 95 % ellipse is the predicted covariance's", "[report][text]") {
    using plate::report::covariance_ellipse;
    using plate::report::normal_ellipse_factor;
    // Closed form: a 2-D standard normal's squared radius is chi-square with 2 degrees of freedom,
    // P(|z| <= k) = 1 - exp(-k^2 / 2), so 95 % is held within k = sqrt(-2 ln 0.05) = 2.4477468306808.
    CHECK(normal_ellipse_factor(0.95) == Approx(2.4477468306808).epsilon(1e-12));
    CHECK(1 - std::exp(-normal_ellipse_factor(0.95) * normal_ellipse_factor(0.95) / 2) == Approx(0.95).epsilon(1e-12));
    // Covariance diag(a^2, b^2): semi-axes 2.4477 a along x and 2.4477 b along y (the extremes of the
    // points; 96 points include the axes' ends).
    const double a = 2e-3, b = 5e-4;
    const std::vector<plate::Vec2> e = covariance_ellipse(Eigen::Vector2d(a * a, b * b).asDiagonal().toDenseMatrix());
    double xmax = 0, ymax = 0;
    for (const plate::Vec2& p : e) {
        xmax = std::max(xmax, std::abs(p.x()));
        ymax = std::max(ymax, std::abs(p.y()));
    }
    CHECK(xmax == Approx(2.4477468306808 * a).epsilon(1e-12));
    CHECK(ymax == Approx(2.4477468306808 * b).epsilon(1e-12));
    CHECK((e.front() - e.back()).norm() < 1e-15);   // closed
    // A correlated covariance: every point on x^T C^-1 x = k^2 (round-off: 1e-15 measured, 1e-12 allowed).
    Eigen::Matrix2d C;
    C << 4e-6, -1.5e-6, -1.5e-6, 1e-6;
    for (const plate::Vec2& p : covariance_ellipse(C))
        CHECK(p.dot(C.inverse() * p) == Approx(2.4477468306808 * 2.4477468306808).epsilon(1e-12));
}

TEST_CASE("report: the robustness sentence says where the response is linear from the run's figures", "[report][text]") {
    using namespace plate::report;
    // As docs/decisions/uncertainty.md measured fig4's design (200 draws): radius 3.28 mm against 3.22 mm
    // first order, angle 0.247 rad against 0.368 rad; median 16 %, 33 of 168 draws over 30 %.
    LinearityFigures f;
    f.rigid = true;
    f.matched = 168;
    f.nonlinear = 33;
    f.error_median = 0.16;
    f.error_max = 2.1;
    f.radius_mc = 3.28e-3;
    f.radius_first = 3.22e-3;
    f.angle_mc = 0.247;
    f.angle_first = 0.368;
    const std::string fig4 = linearity_sentence(f);
    CHECK(fig4.find("linear in position, not in angle") != std::string::npos);
    CHECK(fig4.find("3.22 mm against 3.28 mm") != std::string::npos);
    CHECK(fig4.find("0.368 rad against 0.247 rad") != std::string::npos);
    CHECK(fig4.find("33 of 168 matched draws are more than 30 % off") != std::string::npos);
    CHECK(fig4.find("median draw's fixed point is 16 %") != std::string::npos);
    f.angle_first = 0.26;
    CHECK(linearity_sentence(f).find("linear in position and in angle") != std::string::npos);
    f.radius_first = 1e-3;   // first order a third of the Monte Carlo radius
    CHECK(linearity_sentence(f).find("linear in angle, not in position") != std::string::npos);
    f.rigid = false;
    CHECK(linearity_sentence(f).find("not linear in position") != std::string::npos);
    CHECK(linearity_sentence(f).find("angle") == std::string::npos);   // (a point part has none)
    f.matched = 0;
    CHECK(linearity_sentence(f).find("nothing to compare") != std::string::npos);
}

TEST_CASE("the report copies a built playground beside its page and links it, or says how to build one", "[report][text]") {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / "plate-report-playground";
    const fs::path site = fs::temp_directory_path() / "plate-report-playground-site";
    fs::remove_all(dir);
    fs::remove_all(site);
    fs::create_directories(site / "scenes");
    std::ofstream(site / "index.html") << "<!DOCTYPE html><title>a playground</title>";
    std::ofstream(site / "scenes" / "fig1_point.json") << "{}";
    plate::report::ReportOptions o;
    o.out = dir.string();
    o.source_dir = PLATE_SOURCE_DIR;
    o.sections = {"fig3"};
    const auto page = [&] {
        std::ifstream in(dir / "index.html");
        return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    };
    plate::report::write_report(o);   // no playground given
    CHECK(page().find("Not built. To add it: <code>cmake --build build --target web</code>") != std::string::npos);
    CHECK_FALSE(fs::exists(dir / "playground"));
    o.playground = site.string();
    plate::report::write_report(o);
    CHECK(page().find("<a href=\"playground/index.html\">") != std::string::npos);
    CHECK(fs::exists(dir / "playground" / "index.html"));
    CHECK(fs::exists(dir / "playground" / "scenes" / "fig1_point.json"));
    // Every section heading of the page is in its contents list (the playground's included), and the verdict
    // line counts in English ("1 check", "2 checks").
    const std::string text = page();
    for (std::size_t at = text.find("<h2 id=\""); at != std::string::npos; at = text.find("<h2 id=\"", at + 1)) {
        const std::size_t from = at + 8;
        const std::string id = text.substr(from, text.find('"', from) - from);
        if (id != "contents") CHECK(text.find("<li><a href=\"#" + id + "\">") != std::string::npos);
    }
    CHECK(text.find("<li><a href=\"#playground\">") != std::string::npos);
    const std::regex count(R"((\d+) (checks?) stated in this run)");
    std::smatch m;
    REQUIRE(std::regex_search(text, m, count));
    CHECK((m[1] == "1") == (m[2] == "check"));
    o.playground = (site / "missing").string();   // a folder without a site: as none
    plate::report::write_report(o);
    CHECK(page().find("Not built.") != std::string::npos);
    CHECK_FALSE(fs::exists(dir / "playground"));   // (the older copy removed)
    fs::remove_all(dir);
    fs::remove_all(site);
}
