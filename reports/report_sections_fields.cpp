// The report's section 6, the paper's fields: each scene's field, a full-dynamics run from rest,
// its fixed points; then stick-slip against the regularised-friction limit.
#include "report_sections.hpp"

#include "plate/field.hpp"
#include "plate/scene_io.hpp"
#include "plate/study.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <ostream>
#include <string>
#include <vector>

namespace plate::report {
namespace fs = std::filesystem;
using namespace html;

namespace {

// The largest of 1, 2, 5 times a power of ten not above x (x > 0).
double nice_floor(double x) {
    const double p = std::pow(10.0, std::floor(std::log10(x)));
    for (double m : {5.0, 2.0, 1.0})
        if (m * p <= x) return m * p;
    return p;
}

// The arrows' scale for arrows that are the twist times k [s] on grid g: a reference arrow of a round
// speed along s_x (gnuplot commands), and the caption's statement of it and of a theta component.
struct QuiverScale {
    std::string arrow, caption;
};
QuiverScale quiver_scale(const GridSpec& g, double k, bool point);

// Gnuplot objects for an s_x-s_y figure: each stuck region's extent (a shaded rectangle), each rotating
// orbit's position on its section (a marker labelled with its rate and stability) and, where the
// position circles, that circle (dashed); the ranges then hold them with the grid.
std::string fixed_set_marks(const FixedPoints& fp, const GridSpec& g) {
    std::string o;
    double x0 = g.x0, x1 = g.x1, y0 = g.y0, y1 = g.y1;
    int tag = 100;   // above the arrow scale's labels and arrows (90, 91)
    for (const StuckRegion& r : fp.stuck_regions)
        o += "set object " + std::to_string(tag++) + " rect from " + fmt(r.lo[0], 6) + "," + fmt(r.lo[1], 6) + " to " +
             fmt(r.hi[0], 6) + "," + fmt(r.hi[1], 6) +
             " fc rgb '#9999cc' fs transparent solid 0.3 border lc rgb '#333399' back\n";
    for (const RotatingAttractor& r : fp.rotating) {
        if (r.radius > 0) {
            o += "set object " + std::to_string(tag++) + " ellipse at " + fmt(r.centre[0], 6) + "," + fmt(r.centre[1], 6) +
                 " size " + fmt(2 * r.radius, 6) + "," + fmt(2 * r.radius, 6) +
                 " units xy fs empty border lc rgb '#208020' dashtype 2 lw 1.5 front\n";
            x0 = std::min(x0, r.centre[0] - r.radius);
            x1 = std::max(x1, r.centre[0] + r.radius);
            y0 = std::min(y0, r.centre[1] - r.radius);
            y1 = std::max(y1, r.centre[1] + r.radius);
        }
        o += "set label " + std::to_string(tag++) + " 'ω " + fmt(r.rate, 3) + " rad/s, " + stability_name(r.stability) + "' at " +
             fmt(r.q[0], 6) + "," + fmt(r.q[1], 6) +
             " point pt 7 ps 1.5 lc rgb '#208020' offset 0.8,0.6 font ',10' textcolor rgb '#206020' front\n";
    }
    bool circles = false;
    for (const RotatingAttractor& r : fp.rotating) circles = circles || r.radius > 0;
    if (circles) o += "set size ratio -1\n";   // circles drawn round
    if (x0 < g.x0 || x1 > g.x1 || y0 < g.y0 || y1 > g.y1) {
        const double pad = 0.05 * std::max(x1 - x0, y1 - y0);
        o += "set xrange [" + fmt(x0 - pad, 6) + ":" + fmt(x1 + pad, 6) + "]\nset yrange [" + fmt(y0 - pad, 6) + ":" +
             fmt(y1 + pad, 6) + "]\n";
    }
    return o;
}

// The table's rows for what find_fixed_points found: points, lines, stuck regions (their extent) and
// rotating orbits (rate, and the circle the position follows).
void fixed_set_rows(std::ostream& html, const FixedPoints& fp, bool pt) {
    for (const auto& p : fp.points) {
        html << "<tr><td>point</td><td>(" << fmt(p.q[0], 3) << ", " << fmt(p.q[1], 3) << (pt ? "" : ", " + fmt(p.q[2], 4))
             << ")</td><td>" << stability_name(p.stability) << "</td><td>";
        for (int i = 0; i < (pt ? 2 : 3); ++i) html << fmt(p.eigenvalues[i].real(), 3) << " ";
        html << "</td></tr>\n";
    }
    for (const auto& l : fp.lines) {
        const Vec3 &a = l.points.front(), &b = l.points.back();
        html << "<tr><td>line</td><td>(" << fmt(a[0], 3) << ", " << fmt(a[1], 3) << (pt ? "" : ", " + fmt(a[2], 3)) << ") … ("
             << fmt(b[0], 3) << ", " << fmt(b[1], 3) << (pt ? "" : ", " + fmt(b[2], 3)) << ")</td><td>"
             << stability_name(l.stability) << "</td><td>";
        for (int i = 0; i < (pt ? 2 : 3); ++i) html << fmt(l.eigenvalues[i].real(), 3) << " ";
        html << "</td></tr>\n";
    }
    for (const auto& r : fp.stuck_regions)
        html << "<tr><td>stuck region (" << r.grid_points << " grid points)</td><td>x " << fmt(r.lo[0], 3) << " … "
             << fmt(r.hi[0], 3) << ", y " << fmt(r.lo[1], 3) << " … " << fmt(r.hi[1], 3)
             << (pt || r.all_theta ? "" : ", θ " + fmt(r.lo[2], 3) + " … " + fmt(r.hi[2], 3))
             << "</td><td>fixed (sticks)</td><td>—</td></tr>\n";
    for (const auto& r : fp.rotating) {
        html << "<tr><td>rotating orbit, " << fmt(r.rate, 4) << " rad/s</td><td>(" << fmt(r.q[0], 3) << ", " << fmt(r.q[1], 3)
             << ") at θ = " << fmt(r.q[2], 3);
        if (r.radius > 0)
            html << "; circling (" << fmt(r.centre[0], 3) << ", " << fmt(r.centre[1], 3) << ") at radius " << fmt(r.radius, 3);
        html << "</td><td>" << stability_name(r.stability) << "</td><td>multipliers |μ| " << fmt(std::abs(r.multipliers[0]), 3)
             << " " << fmt(std::abs(r.multipliers[1]), 3) << "</td></tr>\n";
    }
}

// The quiver's scale: a reference arrow above a 2-D field plot, along its x axis (every such plot's x is a
// position in m), `length` [m] for `speed` [unit]; gnuplot commands.
std::string scale_arrow(double length, double speed, const char* unit) {
    return "set tmargin 4\nset label 90 'arrow scale: " + fmt(speed, 3) + " " + unit +
           "' at graph 0, graph 1.06 left\nset arrow 90 from graph 0.3, graph 1.04 rto first " + fmt(length, 6) +
           ", first 0 lw 2 lc rgb '#000000' front head size 0.004,20\n";
}

QuiverScale quiver_scale(const GridSpec& g, double k, bool point) {
    if (!(k > 0) || !(g.dx() > 0)) return {};
    const double v = nice_floor(0.8 * g.dx() / k), w = nice_floor(0.8 * g.dth() / k);
    return {scale_arrow(k * v, 1e3 * v, "mm/s"),
            " Arrows: the twist times " + fmt(k, 3) + " s; the black one above the plot is " + fmt(1e3 * v, 3) + " mm/s" +
                (point ? "" : "; a θ-component of " + fmt(k * w, 3) + " rad is " + fmt(w, 3) + " rad/s") + "."};
}

// Stick-slip against the regularised-friction limit (study.hpp): a cycle that pivots and one with a
// short phase stuck as a whole, on fig6's thick part.
void section_stick_reference(Ctx& c, const fs::path& src, bool quick) {
    const Scene sc = load_scene((src / "scenes/fig6.json").string());
    const double v = sc.v_ref();
    const Vec3 S(v, v, v / sc.part.rho());
    c.html
        << "<h3>Stick-slip against the regularised-friction limit</h3>\n<p>The engine holds a contact (or the "
           "part) as long as <i>some</i> static friction inside the disks can (rigid Coulomb friction: the distribution "
           "is indeterminate). The reference replaces Coulomb's law by f = −μN v/√(|v|²+ε²) (no stick, no events; GSL "
           "bsimp), ε = 10<sup>-5</sup>…10<sup>-8</sup> v<sub>ref</sub>, extrapolated to ε = 0 with the observed order. "
           "Differences relative to v<sub>ref</sub>:</p>\n<table><tr><th>configuration (fig6)</th><th>cycle</th>"
           "<th>engine</th><th>regularised limit</th><th>observed order</th><th>difference</th><th>reference's error</th></tr>\n";
    Vec3 qs[] = {Vec3(0.0333333333333, 0.0166666666667, 1.7951958020513104), Vec3(0.0166666666667, 0, 2.6927937030769655)};
    int stuck_differ = 0, agree = 0;   // cycles stuck as a whole beyond the reference's error; cycles within it
    for (const Vec3& q : qs) {
        LimitCycleOptions o;
        o.integration.rtol = 1e-10;
        o.tol = 1e-9;
        const LimitCycleSummary lc = limit_cycle(sc, q, o);
        const RegularisedReference r = regularised_reference(sc, q);
        const bool stuck =
            lc.start_mode.kind == ModeKind::Stuck || std::any_of(lc.mode_events.begin(), lc.mode_events.end(),
                                                                 [](const ModeEvent& e) { return e.to.kind == ModeKind::Stuck; });
        const double held = *std::max_element(lc.stick_fraction.begin(), lc.stick_fraction.end());
        c.html << "<tr><td>(" << fmt(q[0], 3) << ", " << fmt(q[1], 3) << ", " << fmt(q[2], 3) << ")</td><td>"
               << (stuck      ? "stuck as a whole "
                   : held > 0 ? "a contact held "
                              : "sliding ")
               << fmt(100 * held, 3) << "% of the period</td><td>" << fmt(lc.twist[0] / S[0], 7) << ", "
               << fmt(lc.twist[1] / S[1], 7) << ", " << fmt(lc.twist[2] / S[2], 7) << "</td><td>"
               << (r.ok ? fmt(r.twist[0] / S[0], 7) + ", " + fmt(r.twist[1] / S[1], 7) + ", " + fmt(r.twist[2] / S[2], 7)
                        : esc(r.failure))
               << "</td><td>" << fmt(r.order, 3) << "</td><td>"
               << (r.ok && lc.converged ? fmt((lc.twist - r.twist).cwiseQuotient(S).cwiseAbs().maxCoeff(), 3) : std::string("—"))
               << "</td><td>" << fmt(r.error, 2) << "</td></tr>\n";
        if (r.ok && lc.converged) {
            const bool within = (lc.twist - r.twist).cwiseQuotient(S).cwiseAbs().maxCoeff() <= 1e-7 + r.error;
            agree += within;
            stuck_differ += stuck && !within;
        }
    }
    c.html << "</table>\n<p>" << agree << " of " << std::size(qs) << " cycles agree with the reference within 10<sup>-7</sup> "
           << "v<sub>ref</sub> plus its error.";
    if (stuck_differ > 0)
        c.html << " " << stuck_differ << " cycle" << (stuck_differ > 1 ? "s" : "") << " stuck as a whole for part of the "
               << "period differ" << (stuck_differ > 1 ? "" : "s") << " beyond it (the engine breaks away where the "
               << "friction-disk gauge of the needed wrench reaches 1; the regularised part where its creep does).";
    c.html << " The engine's fields assume rigid Coulomb friction.</p>\n";

    // Scenes nobody tuned (study.hpp: sticking_random_scene): the same comparison on seeded random
    // scenes, the engine at its default options.
    const int n = quick ? 12 : 60;
    const double band = 3e2 * LimitCycleOptions{}.integration.rtol, tol = LimitCycleOptions{}.tol;
    int converged = 0, flew = 0, held = 0, stuck = 0, ref_failed = 0, beyond = 0;
    std::vector<std::pair<double, std::uint64_t>> diffs;
    std::vector<double> ref_errors;
    for (std::uint64_t seed = 1; seed <= static_cast<std::uint64_t>(n); ++seed) {
        const RandomStickCase r = random_stick_case(seed);
        converged += r.converged();
        flew += !r.converged() && r.failure.find("would fly") != std::string::npos;
        if (!r.converged()) continue;
        held += r.held > 0;
        stuck += r.held >= 1;
        if (!r.reference_ok) {
            ++ref_failed;
            continue;
        }
        diffs.emplace_back(r.error, seed);
        ref_errors.push_back(r.reference_error);
        beyond += r.error > band + tol + r.reference_error;
    }
    std::sort(diffs.begin(), diffs.end());
    std::sort(ref_errors.begin(), ref_errors.end());
    c.html << "<p><b>Scenes nobody tuned.</b> " << n << " seeded random scenes (thick, thin and point parts; motions on "
           << "all six axes, the largest x or y harmonic rescaled to 0.05–1.2 μg and the heave by 0.5–2.5; one random "
           << "configuration within 3 cm of the centre each; <code>sticking_random_scene</code>), the engine at its default "
           << "options (rtol " << fmt(LimitCycleOptions{}.integration.rtol, 1) << ", cycles to " << fmt(tol, 1)
           << " v<sub>ref</sub>): " << converged << " cycles found";
    if (flew > 0)
        c.html << ", " << flew << " left the model (a contact's normal force reached zero: the part would fly; said so)";
    c.html << "; " << held << " of them hold a contact for part of the period or longer, " << stuck << " all period. ";
    if (!diffs.empty())
        c.html << "The reference found a cycle on " << diffs.size() << " (its own error estimate: median "
               << fmt(ref_errors[ref_errors.size() / 2], 2) << ", largest " << fmt(ref_errors.back(), 2)
               << " v<sub>ref</sub>); the differences: largest " << fmt(diffs.back().first, 2) << " v<sub>ref</sub> (seed "
               << diffs.back().second << "), median " << fmt(diffs[diffs.size() / 2].first, 2) << "; " << beyond
               << " beyond the engine's bound (the zero band of its slips, " << fmt(band, 1) << ", plus the cycle tolerance) "
               << "plus the reference's error";
    if (ref_failed > 0) c.html << "; on " << ref_failed << " the reference itself found no cycle";
    c.html << ".</p>\n";
}

}   // namespace

void section_fields(Ctx& c, const fs::path& src, const ReportOptions& opt) {
    c.html << c.heading("6. The paper's fields", "fields");
    struct F {
        const char* scene;
        Vec3 start;
        double duration;
        const char* what;
    };
    const F figs[] = {{"fig1_point", Vec3(0.04, -0.03, 0), 10, "Fig. 1(b): point part, velocity field"},
                      {"fig1", Vec3(-0.04, 0.03, 1.2), 20, "Fig. 1(c)-(f): lines of fixed points at θ = 0, π"},
                      {"fig4", Vec3(0.04, -0.04, 1.0), 20, "Fig. 4: centring and orienting"},
                      {"fig5", Vec3(0.0, -0.04, 1.0), 4, "Fig. 5: transport along y, θ to 0 or π"},
                      {"fig6", Vec3(0.03, 0.03, 0.5), 20, "Fig. 6: rotation"},
                      {"heave_yaw", Vec3(0.03, 0.03, 0.5), 20, "Heave + rocking yaw (z and rz, one frequency)"},
                      {"heave_yaw_point", Vec3(0.03, 0.03, 0), 20, "Heave + rocking yaw, point part"}};
    for (const auto& f : figs) {
        const Scene sc = load_scene((src / "scenes" / (std::string(f.scene) + ".json")).string());
        GridSpec g;
        if (opt.quick) g.nx = g.ny = g.nth = 4;
        if (std::string(f.scene) == "fig5") {
            g.x0 = -0.03;
            g.x1 = 0.03;
        }
        Field field;
        FixedPoints fp;
        Trajectory tr;
        FieldOptions fo;
        fo.threads = opt.threads;
        c.timed(std::string("field ") + f.scene, [&] {
            field = compute_field(sc, g, fo);
            fp = find_fixed_points(sc, field);
            tr = simulate(sc, Dynamics::Full, f.start, Vec3::Zero(), opt.quick ? std::min(f.duration, 4.0) : f.duration, 0.05);
        });
        const bool pt = sc.part.point;
        const std::string n = f.scene;
        double k = 0;   // [s]: an arrow is the twist times k
        {
            // Arrows = twist x one time scale, the longest 0.8 of a grid cell (in x, y and theta).
            double lmax = 0;
            const double dx = std::max(g.dx(), 1e-9), dy = std::max(g.dy(), 1e-9), dth = g.dth();
            for (const auto& p : field.points)
                if (p.converged)
                    lmax = std::max(
                        {lmax, std::abs(p.twist[0]) / dx, std::abs(p.twist[1]) / dy, pt ? 0.0 : std::abs(p.twist[2]) / dth});
            k = lmax > 0 ? 0.8 / lmax : 0;
            auto o = c.data(n + "_field.dat");
            for (const auto& p : field.points) {
                if (!p.converged) continue;
                o << p.q[0] << ' ' << p.q[1] << ' ' << wrap_angle(p.q[2]) << ' ' << k * p.twist[0] << ' ' << k * p.twist[1] << ' '
                  << (pt ? 0.0 : k * p.twist[2]) << ' ' << *std::max_element(p.stick_fraction.begin(), p.stick_fraction.end())
                  << '\n';
            }
            auto t = c.data(n + "_traj.dat");
            for (const auto& s : tr.samples) t << s.q[0] << ' ' << s.q[1] << ' ' << wrap_angle(s.q[2]) << '\n';
        }
        c.html << scene_heading(f.what, sc.name, n + ".json") << "\n<p>Field on " << field.grid.nx << "×" << field.grid.ny
               << (pt ? "" : "×" + std::to_string(field.grid.nth)) << " configurations (" << fmt(field.seconds, 3)
               << " s); red: full-dynamics run from rest at (" << f.start[0] << ", " << f.start[1]
               << (pt ? "" : ", " + fmt(f.start[2], 3)) << ") for " << (tr.samples.empty() ? 0.0 : tr.samples.back().t) << " s"
               << (tr.stop.reason != StopReason::None ? " — stopped: " + esc(tr.stop.describe()) : std::string()) << ".</p>\n";
        {
            // A paper figure's run must reach its full duration (a run that stops at once draws a dot).
            const double want = opt.quick ? std::min(f.duration, 4.0) : f.duration;
            const double reached = tr.samples.empty() ? 0.0 : tr.samples.back().t;
            const bool full = tr.stop.reason == StopReason::None && reached >= want * (1 - 1e-9);
            c.html << "<p>The run from rest reaches its full " << fmt(want, 3) << " s: "
                   << c.verdict(std::string(f.what) + ": the run from rest reaches its full duration", full, "pass",
                                "FAIL: the run from rest stopped at t = " + fmt(reached, 4) + " s of " + fmt(want, 3) + " s" +
                                    (tr.stop.reason != StopReason::None ? " (" + tr.stop.describe() + ")" : ""))
                   << "</p>\n";
        }
        const std::string F = "'data/" + n + "_field.dat'", T = "'data/" + n + "_traj.dat'";
        const std::string arrows = " w vec head size 0.004,20 lc rgb '#777777' notitle";
        const std::string kFieldSize = "800,640";   // field figures: large enough to read the arrows
        const QuiverScale qs = quiver_scale(g, k, pt);
        const std::string &scale = qs.arrow, &scale_text = qs.caption;
        const std::string marks = fixed_set_marks(fp, g);
        if (pt) {
            c.plot(n + "_xy",
                   scale + marks + "set xlabel 's_x [m]'\nset ylabel 's_y [m]'\nset size ratio -1\nplot " + F + " u 1:2:4:5" +
                       arrows + ", " + T + " u 1:2 w l lw 2 lc rgb '#c02020' notitle\n",
                   std::string(f.what) + ": s_x–s_y." + scale_text, kFieldSize);
        } else {
            c.plot(n + "_3d",
                   "set xlabel 's_x [m]'\nset ylabel 's_y [m]'\nset zlabel 'θ [rad]'\nset view 60,30\nsplot " + F +
                       " u 1:2:3:4:5:6" + arrows + ", " + T + " u 1:2:3 w l lw 2 lc rgb '#c02020' notitle\n",
                   std::string(f.what) + ": (s_x, s_y, θ). Arrows: the twist times " + fmt(k, 3) + " s.", kFieldSize);
            c.plot(n + "_xy",
                   scale + marks + "set xlabel 's_x [m]'\nset ylabel 's_y [m]'\nplot " + F + " u 1:2:4:5" + arrows + ", " + T +
                       " u 1:2 w l lw 2 lc rgb '#c02020' notitle\n",
                   "s_x–s_y projection." + scale_text, kFieldSize);
            c.plot(n + "_xt",
                   scale + "set xlabel 's_x [m]'\nset ylabel 'θ [rad]'\nplot " + F + " u 1:3:4:6" + arrows + ", " + T +
                       " u 1:3 w p pt 7 ps 0.3 lc rgb '#c02020' notitle\n",
                   "s_x–θ projection." + scale_text, kFieldSize);
            c.plot(n + "_yt",
                   scale + "set xlabel 's_y [m]'\nset ylabel 'θ [rad]'\nplot " + F + " u 2:3:5:6" + arrows + ", " + T +
                       " u 2:3 w p pt 7 ps 0.3 lc rgb '#c02020' notitle\n",
                   "s_y–θ projection." + scale_text, kFieldSize);
        }
        int stuck = 0, lost = 0, sticks = 0, held_all = 0;
        for (const auto& p : field.points) {
            stuck += p.stop == StopReason::Sticking;
            lost += p.stop == StopReason::ContactLost;
            sticks += p.converged && *std::max_element(p.stick_fraction.begin(), p.stick_fraction.end()) > 0;
            held_all +=
                p.converged && *std::min_element(p.stick_fraction.begin(), p.stick_fraction.begin() + sc.part.contacts()) >= 1;
        }
        c.html << "<p>Configurations where the twist is undefined: " << stuck << " sticking, " << lost << " contact lost. "
               << "Configurations whose cycle sticks (a contact held for part of the period): " << sticks << " of "
               << field.points.size() << "; stuck as a whole all period long (twist exactly zero): " << held_all << ".</p>\n";
        if (sticks > 0) {
            // The largest stick fraction of the three contacts over the cycle, per configuration.
            const std::string SF = "'data/" + n + "_field.dat'";
            c.plot(n + "_stick",
                   pt ? "set xlabel 's_x [m]'\nset ylabel 's_y [m]'\nset size ratio -1\nset cblabel 'stick fraction'\nset "
                        "cbrange [0:1]\n"
                        "plot " +
                            SF + " u 1:2:7 w p pt 5 ps 2 palette notitle\n"
                      : "set xlabel 's_x [m]'\nset ylabel 's_y [m]'\nset zlabel 'θ [rad]'\nset view 60,30\nset cblabel 'stick "
                        "fraction'\n"
                        "set cbrange [0:1]\nsplot " +
                            SF + " u 1:2:3:7 w p pt 7 ps 1 palette notitle\n",
                   std::string(f.what) + ": fraction of the cycle a contact is held (largest of the contacts)", kFieldSize);
        }
        c.html << "<table><tr><th>fixed point, line, stuck region or rotating orbit</th><th>at (from … "
                  "to)</th><th>stability</th><th>eigenvalues (real "
                  "parts)</th></tr>\n";
        fixed_set_rows(c.html, fp, pt);
        c.html << "</table>\n<p>" << esc(fixed_points_sentence(fp)) << ".</p>\n";
    }
    section_stick_reference(c, src, opt.quick);
}

}   // namespace plate::report
