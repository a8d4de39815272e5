// The report's robustness section (issue 51): each shipped design (scenes/designs/*.json) under the PPOD
// uncertainty spec (scenes/uncertainty/ppod.json) -- its outcome shares, the fixed point's scatter over
// the draws against the first-order 95 % ellipse, the arrival times and the largest sensitivities.
#include "report_sections.hpp"

#include "plate/robustness.hpp"
#include "plate/scene_io.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

namespace plate::report {
namespace fs = std::filesystem;
using namespace html;

double normal_ellipse_factor(double level) { return std::sqrt(-2 * std::log(1 - level)); }

std::vector<Vec2> covariance_ellipse(const Eigen::Matrix2d& C, double level, int points) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(0.5 * (C + C.transpose()));
    const Eigen::Matrix2d axes =
        normal_ellipse_factor(level) * es.eigenvectors() * es.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
    std::vector<Vec2> out;
    for (int i = 0; i <= points; ++i) {   // (closed: the last point is the first)
        const double t = 2 * kPi * i / points;
        out.push_back(axes * Vec2(std::cos(t), std::sin(t)));
    }
    return out;
}

std::string linearity_sentence(const LinearityFigures& f) {
    std::ostringstream o;
    o.precision(3);
    if (f.matched <= 0) return "No draw kept a stable fixed point at the target: nothing to compare with the first order.";
    auto within = [](double mc, double first) { return first > 0 && mc / first >= 1 / 1.3 && mc / first <= 1.3; };
    const bool pos = within(f.radius_mc, f.radius_first);
    o << "The first-order 95 % radius is " << (pos ? "within" : "not within") << " 30 % of the Monte Carlo one ("
      << 1e3 * f.radius_first << " mm against " << 1e3 * f.radius_mc << " mm)";
    if (f.rigid) {
        const bool ang = within(f.angle_mc, f.angle_first);
        o << "; the 95 % angle is " << (ang ? "within" : "not within") << " 30 % (" << f.angle_first << " rad against "
          << f.angle_mc << " rad)";
        o << ". "
          << (pos && ang ? "The response is linear in position and in angle"
              : pos      ? "The response is linear in position, not in angle"
              : ang      ? "The response is linear in angle, not in position"
                         : "The response is not linear, in position or in angle");
    } else {
        o << ". " << (pos ? "The response is linear in position" : "The response is not linear in position");
    }
    o << ": draw by draw, the median draw's fixed point is " << 100 * f.error_median << " % off its linear prediction S p, the "
      << "worst " << 100 * f.error_max << " %, and " << f.nonlinear << " of " << f.matched
      << " matched draws are more than 30 % off.";
    return o.str();
}

