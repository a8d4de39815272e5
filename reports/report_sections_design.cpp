// The report's inverse-design sections: point-part sinks, a rigid part's sink and a line sink
// (section_design), the orienter (section_orient) and a rigid part's fixed point (section_fixed_point).
#include "report_sections.hpp"

#include "plate/design.hpp"
#include "plate/field.hpp"
#include "plate/scene_io.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace plate::report {
namespace fs = std::filesystem;
using namespace html;

// Inverse design (design.hpp): point-part sinks designed, verified, and shown -- the signal, the field
// with its fixed point, and full-dynamics runs from the verification's random starts.
// A design table row's first cells: the target, the verdict (with why it failed), unique, the rate,
// evaluations, cycles and the designed signal's peaks (the axes that move), and its corners'.
std::string design_cells(Ctx& c, const std::string& target, const DesignSummary& d) {
    std::string peaks;
    for (int a = 0; a < 6; ++a)
        if (d.peaks[a] > 0)
            peaks += (peaks.empty() ? "" : ", ") + std::string(axis_name(static_cast<Axis>(a))) + " " + fmt(d.peaks[a], 3) +
                     (a < 3 ? " m/s²" : " rad/s²");
    peaks += "; corners at ±(" + fmt(1e3 * d.corner_half_size.x(), 3) + ", " + fmt(1e3 * d.corner_half_size.y(), 3) +
             ") mm: " + fmt(1e3 * d.corner_peaks.displacement, 3) + " mm, " + fmt(d.corner_peaks.velocity, 3) + " m/s";
    return "<tr><td>" + target + "</td><td>" + c.verdict("design verified: " + target, d.verified) +
           (d.verified ? "" : " " + esc(d.failure)) + "</td><td>" + (d.unique ? "yes" : "no") + "</td><td>" + fmt(d.rate, 3) +
           "</td><td>" + std::to_string(d.evaluations) + "</td><td>" + std::to_string(d.cycles) + "</td><td>" + peaks + "</td>";
}

// The cell of the part released at the target: how far it is after the hold, marked beyond `allowed`,
// and why its run stopped early (`stop`), if it did.
std::string held_cell(Ctx& c, const std::string& target, double walked, double allowed, const std::string& from,
                      const std::string& stop) {
    const std::string v = fmt(1e3 * walked, 3);
    return "<td>" +
           c.verdict("released at rest on " + target + ", it stays within " + fmt(1e3 * allowed, 3) + " mm", !(walked > allowed),
                     v + " mm", v + " mm") +
           from + (stop.empty() ? "" : " (" + esc(stop) + ")") + "</td></tr>\n";
}

