#include "internal.hpp"

namespace plate::design_detail {

// A rigid part's sink, verified: at the target, for each orientation of the verification grid, the
// position's field vanishes within fixed_point_tolerance (Newton from the target, 3 mm central
// differences) with both eigenvalues' real parts negative; full-dynamics runs from random (x, y, theta)
// end within verify_distance of the target's position, whatever their orientation; the hold.
DesignSummary& verify_rigid_sink(DesignSummary& sum, const Field& field, const DesignTarget& target, const DesignOptions& opt,
                                 std::atomic<long>& cycles, Clock::time_point t0) {
    sum.fixed_points = FixedPoints{};
    const double h = 0.003;
    int held = 0;
    std::string why;
    for (int k = 0; k < field.grid.nth; ++k) {
        DesignSummary::OrientationPull pull;
        pull.theta = field.grid.th0 + k * field.grid.dth();
        Vec2 s = target.at;
        bool ok = false;
        for (int it = 0; it < 6 && !ok; ++it) {
            Vec2 v0 = Vec2::Zero();
            Eigen::Matrix2d J;
            if (!position_pull(sum.scene, s, pull.theta, opt.cycle, h, v0, J, cycles)) break;
            pull.eigenvalues = J.eigenvalues();
            const Vec2 step = J.fullPivLu().solve(v0);
            if (!step.allFinite()) break;
            s -= step;
            ok = step.norm() < 1e-6;
        }
        pull.zero = s;
        sum.pulls.push_back(pull);
        const bool here = ok && (s - target.at).norm() <= opt.fixed_point_tolerance &&
                          std::max(pull.eigenvalues[0].real(), pull.eigenvalues[1].real()) < 0;
        held += here;
        if (!here && why.empty())
            why = "at orientation " + std::to_string(pull.theta) + " rad the position's field " +
                  (ok ? "vanishes " + std::to_string((s - target.at).norm()) + " m from the target" +
                            (std::max(pull.eigenvalues[0].real(), pull.eigenvalues[1].real()) < 0 ? "" : ", not attracting")
                      : std::string("has no zero found near the target"));
    }
    sum.unique = held == field.grid.nth;   // (one position for every orientation)
    sum.fixed_point = Vec3(sum.pulls.front().zero.x(), sum.pulls.front().zero.y(), sum.pulls.front().theta);
    // The runs' durations: the position's field averaged over the grid's orientations (the part turns
    // as it travels), interpolated as for a point part.
    Field avg = field;
    avg.grid.nth = 1;
    avg.points.assign(field.grid.nx * field.grid.ny, FieldPoint{});
    for (int i = 0; i < field.grid.nx; ++i)
        for (int j = 0; j < field.grid.ny; ++j) {
            // (over the orientations whose cycle converged; none: NaN, and the runs take the cap)
            Vec3 m = Vec3::Zero();
            int n = 0;
            for (int k = 0; k < field.grid.nth; ++k) {
                const Vec3& w = field.points[field.grid.index(i, j, k)].twist;
                if (!w.allFinite()) continue;
                m += w;
                ++n;
            }
            avg.points[avg.grid.index(i, j, 0)].twist = m / n;
        }
    return sink_verdict(sum, avg, target, opt, why, cycles, t0);
}

DesignSummary design_sink(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt, double T) {
    const auto t0 = Clock::now();
    DesignSummary sum;
    sum.notes.push_back(
        "odd harmonics on x, y, rx, ry only: the field is odd about the design's centre, so the "
        "centre is a fixed point by construction and fixed points come in pairs s, -s");
    sum.notes.push_back(
        "the design's centre moved onto the target by adding -alpha x D to the linear acceleration "
        "(exact: the field shifts by D)");
    if (std::isfinite(sink_coning_limit(target.at, opt)))
        sum.notes.push_back("coning held to " + std::to_string(sink_coning_limit(target.at, opt)) +
                            " rad/s: the plate's second-order turn about z, which the field does not see, turns the "
                            "sink about the plate's centre; at most half the verification distance over the hold");
    else if (target.at.norm() > 0)   // (without a hold nothing limits the coning: say so)
        sum.notes.push_back(
            "coning not limited (no hold, no --max-coning): the plate's second-order turn about z turns "
            "the sink about the plate's centre, so a part held at the target walks off it in time "
            "(not checked)");
    std::atomic<long> cycles{0};
    const auto make = [&] { return SinkProblem(part_scene, target.at, opt, T, &cycles); };
    const std::vector<double> best = multistart<SinkProblem>(opt, -HUGE_VAL, make, sum.evaluations);
    start_summary(sum, part_scene, "_sink", T);   // (no motion unless a design is found)
    if (best.empty()) {
        sum.failure = kNoFeasibleMotion;
        return finished(sum, cycles, t0);
    }
    make().evaluate(best, &sum.rate, &sum.eigenvalues);
    sum.scene.plate = combined(shift_motion(sink_motion(best, T), target.at));
    sum.min_vertical_margin = vertical_margin(sum.scene.plate, sum.scene.g, flight_region(sum.scene, opt));
    sum.coning = coning_rate(sum.scene.plate);
    if (opt.robust && part_scene.part.point)
        sum.predicted_radius95 = first_order_radius95(sum.scene, *opt.robust, target.at, opt.cycle, cycles);

    // --- verification: the field's fixed points on the grid (a rigid part: where its position's
    // field vanishes near the target, at each of the grid's orientations), then full dynamics from
    // random starts (each for as long as the field takes to bring it in) and from the target itself
    // (the hold).
    const Field field = verification_field(sum.scene, opt);
    if (!part_scene.part.point) return verify_rigid_sink(sum, field, target, opt, cycles, t0);
    sum.fixed_points = find_fixed_points(sum.scene, field);
    int stable = 0, stable_at_target = 0;
    double nearest = std::numeric_limits<double>::infinity();
    for (const FixedPoint& p : sum.fixed_points.points) {
        if (p.stability != Stability::Stable) continue;
        ++stable;
        const double d = (p.q.head<2>() - target.at).norm();
        if (d < nearest) {
            nearest = d;
            sum.fixed_point = p.q;
            sum.fixed_point_eigenvalues = p.eigenvalues;
        }
        stable_at_target += d <= opt.fixed_point_tolerance;
    }
    for (const FixedLine& l : sum.fixed_points.lines) stable += l.stability == Stability::Stable;
    const std::string gaps = unsearched(sum.fixed_points);
    sum.unique = stable == 1 && stable_at_target == 1 && gaps.empty();
    return sink_verdict(sum, field, target, opt,
                        "the designed field has " + std::to_string(stable) + " stable fixed point(s) or line(s) on the " +
                            std::to_string(opt.verify_grid) + "x" + std::to_string(opt.verify_grid) + " grid, " +
                            std::to_string(stable_at_target) + " within " + std::to_string(opt.fixed_point_tolerance) +
                            " m of the target" + (gaps.empty() ? "" : "; not searched: " + gaps),
                        cycles, t0);
}


}   // namespace plate::design_detail
