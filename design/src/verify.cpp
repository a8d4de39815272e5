// What every verification shares: the designed field on the grid, the runs' lengths, the verdicts.
#include "internal.hpp"

namespace plate::design_detail {


// Verification, shared: the designed field on the verify_grid^2 grid over the region, and full
// dynamics from verify_starts seeded random starts, each run for seconds(start) and measured by
// end_distance(start, end); the worst distance and the runs that left the model are tallied.
GridSpec verification_grid(const Scene& sc, const DesignOptions& opt) {
    GridSpec g;
    g.nx = g.ny = opt.verify_grid;
    g.nth = 1;
    g.x0 = g.y0 = -opt.region;
    g.x1 = g.y1 = opt.region;
    if (!sc.part.point) g.nth = opt.verify_grid;   // theta: a full turn
    return g;
}

Field verification_field(const Scene& sc, const DesignOptions& opt) {
    const GridSpec g = verification_grid(sc, opt);
    FieldOptions fo;
    fo.threads = opt.threads;
    fo.tasks = opt.tasks;
    return compute_field(sc, g, fo);
}

// What the grid's fixed-point search could not look at (empty: it searched every cell): cells with an
// undefined corner, cells left when its budget ran out, cells where the part is stuck all period (a
// region of fixed configurations, not a point). A fixed point is called unique only without these.
std::string unsearched(const FixedPoints& f) {
    std::string gaps;
    const auto add = [&](int n, const char* what) {
        if (n > 0) gaps += (gaps.empty() ? "" : ", ") + std::to_string(n) + " cell(s) " + what;
    };
    add(f.undefined_cells, "with an undefined corner");
    add(f.unsearched_cells, "left unsearched (budget)");
    add(f.stuck_cells, "where the part is stuck all period");
    return gaps;
}

// The hold's verdict (empty: held, or no hold asked): released at the target, the part ended beyond
// verify_distance (`unit` names the distance) or left the model.
std::string hold_failure(const DesignSummary& sum, const DesignOptions& opt, const std::string& unit) {
    if (!(opt.hold > 0) || (sum.held.stop.empty() && sum.held.end_distance <= opt.verify_distance)) return "";
    return "released at rest at the target, the part " +
           (sum.held.stop.empty() ? "ended " + std::to_string(sum.held.end_distance) + unit + " away after "
                                  : "stopped (" + sum.held.stop + ") within ") +
           std::to_string(opt.hold) + " s of full dynamics (coning " + std::to_string(sum.coning) + " rad/s)";
}

// The summary's last entries, whatever the outcome: the cycles computed and the wall time.
DesignSummary& finished(DesignSummary& sum, const std::atomic<long>& cycles, Clock::time_point t0) {
    sum.cycles = cycles;
    sum.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return sum;
}

// A verification run's duration: long enough for the slowest mode, at `rate` [1/s], to bring a start
// d0 away within a fifth of the distance asked (2 s to 120 s).
double settle_time(double d0, double rate, const DesignOptions& opt) {
    return std::clamp(std::log(std::max(d0, opt.verify_distance) / (0.2 * opt.verify_distance)) / std::max(rate, 1e-3), 2.0,
                      120.0);
}

// A point part's verification run from `start`: the time the designed field, interpolated bilinearly
// on the verification grid, takes to bring it within a fifth of verify_distance of `target` (RK4 in
// 0.05 s steps), plus half again and 2 s for the interpolation's error; at most 120 s (also if the
// interpolated curve never arrives). Far starts can take several times ln(d0 / d) / rate: the rate is
// the centre's, and the field weakens away from it.
double field_settle_time(const Field& f, const Vec2& start, const Vec2& target, const DesignOptions& opt) {
    const GridSpec& g = f.grid;
    constexpr double h = 0.05, cap = 120;
    if (g.nx < 2 || g.ny < 2) return cap;   // (no cell to interpolate in)
    auto v = [&](const Vec2& s) {
        const double u = std::clamp((s.x() - g.x0) / g.dx(), 0.0, g.nx - 1.0),
                     w = std::clamp((s.y() - g.y0) / g.dy(), 0.0, g.ny - 1.0);
        const int i = std::min(static_cast<int>(u), g.nx - 2), j = std::min(static_cast<int>(w), g.ny - 2);
        const double a = u - i, b = w - j;
        auto at = [&](int di, int dj) -> Vec2 { return f.points[g.index(i + di, j + dj, 0)].twist.head<2>(); };
        return Vec2((1 - a) * (1 - b) * at(0, 0) + a * (1 - b) * at(1, 0) + (1 - a) * b * at(0, 1) + a * b * at(1, 1));
    };
    Vec2 s = start;
    for (double t = 0; t < cap; t += h) {
        if ((s - target).norm() <= 0.2 * opt.verify_distance) return std::min(1.5 * t + 2, cap);
        const Vec2 k1 = v(s), k2 = v(s + 0.5 * h * k1), k3 = v(s + 0.5 * h * k2), k4 = v(s + h * k3);
        s += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
        if (!s.allFinite()) break;
    }
    return cap;
}
// The summary's scene before a design is found: the part on a plate at rest.
void start_summary(DesignSummary& sum, const Scene& part, const std::string& suffix, double T) {
    sum.scene = part;
    sum.scene.name = part.name + suffix;
    sum.scene.plate = PlateMotion{};
    sum.scene.plate.T = T;
}

// The position's field v0 at (s, theta) and its Jacobian in s by central differences of h: five limit
// cycles (counted in `cycles`); false if one did not converge.
bool position_pull(const Scene& sc, const Vec2& s, double theta, const LimitCycleOptions& cyc, double h, Vec2& v0,
                   Eigen::Matrix2d& J, std::atomic<long>& cycles) {
    const Vec2 d[5] = {Vec2::Zero(), Vec2(h, 0), Vec2(-h, 0), Vec2(0, h), Vec2(0, -h)};
    Vec2 v[5];
    for (int j = 0; j < 5; ++j) {
        const LimitCycleSummary lc = limit_cycle(sc, Vec3(s.x() + d[j].x(), s.y() + d[j].y(), theta), cyc);
        ++cycles;
        if (!lc.converged) return false;
        v[j] = lc.twist.head<2>();
    }
    v0 = v[0];
    J.col(0) = (v[1] - v[2]) / (2 * h);
    J.col(1) = (v[3] - v[4]) / (2 * h);
    return true;
}


// The designed motion's peaks against the limits, for every target (design() judges what each designer
// returns, a registered kind's too): sum.peaks and sum.corner_peaks set, and a verified design with an
// axis' peak or a set corner limit exceeded (by more than 1e-9 relative: the searches' constraints hold
// to roundoff) fails, naming the axis or the corner's quantity.
void judge_peaks(DesignSummary& sum, const DesignOptions& opt) {
    sum.peaks = axis_peaks(sum.scene.plate);
    sum.corner_half_size = corner_half_size(sum.scene, opt);
    sum.corner_peaks = corner_peaks(sum.scene.plate, sum.corner_half_size);
    for (int a = 0; a < 6 && sum.verified; ++a) {
        const double lim = a < 3 ? opt.lin_limit : opt.ang_limit;
        if (sum.peaks[a] <= lim * (1 + 1e-9)) continue;
        std::ostringstream why;
        why.precision(4);
        const char* unit = a < 3 ? " m/s^2" : " rad/s^2";
        why << "the designed motion's peak on " << axis_name(static_cast<Axis>(a)) << " is " << sum.peaks[a] << unit
            << ", above the limit " << lim << unit << " (the peak of the axis' summed signal over the period)";
        sum.verified = false;
        sum.failure = why.str();
    }
    // (the corners' displacement in mm, their velocity in m/s)
    const struct {
        double peak, limit, scale;
        const char *what, *unit;
    } corners[] = {{sum.corner_peaks.displacement, opt.corner_displacement_limit, 1e3, "displacement", " mm"},
                   {sum.corner_peaks.velocity, opt.corner_velocity_limit, 1, "velocity", " m/s"}};
    for (const auto& k : corners) {
        if (!sum.verified || !(k.limit > 0) || k.peak <= k.limit * (1 + 1e-9)) continue;
        std::ostringstream why;
        why.precision(4);
        why << "the designed motion's corner " << k.what << " peaks at " << k.scale * k.peak << k.unit << ", above the limit "
            << k.scale * k.limit << k.unit << " (the plate's corners at +-(" << sum.corner_half_size.x() << ", "
            << sum.corner_half_size.y() << ") m)";
        sum.verified = false;
        sum.failure = why.str();
    }
}

// The checks every sink and fixed point ends with, where nothing before failed: the hold (`unheld`:
// hold_failure's verdict) and the flight margin; then the summary's end.
DesignSummary& last_checks(DesignSummary& sum, const DesignOptions& opt, const std::string& unheld,
                           const std::atomic<long>& cycles, Clock::time_point t0) {
    if (sum.failure.empty()) sum.failure = unheld;
    if (sum.failure.empty() && !(sum.min_vertical_margin >= opt.flight_margin - 1e-9))
        sum.failure = "the vertical acceleration margin is below the one asked";
    sum.verified = sum.failure.empty();
    return finished(sum, cycles, t0);
}

// A sink's verdict, shared: full-dynamics runs from random starts (each as long as the position
// field `settle` takes to bring it in) and from the target (the hold), then the first check that
// fails: uniqueness (`not_unique` says why not), runs that left the model, a run ending too far, the
// hold, the flight margin.
DesignSummary& sink_verdict(DesignSummary& sum, const Field& settle, const DesignTarget& target, const DesignOptions& opt,
                            const std::string& not_unique, std::atomic<long>& cycles, Clock::time_point t0) {
    const Vec3 hold_at(target.at.x(), target.at.y(), 0);
    const int stopped = verification_runs(
        sum, opt, [&](const DesignStartRun& r) { return field_settle_time(settle, Vec2(r.x, r.y), target.at, opt); },
        [&](const DesignStartRun&, const Vec3& end) { return (end.head<2>() - target.at).norm(); }, &hold_at);
    const std::string unheld = hold_failure(sum, opt, " m");
    if (!sum.unique)
        sum.failure = not_unique;
    else if (stopped)
        sum.failure = std::to_string(stopped) + " full-dynamics run(s) left the model";
    else if (!(sum.worst_end_distance <= opt.verify_distance))
        sum.failure = "a full-dynamics run ended " + std::to_string(sum.worst_end_distance) + " m from the target";
    return last_checks(sum, opt, unheld, cycles, t0);
}


}   // namespace plate::design_detail
