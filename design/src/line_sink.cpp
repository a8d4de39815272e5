#include "internal.hpp"

namespace plate::design_detail {

// --- the point-part line sink ------------------------------------------------------------------
// Parameters: cosine and sine coefficients of y and rx, first harmonic. rx couples the plate's
// vertical acceleration to y (alpha x s = (0, 0, alpha_x y)), so the normal force swings with y in
// step with the y shaking and a part drifts along y at a rate that changes sign with y. The line y = 0
// is exact by construction: the motion is mirror symmetric about x = 0 (y and the pseudovector's x
// component keep their signs) and nothing depends on x, so v_x = 0 everywhere; odd harmonics make
// v_y odd in y. The search makes it attract (fast, and over the whole region); rotate_motion turns
// the line onto the direction asked, shift_motion moves it through the point asked.
PlateMotion line_motion(const std::vector<double>& p, double T) { return motion_from(p, {Axis::y, Axis::rx}, {1}, T); }

struct LineSinkProblem : Problem<LineSinkProblem> {
    LineSinkProblem(const Scene& part_, const DesignTarget& t_, const DesignOptions& opt_, double T_, std::atomic<long>* cycles_)
        : Problem(part_, opt_, T_, cycles_), target(t_) {
        // the farthest the region reaches from the line, across it
        const Vec2 nrm(-std::sin(target.theta), std::cos(target.theta));
        for (const Vec2& e : region_edge(opt.region)) reach = std::max(reach, std::abs((e - target.at).dot(nrm)));
    }
    DesignTarget target;
    double reach = 0;
    static constexpr int kParams = 4;
    static constexpr const char* kFamily = "y, rx at n = 1";
    static constexpr int kConstraints = kPeakConstraints;   // six peaks, the flight margin
    double limit(int i) const { return i < 2 ? opt.lin_limit : opt.ang_limit; }
    bool is_free(int i) const { return free({Axis::y, Axis::rx}, {1}, i); }
    PlateMotion placed(const std::vector<double>& p) const {
        return shift_motion(rotate_motion(line_motion(p, T), target.theta), target.at);
    }
    void constraints(const std::vector<double>& p, double* c) const { peak_constraints(placed(p), opt, part, 1.0, c); }
    // The convergence rate onto the line, -dv_y/dy at y = 0 (v_y is odd: v_y(h) / h), and how much of
    // the region the field does not pull towards the line (four distances out to its reach).
    double evaluate(const std::vector<double>& p, double* rate_out = nullptr) {
        ++evaluations;
        Scene sc = part;
        sc.plate = line_motion(p, T);
        const double h = 0.003;
        Vec2 v;
        if (!twist_at(sc, Vec2(0, h), v)) return 1e3;
        const double rate = -v.y() / h;
        if (rate_out) *rate_out = rate;
        double outward = 0;
        for (int k = 1; k <= 4; ++k) {
            const double y = reach * k / 4;
            if (!twist_at(sc, Vec2(0, y), v)) return 1e3;
            outward += std::max(0.0, v.y() / y);
        }
        return -rate + 10 * outward;
    }
};

DesignSummary design_line_sink(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt, double T) {
    const auto t0 = Clock::now();
    DesignSummary sum;
    sum.notes.push_back(
        "y and rx, first harmonic: mirror symmetric about the line's normal and odd, so the field has a "
        "line of fixed points by construction (no drift along it)");
    sum.notes.push_back(
        "the line turned onto the direction asked (the field turns with the motion) and moved through "
        "the point asked by adding -alpha x D to the linear acceleration (the field shifts by D)");
    std::atomic<long> cycles{0};
    const auto make = [&] { return LineSinkProblem(part_scene, target, opt, T, &cycles); };
    const std::vector<double> best = multistart<LineSinkProblem>(opt, -HUGE_VAL, make, sum.evaluations);
    start_summary(sum, part_scene, "_line_sink", T);
    if (best.empty()) {
        sum.failure = kNoFeasibleMotion;
        return finished(sum, cycles, t0);
    }
    make().evaluate(best, &sum.rate);
    sum.eigenvalues = Eigen::Vector2cd(0, -sum.rate);   // along the line neutral, across it the rate
    sum.scene.plate = combined(make().placed(best));
    sum.min_vertical_margin = vertical_margin(sum.scene.plate, sum.scene.g, flight_region(sum.scene, opt));

    // --- verification: on the grid, no velocity along the line and every point off it (by more than
    // the fixed-point tolerance) moving towards it; full dynamics from random starts ending on it.
    const Vec2 dir(std::cos(target.theta), std::sin(target.theta)), nrm(-dir.y(), dir.x());
    const Field f = verification_field(sum.scene, opt);
    int undefined = 0, away = 0;
    double along = 0;
    for (const FieldPoint& p : f.points) {
        if (!p.converged) {
            ++undefined;
            continue;
        }
        const Vec2 v = p.twist.head<2>();
        const double d = (p.q.head<2>() - target.at).dot(nrm);
        along = std::max(along, std::abs(v.dot(dir)));
        away += std::abs(d) > opt.fixed_point_tolerance && !(v.dot(nrm) * d < 0);
    }
    sum.transport_spread = along;                                            // (the largest speed along the line on the grid)
    sum.transport_tolerance = cycle_noise(opt.cycle) * part_scene.v_ref();   // (zero by the symmetry)
    sum.fixed_point = Vec3(target.at.x(), target.at.y(), 0);
    sum.fixed_point_eigenvalues = Eigen::Vector3cd(sum.eigenvalues[0], sum.eigenvalues[1], 0);
    const int stopped = verification_runs(
        sum, opt,
        [&](const DesignStartRun& r) { return settle_time(std::abs((Vec2(r.x, r.y) - target.at).dot(nrm)), sum.rate, opt); },
        [&](const DesignStartRun&, const Vec3& end) { return std::abs((end.head<2>() - target.at).dot(nrm)); });
    // The pull onto the line at 1 mm (the search's rate is a secant at 3 mm, and the grid and the runs
    // do not look closer than 2 and 5 mm: a line that repels between two attracting ones nearby would
    // pass them).
    double pull = 0;
    {
        const Vec2 s1 = target.at + 1e-3 * nrm;
        const LimitCycleSummary c = limit_cycle(sum.scene, Vec3(s1.x(), s1.y(), 0), opt.cycle);
        ++cycles;
        pull = c.converged ? -c.twist.head<2>().dot(nrm) / 1e-3 : std::numeric_limits<double>::quiet_NaN();
    }
    sum.unique = undefined == 0 && away == 0 && along <= sum.transport_tolerance && sum.rate > 0 && pull > 0;
    if (!(sum.rate > 0 && pull > 0))
        sum.failure = "the line does not attract (rate " + std::to_string(sum.rate) + " 1/s at 3 mm, " + std::to_string(pull) +
                      " 1/s at 1 mm)";
    else if (undefined)
        sum.failure = std::to_string(undefined) + " configurations of the field are undefined";
    else if (away)
        sum.failure = std::to_string(away) + " of the grid's points off the line do not move towards it";
    else if (!(along <= sum.transport_tolerance))
        sum.failure = "the field moves parts along the line (" + std::to_string(along) + " m/s)";
    else if (stopped)
        sum.failure = std::to_string(stopped) + " full-dynamics run(s) left the model";
    else if (!(sum.worst_end_distance <= opt.verify_distance))
        sum.failure = "a full-dynamics run ended " + std::to_string(sum.worst_end_distance) + " m from the line";
    else if (!(sum.min_vertical_margin >= opt.flight_margin - 1e-9))
        sum.failure = "the vertical acceleration margin is below the one asked";
    sum.verified = sum.failure.empty();
    return finished(sum, cycles, t0);
}


}   // namespace plate::design_detail
