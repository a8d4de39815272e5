#include "internal.hpp"

namespace plate::design_detail {

// --- the point-part transport --------------------------------------------------------------------
// Parameters: cosine and sine coefficients of harmonics n = 1, 2 on x, y and z (a plate that only
// translates). The field is uniform; its value at the centre is driven onto the target.
PlateMotion transport_motion(const std::vector<double>& p, double T) { return motion_from(p, kTranslationAxes, {1, 2}, T); }

struct TransportProblem : Problem<TransportProblem> {
    TransportProblem(const Scene& part_, const Vec2& v_, const DesignOptions& opt_, double T_, std::atomic<long>* cycles_)
        : Problem(part_, opt_, T_, cycles_), target(v_) {}
    Vec2 target;
    static constexpr int kParams = 12;
    static constexpr const char* kFamily = "x, y, z at n = 1, 2";
    static constexpr int kConstraints = kPeakConstraints;   // x, y, z's peaks (the others' zero), the flight margin
    double limit(int) const { return opt.lin_limit; }
    bool is_free(int i) const { return free(kTranslationAxes, {1, 2}, i); }
    void constraints(const std::vector<double>& p, double* c) const {
        peak_constraints(transport_motion(p, T), opt, part, 1.0, c);
    }
    double evaluate(const std::vector<double>& p) {
        ++evaluations;
        Scene sc = part;
        sc.plate = transport_motion(p, T);
        Vec2 v;
        if (!twist_at(sc, Vec2::Zero(), v)) return 1e3;
        return (v - target).norm() / target.norm();
    }
};

DesignSummary design_transport(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt, double T) {
    const auto t0 = Clock::now();
    DesignSummary sum;
    sum.notes.push_back("a plate that only translates (x, y, z): a point part's velocity field is the same everywhere");
    std::atomic<long> cycles{0};
    // A rigid part with one friction coefficient moves on a translating plate as a point part with
    // that coefficient (DesignTarget): the search runs on that point part, the verification on the part.
    Scene point = part_scene;
    if (!point.part.point) {
        sum.notes.push_back(
            "a rigid part with one friction coefficient on a plate that only translates: it moves as a point "
            "part with that coefficient (no turn; the same velocity at every orientation); designed as that "
            "point part, verified as the part itself");
        point.part.point = true;
        point.part.mu.setConstant(part_scene.part.friction().kinetic(0));
    }
    const auto make = [&] { return TransportProblem(point, target.velocity, opt, T, &cycles); };
    // (stop within 0.01% of the target speed)
    const std::vector<double> best = multistart<TransportProblem>(opt, 1e-4, make, sum.evaluations);
    start_summary(sum, part_scene, "_transport", T);
    if (best.empty()) {
        sum.failure = kNoFeasibleMotion;
        return finished(sum, cycles, t0);
    }
    sum.scene.plate = combined(transport_motion(best, T));
    sum.min_vertical_margin = vertical_margin(sum.scene.plate, sum.scene.g, flight_region(sum.scene, opt));
    // Verification: the field on the grid (mean and spread), then full dynamics from random starts.
    const Field f = verification_field(sum.scene, opt);
    int undefined = 0;
    for (const FieldPoint& p : f.points) {
        if (!p.converged)
            ++undefined;
        else
            sum.transport_mean += p.twist.head<2>();
    }
    if (undefined < static_cast<int>(f.points.size())) sum.transport_mean /= static_cast<double>(f.points.size() - undefined);
    for (const FieldPoint& p : f.points)
        if (p.converged) {
            sum.transport_spread = std::max(sum.transport_spread, (p.twist.head<2>() - sum.transport_mean).norm());
            if (!sum.scene.part.point) sum.transport_turn = std::max(sum.transport_turn, std::abs(p.twist[2]));
        }
    sum.transport_tolerance = 0.02 * target.velocity.norm();
    // (a rigid part: theta' within the same 2 %, turned into an angular rate by the part's radius rho)
    const double turn_tolerance = sum.transport_tolerance / sum.scene.part.rho();
    // Each run for a region's width of travel (1-20 s), judged over its second half: released at rest
    // the part lags the plate's drive while its cycle builds up (about 0.1 s on fig1_point, which a check
    // from the start would count against the design), so the distance is from where the target velocity takes it from the run's
    // midpoint, within the field's 2 % over that half (and 5 mm).
    const int stopped = verification_runs(
        sum, opt, [&](const DesignStartRun&) { return std::clamp(0.05 / target.velocity.norm(), 1.0, 20.0); },
        [&](const DesignStartRun& r, const Vec3& end) {   // (a rigid part's turn over the half: 0.05 rad counts as 5 mm)
            return std::max((end.head<2>() - r.at_from.head<2>() - target.velocity * (r.seconds - r.from)).norm(),
                            sum.scene.part.point ? 0.0 : std::abs(end[2] - r.at_from[2]) * opt.verify_distance / 0.05);
        },
        nullptr, 0.5);
    double allowed = opt.verify_distance;
    for (const DesignStartRun& r : sum.runs) allowed = std::min(allowed, sum.transport_tolerance * (r.seconds - r.from));
    sum.unique = true;   // (no fixed point is sought)
    if (undefined)
        sum.failure = std::to_string(undefined) + " configurations of the field are undefined";
    else if (!((sum.transport_mean - target.velocity).norm() <= sum.transport_tolerance))
        sum.failure = "the field's mean velocity (" + std::to_string(sum.transport_mean.x()) + ", " +
                      std::to_string(sum.transport_mean.y()) +
                      ") m/s misses the target by more than 2%: out of reach within the limits";
    else if (!(sum.transport_spread <= sum.transport_tolerance))
        sum.failure = "the field is not uniform over the region";
    else if (!(sum.transport_turn <= turn_tolerance))
        sum.failure = "the part turns (theta' up to " + std::to_string(sum.transport_turn) + " rad/s on the grid)";
    else if (stopped)
        sum.failure = std::to_string(stopped) + " full-dynamics run(s) left the model";
    else if (!(sum.worst_end_distance <= allowed))
        sum.failure = "a full-dynamics run ended " + std::to_string(sum.worst_end_distance) +
                      " m from where the target velocity takes it over the run's second half (allowed " +
                      std::to_string(allowed) + " m: 2 % of the travel)";
    sum.verified = sum.failure.empty();
    return finished(sum, cycles, t0);
}


}   // namespace plate::design_detail