void section_design(Ctx& c, const fs::path& src, const ReportOptions& opt) {
    const Scene part = load_scene((src / "scenes" / "fig1_point.json").string());
    DesignOptions o;
    o.lin_limit = 15;
    o.ang_limit = 100;
    o.threads = opt.threads;
    o.seed = opt.seed;
    o.starts = default_starts(part, DesignTarget{});   // (the sink's and the line sink's)
    if (opt.quick) {
        o.local_evaluations = 120;
        o.verify_starts = 6;
    }
    c.html << c.heading("Inverse design", "design") << "<p>Plate motions designed by <code>design()</code> (NLopt COBYLA from "
           << o.starts << " seeded feasible starts, " << o.local_evaluations << " evaluations each) so that " << esc(part.name)
           << "'s point part has its unique stable fixed point at the target, within peak limits of " << fmt(o.lin_limit, 3)
           << " m/s² and " << fmt(o.ang_limit, 3)
           << " rad/s² (each axis' summed signal over the period) and keeping g + a<sub>z</sub> ≥ " << fmt(o.flight_margin, 3)
           << " g over the plate; each verified on a " << o.verify_grid << "×" << o.verify_grid
           << " grid (one stable fixed point within " << fmt(1e3 * o.fixed_point_tolerance, 3) << " mm) and by "
           << o.verify_starts << " full-dynamics runs from seeded random starts (ending within "
           << fmt(1e3 * o.verify_distance, 3) << " mm), and by a part released at rest at the target still within that "
           << "distance after " << fmt(o.hold, 3)
           << " s of full dynamics (the last column). Odd harmonics (n = 1, 3) on x, "
              "y, rx, ry make the field odd about the design's centre (a fixed point by construction); adding −α×D to the "
              "linear acceleration moves it onto the target exactly. Tilting in circles cones: the plate turns about z "
              "at a second-order rate the asymptotic field does not see, and the whole field, the sink with it, turns "
              "about the plate's centre; so a sink at D is held to a coning rate of at most (verification distance) / "
              "(2 |D| hold). The same construction pulls a rigid part's position at every orientation (its row: "
              "verified at each of the grid's orientations, by runs from random positions and orientations, and "
              "held; the part may turn on at the sink).</p>\n"
              "<table><tr><th>target</th><th>verified</th><th>unique</th><th>rate [1/s]</th><th>evaluations</th>"
              "<th>cycles</th><th>peaks over the period</th><th>worst end distance [mm]</th><th>seconds</th>"
              "<th>coning [rad/s]</th><th>from the target, after the hold</th></tr>\n";
    DesignSummary first;
    Vec2 first_at = Vec2::Zero();
    const Vec2 targets[] = {{0.02, -0.01}, {-0.025, 0.015}};
    int k = 0;
    for (const Vec2& at : targets) {
        DesignTarget t;
        t.at = at;
        const DesignSummary d = design(part, t, o);
        const std::string name = "sink (" + fmt(at.x(), 3) + ", " + fmt(at.y(), 3) + ")";
        c.html << design_cells(c, name, d) << "<td>" << fmt(1e3 * d.worst_end_distance, 3) << "</td><td>" << fmt(d.seconds, 3)
               << "</td><td>" << fmt(d.coning, 3) << "</td>"
               << held_cell(c, name, d.held.end_distance, o.verify_distance, "", d.held.stop);
        if (k++ == 0) {   // the figures are the first target's
            first = d;
            first_at = at;
        }
    }
    {   // a rigid part's sink: its position, whatever its orientation (the same construction)
        const Scene rigid = load_scene((src / "scenes" / "fig4.json").string());
        DesignTarget t;
        t.at = targets[0];
        const DesignSummary d = design(rigid, t, o);
        const std::string name =
            esc(rigid.name) + "'s rigid part: sink (" + fmt(t.at.x(), 3) + ", " + fmt(t.at.y(), 3) + "), any orientation";
        c.html << design_cells(c, name, d) << "<td>" << fmt(1e3 * d.worst_end_distance, 3) << "</td><td>" << fmt(d.seconds, 3)
               << "</td><td>" << fmt(d.coning, 3) << "</td>"
               << held_cell(c, name, d.held.end_distance, o.verify_distance, "", d.held.stop);
    }
    {   // a line sink (design.cpp: y and rx, turned and shifted onto the line)
        DesignTarget t;
        t.kind = DesignTargetKind::LineSink;
        t.at = Vec2(0.01, -0.02);
        t.theta = 0.6;
        const DesignSummary d = design(part, t, o);
        const Vec2 nrm(-std::sin(t.theta), std::cos(t.theta));
        const Trajectory hold = simulate(d.scene, Dynamics::Full, Vec3(t.at.x(), t.at.y(), 0), Vec3::Zero(), o.hold, o.hold);
        const double walked = hold.samples.empty() ? std::numeric_limits<double>::quiet_NaN()
                                                   : std::abs((hold.samples.back().q.head<2>() - t.at).dot(nrm));
        const std::string name =
            "line sink through (" + fmt(t.at.x(), 3) + ", " + fmt(t.at.y(), 3) + ") along " + fmt(t.theta, 3) + " rad";
        c.html << design_cells(c, name, d) << "<td>" << fmt(1e3 * d.worst_end_distance, 3) << " (from the line)</td><td>"
               << fmt(d.seconds, 3) << "</td><td>" << fmt(coning_rate(d.scene.plate), 3) << "</td>"
               << held_cell(c, name, walked, o.verify_distance, " (from the line)",
                            hold.stop.reason != StopReason::None ? hold.stop.describe() : "");
    }
    c.html << "</table>\n<p>For the sinks the last column is the verification's hold; the line sink's (y and rx "
              "only: no coning) is measured here, released on the line for "
           << fmt(o.hold, 3)
           << " s. A distance "
              "beyond the verification's is marked.</p>\n";
    {
        const DesignSummary& d = first;
        const Vec2& at = first_at;
        const std::string n = "design_sink";
        {
            auto o2 = c.data(n + "_signal.dat");
            for (int i = 0; i <= 200; ++i) {
                const double tt = d.scene.plate.T * i / 200;
                Vec3 pdd, wd;
                d.scene.plate.acceleration(tt, pdd, wd);
                o2 << tt << ' ' << pdd.transpose() << ' ' << wd.transpose() << '\n';
            }
        }
        int reached = 0;   // the verification's own test (design.cpp): no early stop, within its distance
        for (const DesignStartRun& r : d.runs) reached += r.stop.empty() && r.end_distance <= o.verify_distance;
        GridSpec g;
        g.nx = g.ny = 11;
        g.nth = 1;
        FieldOptions fo;
        fo.threads = opt.threads;
        const Field f = compute_field(d.scene, g, fo);
        {
            auto o3 = c.data(n + "_field.dat");
            const double scale = 0.004 / std::max(1e-12, [&] {
                                     double m = 0;
                                     for (const auto& p : f.points) m = std::max(m, p.twist.head<2>().norm());
                                     return m;
                                 }());
            for (const auto& p : f.points)
                o3 << p.q[0] << ' ' << p.q[1] << ' ' << scale * p.twist[0] << ' ' << scale * p.twist[1] << '\n';
            auto o4 = c.data(n + "_runs.dat");
            for (const DesignStartRun& r : d.runs) {
                const Trajectory tr =
                    simulate(d.scene, Dynamics::Full, Vec3(r.x, r.y, 0), Vec3::Zero(), r.seconds, r.seconds / 200);
                for (const Sample& smp : tr.samples) o4 << smp.q[0] << ' ' << smp.q[1] << '\n';
                o4 << "\n\n";
            }
            c.data(n + "_target.dat") << at.x() << ' ' << at.y() << '\n';
        }
        c.plot(n + "_signal",
               "set xlabel 't [s]'\nset ylabel 'm/s²'\nset y2label 'rad/s²'\nset ytics nomirror\nset y2tics\n"
               "set key outside right\nplot for [i=2:4] 'data/" +
                   n +
                   "_signal.dat' u 1:i w l lw 2 t word('x y z', i-1), "
                   "for [i=5:7] 'data/" +
                   n + "_signal.dat' u 1:i axes x1y2 w l dt 2 lw 2 t word('rx ry rz', i-4)\n",
               "The designed signal over one period: the plate's linear (solid) and angular (dashed) acceleration.", "800,420");
        c.plot(n + "_field",
               "set xlabel 's_x [m]'\nset ylabel 's_y [m]'\nset size ratio -1\nset key outside right\n"
               "plot 'data/" +
                   n +
                   "_field.dat' u 1:2:3:4 w vec head size 0.002,20 lc rgb '#777777' t 'field', "
                   "'data/" +
                   n +
                   "_runs.dat' u 1:2 w l lc rgb '#3050c0' t 'full dynamics, random starts', "
                   "'data/" +
                   n + "_target.dat' u 1:2 w p pt 7 ps 2 lc rgb '#c02020' t 'target'\n",
               design_runs_caption(reached, static_cast<int>(d.runs.size()), o.verify_distance, d.verified, d.failure),
               "800,640");
    }
}

