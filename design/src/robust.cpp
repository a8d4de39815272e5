// Robust designs (DesignOptions::robust, issue 51): the search's first-order spread of a point sink, and
// the verification on the spec's draws that every robust design ends with.
#include "internal.hpp"

#include <sstream>

namespace plate::design_detail {

double first_order_radius95(const Scene& final_scene, const UncertaintySpec& spec, const Vec2& at, const LimitCycleOptions& lo,
                            std::atomic<long>& cycles) {
    RobustnessSummary s;
    try {
        SensitivityOptions so;
        so.refine = false;   // (the design's centre is a zero of the field by its symmetry)
        fixed_point_sensitivities(final_scene, spec, Vec3(at.x(), at.y(), 0), lo, s, so);
    } catch (const FieldUndefined&) {
        return std::numeric_limits<double>::infinity();
    }
    cycles += 2 * static_cast<long>(s.sensitivities.size()) + 4;
    return s.predicted_radius95;
}

void verify_robust(DesignSummary& sum, const DesignTarget& target, const DesignOptions& opt) {
    const auto t0 = Clock::now();
    const bool rigid = !sum.scene.part.point;
    RobustnessOptions ro;
    ro.draws = opt.robust_draws;
    ro.target = Vec3(target.at.x(), target.at.y(), rigid ? target.theta : 0.0);
    ro.grid = verification_grid(sum.scene, opt);
    ro.fixed.cycle.max_rhs_evaluations = 2'000'000;   // (plate robustness's: the command line's cycle budget)
    ro.starts = opt.verify_starts;
    ro.arrive_distance = opt.verify_distance;
    ro.horizon = opt.arrive;
    ro.full_draws = opt.robust_full_draws;
    ro.tasks = runner(opt);
    RobustnessSummary r = robustness(sum.scene, *opt.robust, ro);
    // A draw succeeds where the target is its one attractor and every start's integral curve reaches it
    // within `arrive`.
    int success = 0;
    for (const DrawResult& d : r.draws) {
        bool all = d.outcome == Outcome::unique;
        for (double t : d.arrival) all = all && std::isfinite(t);
        success += all;
    }
    int full_runs = 0, full_arrived = 0;   // the nominal plate's runs and the draws'
    const auto count_full = [&](const DrawResult& d) {
        full_runs += static_cast<int>(d.arrival_full.size());
        for (double t : d.arrival_full) full_arrived += std::isfinite(t);
    };
    count_full(r.nominal_result);
    for (const DrawResult& d : r.draws) count_full(d);
    const int n = static_cast<int>(r.draws.size());
    const double share = static_cast<double>(success) / n;
    std::ostringstream why;
    why.precision(3);
    if (share < opt.robust_share)
        why << "robust: the target unique and reached from every start within " << opt.arrive << " s on " << success << " of "
            << n << " draws of " << opt.robust->source << " (" << share << ", " << opt.robust_share << " asked; "
            << r.counts[static_cast<int>(Outcome::unique)] << " unique)";
    else if (r.radius95 > opt.robust_radius)
        why << "robust: the fixed point's 95 % radius over the draws " << 1e3 * r.radius95 << " mm, over the "
            << 1e3 * opt.robust_radius << " mm asked";
    else if (rigid && r.angle95 > opt.robust_angle)
        why << "robust: the fixed point's 95 % angle over the draws " << r.angle95 << " rad, over the " << opt.robust_angle
            << " rad asked";
    else if (full_arrived < full_runs)
        why << "robust: " << full_runs - full_arrived << " of " << full_runs << " full-dynamics runs (the nominal plate and "
            << opt.robust_full_draws << " drawn ones) not within " << opt.verify_distance << " m of the target by " << opt.arrive
            << " s";
    std::ostringstream note;
    note.precision(3);
    note << "robust: " << success << " of " << n << " draws of " << opt.robust->source << " (seed " << opt.robust->seed
         << ", draws the search never saw) with the target unique and reached from all " << ro.starts << " starts within "
         << opt.arrive << " s; 95 % radius " << 1e3 * r.radius95 << " mm (first order " << 1e3 * r.predicted_radius95
         << " mm); full dynamics " << full_arrived << " of " << full_runs << " runs arrived; "
         << std::chrono::duration<double>(Clock::now() - t0).count() << " s";
    sum.notes.push_back(note.str());
    sum.robustness = std::move(r);
    if (!why.str().empty()) {
        sum.verified = false;
        sum.failure = why.str();
    }
    sum.seconds += std::chrono::duration<double>(Clock::now() - t0).count();
}

}   // namespace plate::design_detail