namespace {

// A matched draw's offset from the nominal fixed point (theta wrapped) and its linear prediction's
// relative error, as robustness.cpp's spread() measures it (in (s_x, s_y, rho theta)).
struct Offset {
    Vec3 d = Vec3::Zero();
    double error = std::numeric_limits<double>::quiet_NaN();
};

std::vector<Offset> offsets(const RobustnessSummary& s) {
    const Vec3 ref = s.nominal_result.matched ? s.nominal_result.fixed_point : s.target;
    const Vec3 w(1, 1, s.nominal.part.point ? 0 : s.nominal.part.rho());
    std::vector<Offset> out;
    for (const DrawResult& x : s.draws) {
        if (!x.matched) continue;
        Offset f;
        f.d = x.fixed_point - ref;
        f.d[2] = wrap_angle(f.d[2]);
        if (!s.sensitivities.empty() && f.d.cwiseProduct(w).norm() > 0) {
            Vec3 lin = Vec3::Zero();
            for (std::size_t k = 0; k < s.sensitivities.size(); ++k) lin += s.sensitivities[k].dq * x.p[k];
            f.error = (f.d - lin).cwiseProduct(w).norm() / f.d.cwiseProduct(w).norm();
        }
        out.push_back(f);
    }
    return out;
}

void outcome_figure(Ctx& c, const std::string& n, const RobustnessSummary& s) {
    const int draws = static_cast<int>(s.draws.size());
    c.html << "<table><tr><th>outcome</th><th>draws</th><th>share</th><th>95 % interval (Wilson)</th></tr>\n";
    {
        auto d = c.data(n + "_outcomes.dat");
        for (int k = 0; k < kOutcomes; ++k) {
            const Share w = wilson(s.counts[k], draws);
            c.html << "<tr><td>" << outcome_name(static_cast<Outcome>(k)) << "</td><td>" << s.counts[k] << "</td><td>"
                   << fmt(w.value, 3) << "</td><td>" << fmt(w.low, 3) << " – " << fmt(w.high, 3) << "</td></tr>\n";
            d << k << " \"" << outcome_name(static_cast<Outcome>(k)) << "\" " << w.value << ' ' << w.low << ' ' << w.high << '\n';
        }
    }
    c.html << "</table>\n";
    c.plot(n + "_outcomes",
           "set ylabel 'share of the draws'\nset yrange [0:1.05]\nset xrange [-0.6:4.6]\nset style fill solid 0.5\n"
           "set boxwidth 0.6\nset key top right\nset grid ytics\n"
           "plot 'data/" +
               n +
               "_outcomes.dat' u 1:3:xtic(2) w boxes lc rgb '#3050c0' t 'share', '' u 1:3:4:5 w yerrorbars pt 0 lw 2 "
               "lc rgb '#000000' t '95 % Wilson interval'\n",
           "Outcomes of " + std::to_string(draws) + " draws: the share of each, with its 95 % Wilson interval.", "640,360");
}

// The fixed point's scatter over the matched draws against the first-order 95 % ellipse: x-y [mm] and,
// for a rigid part, x-theta.
void scatter_figures(Ctx& c, const std::string& n, const RobustnessSummary& s, const std::vector<Offset>& off) {
    const bool rigid = !s.nominal.part.point;
    int over = 0;
    {
        auto lin = c.data(n + "_scatter_linear.dat");
        auto non = c.data(n + "_scatter_nonlinear.dat");
        for (const Offset& f : off) {
            const bool bad = f.error > 0.3;
            over += bad;
            (bad ? non : lin) << 1e3 * f.d[0] << ' ' << 1e3 * f.d[1] << ' ' << f.d[2] << '\n';
        }
        lin << "nan nan nan\n";   // (a file gnuplot can read when no draw falls in it)
        non << "nan nan nan\n";
        const Eigen::Matrix3d& P = s.predicted_covariance;
        auto e = c.data(n + "_ellipse_xy.dat");
        for (const Vec2& p : covariance_ellipse(1e6 * P.topLeftCorner<2, 2>())) e << p.x() << ' ' << p.y() << '\n';
        Eigen::Matrix2d xt;
        xt << 1e6 * P(0, 0), 1e3 * P(0, 2), 1e3 * P(2, 0), P(2, 2);
        auto e2 = c.data(n + "_ellipse_xt.dat");
        for (const Vec2& p : covariance_ellipse(xt)) e2 << p.x() << ' ' << p.y() << '\n';
    }
    const std::string marks = std::to_string(over) + " draws more than 30 % off their linear prediction (×)";
    c.html << "<p>" << marks << "; the robustness summary counts "
           << c.verdict("scenes/designs/" + n.substr(std::string("robustness_").size()) +
                            ".json: the summary counts the draws off their linear prediction",
                        over == s.nonlinear_draws, "the same", "FAIL: " + std::to_string(s.nonlinear_draws))
           << ".</p>\n";
    const std::string common = "set key outside right\nset grid\n";
    const std::string pts = "'data/" + n + "_scatter_linear.dat' u %X:%Y w p pt 7 ps 0.6 lc rgb '#3050c0' t 'draw', 'data/" + n +
                            "_scatter_nonlinear.dat' u %X:%Y w p pt 2 ps 1.2 lw 2 lc rgb '#d07000' t 'draw, over 30 % off', ";
    auto with = [](std::string t, const char* x, const char* y) {
        for (std::size_t p; (p = t.find("%X")) != std::string::npos;) t.replace(p, 2, x);
        for (std::size_t p; (p = t.find("%Y")) != std::string::npos;) t.replace(p, 2, y);
        return t;
    };
    const std::string k = fmt(normal_ellipse_factor(0.95), 5);
    c.plot(n + "_scatter_xy",
           common + "set size ratio -1\nset xlabel 'x − x* [mm]'\nset ylabel 'y − y* [mm]'\nplot " + with(pts, "1", "2") +
               "'data/" + n +
               "_ellipse_xy.dat' u 1:2 w l lw 2 lc rgb '#c02020' t 'first order, 95 %', '+' u (0):(0) every ::0::0 "
               "w p pt 3 ps 2 lw 2 lc rgb '#000000' t 'nominal'\n",
           "Where the fixed point went in the " + std::to_string(off.size()) +
               " draws that kept it at the target, about the nominal one (x*, y*), and the first-order ellipse holding 95 % "
               "of a normal distribution of the predicted covariance (" +
               k + " standard deviations along each principal axis); " + marks + ".",
           "800,560");
    if (!rigid) return;
    c.plot(n + "_scatter_xtheta",
           common + "set xlabel 'x − x* [mm]'\nset ylabel 'θ − θ* [rad]'\nplot " + with(pts, "1", "3") + "'data/" + n +
               "_ellipse_xt.dat' u 1:2 w l lw 2 lc rgb '#c02020' t 'first order, 95 %', '+' u (0):(0) every ::0::0 "
               "w p pt 3 ps 2 lw 2 lc rgb '#000000' t 'nominal'\n",
           "The same draws in x and the orientation θ, against the x-θ block's 95 % ellipse; " + marks + ".", "800,480");
}

// Arrival times: the field's integral curves from the seeded starts of every draw, and the full
// dynamics' of the first draws, as shares of their runs; not arrived within the horizon (and undefined)
// as bars of their own.
void arrival_figure(Ctx& c, const std::string& n, const RobustnessSummary& s, const RobustnessOptions& o) {
    const int bins = 12;
    const double bw = o.horizon / bins;
    std::vector<double> field(bins + 2, 0), full(bins + 2, 0);
    int nf = 0, nd = 0;
    auto add = [&](std::vector<double>& h, double t) {
        h[std::isnan(t) ? bins + 1 : std::isinf(t) ? bins : std::min(bins - 1, static_cast<int>(t / bw))] += 1;
    };
    for (const DrawResult& d : s.draws) {
        for (double t : d.arrival) add(field, t), ++nf;
        for (double t : d.arrival_full) add(full, t), ++nd;
    }
    {
        auto f = c.data(n + "_arrival.dat");
        for (int b = 0; b < bins + 2; ++b)   // (the last two bars apart, a bin and a half after the horizon each)
            f << (b < bins ? (b + 0.5) * bw : o.horizon + 1.5 * (b - bins + 1) * bw) << ' ' << field[b] / std::max(1, nf) << ' '
              << full[b] / std::max(1, nd) << '\n';
    }
    const std::string script =
        "set xlabel 'arrival time [s]'\nset ylabel 'share of the runs'\nset style fill solid 0.6\nset key top center\n"
        "set grid ytics\nset xrange [0:" +
        fmt(o.horizon + 4 * bw, 6) + "]\nset xtics 0," + fmt(2 * bw, 6) + "," + fmt(o.horizon, 6) +
        "\nset xtics add (\"not\\narrived\" " + fmt(o.horizon + 1.5 * bw, 6) + ", \"undefined\" " + fmt(o.horizon + 3 * bw, 6) +
        ")\nset arrow from " + fmt(o.horizon, 6) + ",graph 0 to " + fmt(o.horizon, 6) +
        ",graph 1 nohead dt 2 lc rgb '#777777'\nplot 'data/" + n + "_arrival.dat' u ($1-" + fmt(bw / 4, 6) + "):2:(" +
        fmt(bw / 2, 6) + ") w boxes lc rgb '#3050c0' t 'field integral curves (" + std::to_string(nf) + ")', '' u ($1+" +
        fmt(bw / 4, 6) + "):3:(" + fmt(bw / 2, 6) + ") w boxes lc rgb '#c02020' t 'full dynamics (" + std::to_string(nd) + ")'\n";
    const double arrived_field = 1 - (field[bins] + field[bins + 1]) / std::max(1, nf);
    const double arrived_full = 1 - (full[bins] + full[bins + 1]) / std::max(1, nd);
    c.plot(n + "_arrival", script,
           "Time to come within " + fmt(1e3 * o.arrive_distance, 3) + " mm" +
               (s.nominal.part.point ? "" : " and " + fmt(o.arrive_angle, 3) + " rad") + " of the target from " +
               std::to_string(s.starts.size()) +
               " seeded starts: the field's integral curves in every draw with a field (not contact lost or failed; " +
               fmt(100 * arrived_field, 3) + " % within " + fmt(o.horizon, 3) + " s) and full dynamics in the first " +
               std::to_string(o.full_draws) + " draws (" + fmt(100 * arrived_full, 3) + " %). Undefined: the field or the run " +
               "stopped on the way.",
           "800,420");
}

void sensitivity_table(Ctx& c, const RobustnessSummary& s, const std::vector<Offset>& off) {
    const bool rigid = !s.nominal.part.point;
    std::vector<Sensitivity> v = s.sensitivities;
    std::sort(v.begin(), v.end(), [](const Sensitivity& a, const Sensitivity& b) { return a.variance_share > b.variance_share; });
    const std::size_t shown = std::min<std::size_t>(8, v.size());
    c.html << "<p>The largest first-order sensitivities (implicit function theorem at the nominal fixed point, "
           << fmt(1e3 * s.sensitivity_seconds, 3) << " ms; " << shown << " of " << v.size()
           << " parameters): the fixed point's shift for one standard deviation of each parameter, and its share of "
              "the predicted position variance.</p>\n<table><tr><th>parameter</th><th>unit</th><th>standard deviation</th>"
              "<th>shift x [mm]</th><th>shift y [mm]</th>"
           << (rigid ? "<th>shift θ [rad]</th>" : "") << "<th>share of the position variance</th></tr>\n";
    for (std::size_t k = 0; k < shown; ++k) {
        const Vec3 d = v[k].dq * v[k].parameter.standard_deviation;
        c.html << "<tr><td>" << esc(v[k].parameter.name) << "</td><td>" << esc(v[k].parameter.unit) << "</td><td>"
               << fmt(v[k].parameter.standard_deviation, 3) << "</td><td>" << fmt(1e3 * d[0], 3) << "</td><td>"
               << fmt(1e3 * d[1], 3) << "</td>" << (rigid ? "<td>" + fmt(d[2], 3) + "</td>" : "") << "<td>"
               << fmt(100 * v[k].variance_share, 3) << " %</td></tr>\n";
    }
    c.html << "</table>\n<table><tr><th></th><th>Monte Carlo (" << off.size() << " matched draws)</th><th>first order</th></tr>\n"
           << "<tr><td>95 % radius [mm]</td><td>" << fmt(1e3 * s.radius95, 3) << "</td><td>" << fmt(1e3 * s.predicted_radius95, 3)
           << "</td></tr>\n";
    if (rigid)
        c.html << "<tr><td>95 % angle [rad]</td><td>" << fmt(s.angle95, 3) << "</td><td>" << fmt(s.predicted_angle95, 3)
               << "</td></tr>\n";
    c.html << "<tr><td>mean offset x, y [mm]" << (rigid ? ", θ [rad]" : "") << "</td><td>" << fmt(1e3 * s.mean_offset[0], 3)
           << ", " << fmt(1e3 * s.mean_offset[1], 3) << (rigid ? ", " + fmt(s.mean_offset[2], 3) : "")
           << "</td><td>0 (first order)</td></tr>\n</table>\n";
    LinearityFigures f;
    f.rigid = rigid;
    f.matched = static_cast<int>(off.size());
    f.nonlinear = s.nonlinear_draws;
    f.error_median = s.linear_error_median;
    f.error_max = s.linear_error_max;
    f.radius_mc = s.radius95;
    f.radius_first = s.predicted_radius95;
    f.angle_mc = s.angle95;
    f.angle_first = s.predicted_angle95;
    c.html << "<p>" << linearity_sentence(f) << "</p>\n";
}

void design_robustness(Ctx& c, const fs::path& file, const UncertaintySpec& spec, const RobustnessOptions& o) {
    const Scene sc = load_scene(file.string());
    const std::string n = "robustness_" + file.stem().string();
    c.html << scene_heading("Robustness of " + file.stem().string(), sc.name, "designs/" + file.filename().string()) << "\n";
    RobustnessSummary s;
    try {
        s = robustness(sc, spec, o);
    } catch (const std::invalid_argument& e) {   // (no single nominal fixed point to follow)
        c.html << "<p>Not analysed: " << esc(e.what()) << "</p>\n";
        return;
    }
    const Vec3& q = s.nominal_result.fixed_point;
    c.html << "<p>" << (sc.part.point ? "A point part" : "A rigid part") << "; the nominal plate's stable fixed point ("
           << fmt(q[0], 4) << " m, " << fmt(q[1], 4) << " m" << (sc.part.point ? "" : ", " + fmt(q[2], 4) + " rad")
           << "), convergence rate " << fmt(s.nominal_result.rate, 3) << " 1/s; " << s.draws.size() << " draws in "
           << fmt(s.seconds, 3) << " s.";
    for (const std::string& note : s.notes) c.html << " " << esc(note) << ".";
    c.html << "</p>\n";
    outcome_figure(c, n, s);
    const std::vector<Offset> off = offsets(s);
    scatter_figures(c, n, s, off);
    arrival_figure(c, n, s, o);
    if (!s.sensitivities.empty()) sensitivity_table(c, s, off);
}

}   // namespace