// A design's options in the report: the defaults with the report's threads and seed; with --quick a
// smaller search and fewer verification runs.
DesignOptions report_design_options(const ReportOptions& opt, int quick_starts, int quick_evaluations, int quick_runs) {
    DesignOptions o;
    o.threads = opt.threads;
    o.seed = opt.seed;
    if (opt.quick) {
        o.starts = quick_starts;
        o.local_evaluations = quick_evaluations;
        o.verify_starts = quick_runs;
    }
    return o;
}

// The orienter (design.cpp's weathervane): a part with a rubber foot turned to one orientation from
// anywhere by a plate that only translates; theta' over a turn and the full-dynamics runs' theta(t).
void section_orient(Ctx& c, const fs::path& src, const ReportOptions& opt) {
    const Scene part = load_scene((src / "scenes" / "foot.json").string());
    const DesignOptions o = report_design_options(opt, 2, 80, 8);
    DesignTarget t;
    t.kind = DesignTargetKind::Orient;
    t.theta = 2.0;
    const DesignSummary d = design(part, t, o);
    const auto mu = part.part.mu;
    c.html << "<h3>Orienting a part</h3>\n<p>" << esc(part.name) << ": Fig. 4's triangle with friction coefficients "
           << fmt(mu[0], 3) << ", " << fmt(mu[1], 3) << ", " << fmt(mu[2], 3)
           << " on its contacts (a rubber foot), target orientation θ = " << fmt(t.theta, 3)
           << " rad, position free. A plate that only translates makes the twist the same at every position "
              "(full dynamics = U-dynamics: no tilt, no coning); with one friction coefficient on every contact it "
              "cannot turn the part at all (friction's torque −(Σ μ<sub>i</sub>N<sub>i</sub>r<sub>i</sub>)×u "
              "vanishes when the normal forces balance friction's moment), with unequal ones it is a weathervane. "
              "Designed on a ring of 12 orientations ("
           << d.starts << " starts, " << o.local_evaluations << " evaluations each), turned onto θ, verified on a ring of "
           << d.ring_theta.size() << " orientations and by " << d.runs.size() << " full-dynamics runs from random starts.</p>\n"
           << "<table><tr><th>target</th><th>verified</th><th>unique</th><th>rate [1/s]</th><th>evaluations</th>"
              "<th>cycles</th><th>peaks over the period</th><th>worst end angle [rad]</th><th>travel at θ "
              "[m/s]</th><th>seconds</th></tr>\n"
           << design_cells(c, "orient " + fmt(t.theta, 3), d) << "<td>" << fmt(d.worst_end_distance / o.verify_distance * 0.05, 3)
           << "</td><td>" << fmt(d.transport_mean.norm(), 3) << "</td><td>" << fmt(d.seconds, 3) << "</td></tr>\n</table>\n";
    if (d.ring_theta.empty()) return;
    {
        auto r = c.data("design_orient_ring.dat");
        for (std::size_t k = 0; k <= d.ring_theta.size(); ++k) {
            const std::size_t i = k % d.ring_theta.size();
            r << (k == d.ring_theta.size() ? 2 * kPi : d.ring_theta[i]) << ' ' << d.ring_twist[i][2] << '\n';
        }
        c.data("design_orient_target.dat") << wrap_angle(t.theta) + (wrap_angle(t.theta) < 0 ? 2 * kPi : 0) << " 0\n";
        auto runs = c.data("design_orient_runs.dat");
        for (const DesignStartRun& s : d.runs) {
            IntegrationOptions io;
            io.rtol = 1e-7;   // (the verification's)
            const Trajectory tr =
                simulate(d.scene, Dynamics::Full, Vec3(s.x, s.y, s.theta), Vec3::Zero(), s.seconds, s.seconds / 200, io);
            double prev = 0, unwrapped = 0;
            for (std::size_t k = 0; k < tr.samples.size(); ++k) {
                const double th = tr.samples[k].q[2];
                unwrapped = k == 0 ? th : unwrapped + wrap_angle(th - prev);
                prev = th;
                // (shown as the distance to the target orientation, in (-pi, pi])
                runs << tr.samples[k].t << ' ' << wrap_angle(unwrapped - t.theta) << '\n';
            }
            runs << "\n\n";
        }
    }
    int stable_zeros = 0;
    for (std::size_t k = 0; k < d.ring_twist.size(); ++k)
        stable_zeros += d.ring_twist[k][2] > 0 && d.ring_twist[(k + 1) % d.ring_twist.size()][2] <= 0;
    c.plot("design_orient_ring",
           "set xlabel 'θ [rad]'\nset ylabel 'θ′ [rad/s]'\nset xrange [0:2*pi]\nset key outside right\n"
           "plot 'data/design_orient_ring.dat' u 1:2 w lp pt 7 ps 0.5 lw 2 t 'designed: θ′ at the centre', 0 w l lc rgb "
           "'#999999' notitle, "
           "'data/design_orient_target.dat' u 1:2 w p pt 7 ps 2 lc rgb '#c02020' t 'target θ'\n",
           "The designed plate motion's turning rate over a full turn of the part, at the centre (the same at every "
           "position of the 7³ grid, to " +
               fmt(d.transport_spread, 2) + " of v_ref): " + std::to_string(stable_zeros) +
               " stable zero(s) (θ′ falling through zero), the one found at θ = " + fmt(d.fixed_point[2], 4) + " rad.",
           "800,420");
    int reached = 0;
    for (const DesignStartRun& s : d.runs) reached += s.stop.empty() && s.end_distance <= o.verify_distance;
    c.plot("design_orient_runs",
           "set xlabel 't [s]'\nset ylabel 'θ − target [rad]'\nset yrange [-pi:pi]\nset key off\n"
           "plot 'data/design_orient_runs.dat' u 1:2 w l lw 1.5\n",
           "The verification's full-dynamics runs from random starts (rtol 1e-7): " + std::to_string(reached) + " of " +
               std::to_string(d.runs.size()) + " end within 0.05 rad of the target.",
           "800,420");
}

