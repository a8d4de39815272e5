// The report's identification section (issue 52): fig1_point's part filmed at friction it does not
// declare (kinetic 0.27, static 0.33 against the scene's 0.30 and 0.36), one stroboscopic track of 5 s
// at 0.1 mm, fitted by plate identify (mu_k, mu_s) -- the observed frames against the fitted model's
// prediction and the residuals, the estimates with their linearised and profile-likelihood intervals
// beside the truth, and the profiles with the 3.84 line. One small problem (a few seconds), the same in
// quick and full runs: the section shows the method, bench_identify measures it.
#include "report_sections.hpp"

#include "plate/identify.hpp"
#include "plate/observe.hpp"
#include "plate/profile.hpp"
#include "plate/scene_io.hpp"

#include <cmath>
#include <string>
#include <vector>

namespace plate::report {
namespace fs = std::filesystem;
using namespace html;

namespace {

// An interval as the page shows it: "[lo, hi]", an end at a physical bound marked.
std::string interval_text(double lo, double hi, bool lo_bound = false, bool hi_bound = false) {
    if (!std::isfinite(lo) || !std::isfinite(hi)) return "none (not identifiable)";
    return "[" + fmt(lo, 4) + (lo_bound ? " (bound)" : "") + ", " + fmt(hi, 4) + (hi_bound ? " (bound)" : "") + "]";
}

void tracks_figure(Ctx& c, const Track& seen, const Track& fitted) {
    {
        auto d = c.data("identify_track.dat");
        auto r = c.data("identify_residuals.dat");
        for (std::size_t k = 0; k < seen.t.size() && k < fitted.t.size(); ++k) {
            d << seen.t[k] << ' ' << 1e3 * seen.q[k].x() << ' ' << 1e3 * seen.q[k].y() << ' ' << 1e3 * fitted.q[k].x() << ' '
              << 1e3 * fitted.q[k].y() << '\n';
            r << seen.t[k] << ' ' << 1e3 * (seen.q[k].x() - fitted.q[k].x()) << ' ' << 1e3 * (seen.q[k].y() - fitted.q[k].y())
              << '\n';
        }
    }
    c.plot("identify_track",
           "set xlabel 't [s]'\nset ylabel 'position in the plate frame [mm]'\nset key outside right\nset grid\n"
           "plot 'data/identify_track.dat' u 1:2 w p pt 6 ps 0.6 lc rgb '#c03030' t 's_x observed', "
           "'' u 1:4 w l lw 2 lc rgb '#601010' t 's_x fitted', "
           "'' u 1:3 w p pt 6 ps 0.6 lc rgb '#3050c0' t 's_y observed', '' u 1:5 w l lw 2 lc rgb '#102060' t 's_y fitted'\n",
           "The track (one frame a period, at phase 0.25; circles) and the fitted model's prediction at the same "
           "stamps, from the fitted start (lines).",
           "760,380");
    c.plot("identify_residuals",
           "set xlabel 't [s]'\nset ylabel 'observed - fitted [mm]'\nset key outside right\nset grid\n"
           "set yrange [-0.45:0.45]\n"
           "plot 'data/identify_residuals.dat' u 1:2 w p pt 7 ps 0.5 lc rgb '#c03030' t 's_x', "
           "'' u 1:3 w p pt 7 ps 0.5 lc rgb '#3050c0' t 's_y', 0.2 w l dt 2 lc rgb '#888888' t '+-2 sd of the noise', "
           "-0.2 w l dt 2 lc rgb '#888888' notitle\n",
           "Residuals: they should look like the camera's noise (0.1 mm sd), without a trend.", "760,300");
}

void profile_figures(Ctx& c, const IdentifySummary& s, const ProfileSummary& p, const std::vector<double>& truth) {
    for (std::size_t i = 0; i < p.profiles.size(); ++i) {
        const ParameterProfile& pr = p.profiles[i];
        const FittedParameter& f = s.params[i];
        const std::string n = "identify_profile_" + pr.name;
        {
            auto d = c.data(n + ".dat");
            for (const ProfilePoint& q : pr.points) d << q.value << ' ' << q.dchi2 << '\n';
        }
        double x0 = pr.points.front().value, x1 = pr.points.back().value;
        const double pad = 0.05 * (x1 - x0);
        // (gnuplot's enhanced text: mu_k is set as a Greek mu with subscript k)
        const std::string label = pr.name.rfind("mu_", 0) == 0 ? "μ_{" + pr.name.substr(3) + "}" : pr.name + " [m]";
        std::string script = "set xlabel '" + label + "'\nset ylabel 'χ^2 - χ^2_{min}'\nset key below\nset grid\n" +
                             "set xrange [" + fmt(x0 - pad, 8) + ":" + fmt(x1 + pad, 8) + "]\nset yrange [-0.5:10]\n" +
                             "set arrow from " + fmt(truth[i], 8) + ",-0.5 to " + fmt(truth[i], 8) +
                             ",10 nohead dt 3 lw 2 lc rgb '#208020'\n";
        std::string plot = "plot 'data/" + n + ".dat' u 1:2 w lp pt 7 lw 2 lc rgb '#3050c0' t 'profile (re-minimised)', " +
                           fmt(kProfileThreshold95, 6) + " w l dt 2 lw 2 lc rgb '#c03030' t '3.84 (95 %)'";
        const double within = (pr.linear_hi - pr.linear_lo) / (2 * kZ95);   // (the profile's counterpart: NaN if none)
        if (f.identifiable && within > 0)
            plot += ", ((x - " + fmt(f.estimate, 10) + ") / " + fmt(within, 10) +
                    ")**2 w l dt 4 lc rgb '#888888' t 'linearised within the cell: ((x - estimate) / sd)^2'";
        plot += ", NaN w l dt 3 lw 2 lc rgb '#208020' t 'truth'\n";
        c.plot(n, script + plot,
               "Profile likelihood of " + pr.name + ": " + esc(pr.verdict) + ". Interval " +
                   interval_text(pr.lo, pr.hi, pr.lo_end == ProfileEnd::AtBound, pr.hi_end == ProfileEnd::AtBound) + "; " +
                   std::to_string(pr.simulations) + " simulations, " + fmt(pr.seconds, 3) + " s.",
               "640,460");
    }
}

// What the run says of the static coefficient: a part that sticks only briefly after its start shows
// it through a threshold, where a linearised interval can run below the kinetic coefficient.
std::string static_sentence(const FittedParameter& f, const ParameterProfile& pr) {
    std::string s = "The static coefficient's linearised interval (within the fit's cell) ";
    if (!f.identifiable)
        s += "is none (judged not identifiable)";
    else
        s += std::string(pr.linear_lo < pr.bound_lo ? "runs below" : "stays above") + " the kinetic coefficient " +
             fmt(pr.bound_lo, 4) + (pr.linear_lo < pr.bound_lo ? " (no static coefficient can)" : "");
    s += "; its profile ";
    if (!pr.identifiable) return s + "stays within 3.84 of its minimum from bound to bound: not identifiable.";
    if (pr.lo_end == ProfileEnd::AtBound || pr.hi_end == ProfileEnd::AtBound)
        return s + "runs to the bound " + fmt(pr.lo_end == ProfileEnd::AtBound ? pr.bound_lo : pr.bound_hi, 4) +
               ": the track bounds it on one side only.";
    return s + "crosses 3.84 on both sides.";
}

}   // namespace

void section_identify(Ctx& c, const fs::path& src, const ReportOptions& opt) {
    (void)opt;
    Scene nominal = load_scene((src / "scenes" / "fig1_point.json").string());
    nominal.part.mu_static = Vec3::Constant(0.36);
    const std::vector<std::string> names = {"mu_k", "mu_s"};
    const std::vector<double> truth = {0.27, 0.33};
    Camera cam;
    cam.per_period = 1;
    cam.phase = 0.25;
    cam.noise_xy_mm = 0.1;
    cam.seed = 4;
    const Vec3 start(-0.03, 0.01, 0);
    const double duration = 5;
    Track tr = observe(apply_parameters(nominal, names, truth), cam, Dynamics::Full, start, Vec3::Zero(), duration);
    tr.source = "(filmed at the truth)";
    IdentifyOptions o;
    o.params = names;
    o.threads = 1;
    const IdentifySummary s = identify(nominal, {tr}, o);
    const ProfileSummary p = profile_likelihood(nominal, {tr}, o, s, ProfileOptions{});
    Camera clean = cam;
    clean.noise_xy_mm = 0;
    const Track fitted = observe_at(s.fitted, clean, Dynamics::Full, s.tracks[0].start, Vec3::Zero(), tr.t);

    c.html << c.heading("Identification: friction from a filmed track", "identify")
           << "<p>The point part of <code>scenes/fig1_point.json</code> "
           << "(which declares kinetic 0.30 and, here, static 0.36) filmed at kinetic " << fmt(truth[0]) << " and static "
           << fmt(truth[1]) << " from (" << fmt(1e3 * start.x()) << ", " << fmt(1e3 * start.y()) << ") mm for " << fmt(duration)
           << " s: one frame a period, 0.1 mm noise (seed " << cam.seed << "). <code>plate identify --params mu_k,mu_s "
           << "--profile all</code> fits both and the track's start by Levenberg-Marquardt over the full dynamics ("
           << fmt(s.seconds, 3) << " s; reduced chi-square " << fmt(s.reduced_chi2, 3) << " over " << s.dof
           << " degrees of freedom), then profiles each parameter: chi-square minimised over the other and the start, "
           << "stepped until it rises by 3.84 or reaches the physical bound (" << p.simulations << " simulations, "
           << fmt(p.seconds, 3) << " s). " << static_sentence(s.params[1], p.profiles[1]) << "</p>\n";
    tracks_figure(c, tr, fitted);
    c.html << "<table><tr><th>parameter</th><th>truth</th><th>estimate</th><th>linearised 95 % (within the cell)</th><th>profile "
              "95 %</th>"
           << "<th>reported 95 %</th><th>covers the truth</th><th>verdict</th></tr>\n";
    for (std::size_t i = 0; i < p.profiles.size(); ++i) {
        const FittedParameter& f = s.params[i];
        const ParameterProfile& pr = p.profiles[i];
        const double lo = pr.interval_is_profile ? pr.lo_reported : f.lo, hi = pr.interval_is_profile ? pr.hi_reported : f.hi;
        const bool reported = pr.identifiable && std::isfinite(lo);
        c.html << "<tr><td>" << esc(f.name) << "</td><td>" << fmt(truth[i]) << "</td><td>" << fmt(f.estimate, 5) << "</td><td>"
               << (f.identifiable ? interval_text(pr.linear_lo, pr.linear_hi) : "none (not identifiable)") << "</td><td>"
               << interval_text(pr.lo, pr.hi, pr.lo_end == ProfileEnd::AtBound, pr.hi_end == ProfileEnd::AtBound) << "</td><td>"
               << (reported ? interval_text(lo, hi) + (pr.interval_is_profile ? " (profile, cells' spread added)"
                                                                              : " (linearised, cells' spread added)")
                            : "not identifiable")
               << "</td><td>" << (reported ? (lo <= truth[i] && truth[i] <= hi ? "yes" : "no") : "-") << "</td><td>"
               << esc(pr.verdict) << "</td></tr>\n";
    }
    c.html << "</table>\n";
    profile_figures(c, s, p, truth);
}

}   // namespace plate::report