void section_robustness(Ctx& c, const fs::path& src, const ReportOptions& opt) {
    const fs::path spec_file = src / "scenes" / "uncertainty" / "ppod.json";
    const UncertaintySpec spec = load_uncertainty(spec_file.string());
    RobustnessOptions o;
    o.draws = opt.quick ? 40 : 200;
    o.threads = opt.threads;
    std::vector<fs::path> designs;
    for (const auto& e : fs::directory_iterator(src / "scenes" / "designs"))
        if (e.path().extension() == ".json") designs.push_back(e.path());
    std::sort(designs.begin(), designs.end());
    std::ifstream in(spec_file);
    const nlohmann::json spec_text = nlohmann::json::parse(in);
    c.html << c.heading("Robustness", "robustness") << "<p>Each shipped design (<code>scenes/designs/</code>) on " << o.draws
           << " plates and parts drawn from the uncertainty spec <code>scenes/uncertainty/ppod.json</code> (<code>"
           << esc(spec_text.dump()) << "</code>: PPOD-type tracking errors)"
           << (opt.quick ? ", 40 draws in this quick run (the full report draws 200)" : "")
           << ", by <code>robustness()</code> (<code>plate robustness</code>). Per draw the field on a " << o.grid.nx << "×"
           << o.grid.ny << "×" << o.grid.nth
           << " grid and its fixed points decide the outcome: <i>unique</i> (one stable fixed point, the target's: within "
           << fmt(1e3 * o.match_distance, 3) << " mm and " << fmt(o.match_angle, 3)
           << " rad of the nominal one), <i>competing</i> (another attractor too), <i>none</i> (no stable point at the "
              "target), <i>contact lost</i> somewhere on the grid, or <i>failed</i>. The fixed point's scatter is drawn "
              "against the first-order prediction: sensitivities S = −(∂ξ/∂q)<sup>−1</sup> ∂ξ/∂p by the implicit function "
              "theorem give the covariance S diag(σ²) Sᵀ, whose 95 % ellipse lies √(−2 ln 0.05) = "
           << fmt(normal_ellipse_factor(0.95), 5)
           << " standard deviations out along each principal axis; each draw's own deviations p give its linear "
              "prediction S p.</p>\n";
    for (const fs::path& f : designs) c.timed("robustness: " + f.stem().string(), [&] { design_robustness(c, f, spec, o); });
}

}   // namespace plate::report