// A rigid part's fixed point (design.cpp): fig4's part at (0.02, -0.01, 0.5). The design starts from a
// half-turn pair and breaks it with rz about its centre where that verifies (break_pair); the table and
// the runs' theta(t) show what the verification found (the target's share of the random starts and any
// competitor's).
void section_fixed_point(Ctx& c, const fs::path& src, const ReportOptions& opt) {
    const Scene part = load_scene((src / "scenes" / "fig4.json").string());
    const DesignOptions o = report_design_options(opt, 2, 150, 10);
    DesignTarget t;
    t.kind = DesignTargetKind::FixedPoint;
    t.at = Vec2(0.02, -0.01);
    t.theta = 0.5;
    const DesignSummary d = design(part, t, o);
    const std::string name = "fixed point (" + fmt(t.at.x(), 3) + ", " + fmt(t.at.y(), 3) + ", " + fmt(t.theta, 3) + ")";
    c.html << "<h3>Fixing a rigid part: position and orientation</h3>\n<p>" << esc(part.name) << "'s part, target (x, y, θ) = ("
           << fmt(t.at.x(), 3) << ", " << fmt(t.at.y(), 3) << ", " << fmt(t.theta, 3) << "), default limits, " << d.starts
           << " starts in all, " << o.local_evaluations
           << " evaluations each. What the design reports about how it got there:</p>\n<ul>\n";
    for (const std::string& n : d.notes) c.html << "<li>" << esc(n) << "</li>\n";
    c.html << "</ul>\n<table><tr><th>target</th><th>verified</th><th>unique</th><th>rate [1/s]</th><th>evaluations</th>"
              "<th>cycles</th><th>peaks over the period</th><th>target's share of the runs</th><th>other stable fixed points "
              "(share)</th><th>seconds</th>"
              "<th>from the target, after the hold</th></tr>\n"
           << design_cells(c, name, d) << "<td>" << fmt(d.basin_share, 3) << "</td><td>";
    for (const DesignSummary::Competitor& k : d.competitors)
        c.html << "(" << fmt(k.point.q[0], 4) << ", " << fmt(k.point.q[1], 4) << ", " << fmt(k.point.q[2], 4)
               << "): " << fmt(k.basin_share, 3) << "<br>";
    c.html << "</td><td>" << fmt(d.seconds, 3) << "</td>"
           << held_cell(c, name, d.held.end_distance, o.verify_distance, "", d.held.stop) << "</table>\n";
    if (d.runs.empty()) return;
    {
        auto runs = c.data("design_fixed_point_runs.dat");
        IntegrationOptions io;
        io.rtol = 1e-7;   // (the verification's)
        for (const DesignStartRun& s : d.runs) {
            const Trajectory tr =
                simulate(d.scene, Dynamics::Full, Vec3(s.x, s.y, s.theta), Vec3::Zero(), s.seconds, s.seconds / 200, io);
            for (const Sample& smp : tr.samples) {
                double off = wrap_angle(smp.q[2] - t.theta);   // (shown in [-pi/2, 3 pi/2): a half-turn twin at pi)
                if (off < -kPi / 2) off += 2 * kPi;
                runs << smp.t << ' ' << (smp.q.head<2>() - t.at).norm() << ' ' << off << '\n';
            }
            runs << "\n\n";
        }
    }
    // Where the runs ended, counted here: at the target, at each competing fixed point, elsewhere.
    const double ang = 0.05;   // [rad] (the verification's angle tolerance)
    auto ends_at = [&](const DesignStartRun& r, const Vec3& q) {
        return r.stop.empty() && (r.end.head<2>() - q.head<2>()).norm() <= o.verify_distance &&
               std::abs(wrap_angle(r.end[2] - q[2])) <= ang;
    };
    std::string where;
    int accounted = 0;
    const Vec3 goal(t.at.x(), t.at.y(), t.theta);
    int n0 = 0;
    for (const DesignStartRun& r : d.runs) n0 += ends_at(r, goal);
    accounted += n0;
    where = std::to_string(n0) + " of " + std::to_string(d.runs.size()) + " end within " + fmt(1e3 * o.verify_distance, 3) +
            " mm and " + fmt(ang, 3) + " rad of the target";
    for (const DesignSummary::Competitor& k : d.competitors) {
        int n = 0;
        for (const DesignStartRun& r : d.runs) n += !ends_at(r, goal) && ends_at(r, k.point.q);
        accounted += n;
        where += ", " + std::to_string(n) + " at the stable fixed point (" + fmt(k.point.q[0], 4) + ", " + fmt(k.point.q[1], 4) +
                 ") turned " + fmt(wrap_angle(k.point.q[2] - t.theta), 3) + " rad from it";
    }
    where += ", " + std::to_string(static_cast<int>(d.runs.size()) - accounted) + " elsewhere";
    c.plot("design_fixed_point_runs",
           "set xlabel 't [s]'\nset ylabel 'θ − target [rad]'\nset y2label 'distance from the target [m]'\n"
           "set ytics nomirror\nset y2tics\nset yrange [-pi/2:3*pi/2]\nset key outside right\n"
           "plot 'data/design_fixed_point_runs.dat' u 1:3 w l lw 1.5 lc rgb '#3050c0' t 'θ − target', "
           "'' u 1:2 axes x1y2 w l lw 1 lc rgb '#c08020' t 'distance'\n",
           "The verification's full-dynamics runs from random (x, y, θ) (rtol 1e-7; angles shown from −π/2 to 3π/2): " + where +
               (d.verified ? "." : "; the design failed verification: " + d.failure + "."),
           "800,420");
}

}   // namespace plate::report
