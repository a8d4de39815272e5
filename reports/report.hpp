// The verification report: `plate report --out DIR` writes DIR/index.html with its figures
// (SVG, drawn by gnuplot) beside it. Every number in it is computed by that run; the run records
// its seed, the machine and how long each part took.
#pragma once

#include "plate/model.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace plate::report {

struct ReportOptions {
    std::string out;          // folder (created)
    std::string source_dir;   // project root: scenes/ and reports/generated/
    std::uint64_t seed = 1;
    bool quick = false;   // small campaigns and grids (tests); the main job runs the full one
    int threads = 0;
    // The sections to compute (names from report_section_names()); empty: all of them. The page names
    // the ones left out.
    std::vector<std::string> sections;
    // A built playground (the web target's site, build/web/site): copied into DIR/playground and linked
    // from the page; empty or absent: the page says how to build it.
    std::string playground;
};

// The report's sections, in page order: derivation, kernels, proofs, fig3, fields, design, orient,
// fixed-point, robustness, identify, control.
const std::vector<std::string>& report_section_names();
// Throws std::invalid_argument ("'NAME' is not a section (derivation, kernels, ...)") for the first
// name in `sections` that is not one of them.
void check_sections(const std::vector<std::string>& sections);

// Writes the report; throws std::runtime_error (with the file or tool named) on failure, and
// std::invalid_argument (check_sections) before anything is written for an unknown section name.
void write_report(const ReportOptions& opt);

// The report's sentence on Observation 1 for the thick parts (beyond Theorem 1), from the campaign's
// counts: of `valid` cases, how many reached a cycle, how many of those from four more initial twists
// reached the same one, and how many had every Floquet multiplier below 1 in modulus. It says "every
// cycle found was unique and attracting" only when all of them did; otherwise how many did not.
std::string observation1_sentence(int valid, int converged, int unique, int attracting);
// The collinear-contacts paragraph: from A's condition numbers and the two twists' wrench gaps at
// e/L = 1, 0.1, ... (e > 0), and sigma_min/sigma_max at e = 0. It says "grows like L/e" and "develops
// a vertex" only when each tenth of e/L multiplies cond(A) and divides the gap by at least 5.
std::string collinear_sentence(const std::vector<double>& conds, const std::vector<double>& gaps, double singular);

// Captions that state a result, each from what the run measured (the opposite said when it is not so).
// Fig. V: `worst_factor`, the largest per-period factor of |xi_rel| over the `shown` thin cases (up to
// rounding): "contract geometrically" only when it is below 1.
std::string contraction_caption(int shown, double worst_factor);
// Fig. 3: the two runs' twists at the period boundaries, their gap / v_ref at the start and after the
// last period: "converging to one limit cycle" only when the gap shrank 100x or more.
std::string fig3_caption(int periods, double gap_start, double gap_end);
// The designed sink's runs: `reached` of `runs` verification runs ended within `distance` of the
// target; "converging on the target" only when all did and the design was verified.
std::string design_runs_caption(int reached, int runs, double distance, bool verified, const std::string& failure);

// The heading of a field's section: the figure's title and the scene's own name (from its file,
// user text: escaped for HTML, as everything a user supplies that reaches the page).
std::string scene_heading(const std::string& title, const std::string& scene_name, const std::string& file);

// The robustness section's first-order ellipse: a centred 2-D normal distribution of covariance C
// holds probability `level` inside {x : x^T C^-1 x <= k^2}, k = normal_ellipse_factor(level) =
// sqrt(-2 ln(1 - level)) (2.4477 at 0.95: the chi-square quantile with 2 degrees of freedom); the
// ellipse's semi-axes are k sqrt(eigenvalue) along C's eigenvectors. `points` + 1 points on it (the
// last the first again); a degenerate C gives a segment.
double normal_ellipse_factor(double level);
std::vector<Vec2> covariance_ellipse(const Eigen::Matrix2d& C, double level = 0.95, int points = 96);

// The robustness section's sentence on where the response is linear, from the Monte Carlo 95 % radius
// and angle against the first-order ones (within 30 %: linear there) and the draws' linear-prediction
// errors (RobustnessSummary's linear_error_*, nonlinear_draws).
struct LinearityFigures {
    bool rigid = false;
    int matched = 0, nonlinear = 0;
    double error_median = 0, error_max = 0;
    double radius_mc = 0, radius_first = 0;   // [m]
    double angle_mc = 0, angle_first = 0;     // [rad]
};
std::string linearity_sentence(const LinearityFigures& f);

// The speed-accuracy study (`plate bench`): writes its charts into DIR and its section into
// DIR/index.html (between the report's markers; a page of its own if there is no report yet).
// Quick by default (minutes); `full` sweeps more settings, solvers and regularisation widths.
struct SpeedOptions {
    std::string out;
    std::string source_dir;
    bool full = false;
};
void write_speed_study(const SpeedOptions& opt);

}   // namespace plate::report
