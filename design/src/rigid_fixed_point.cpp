#include "internal.hpp"

namespace plate::design_detail {

// --- the rigid part's fixed point (and orientation) ----------------------------------------------
// Parameters: cosine and sine coefficients of harmonics n = 1, 2 on all six axes (24). z, rz and the
// second harmonics break the pairing of fixed points (s, theta), (-s, theta + pi) that odd x, y, rx,
// ry motions force (design.hpp), so the centre is no longer a fixed point by construction: the search
// makes (0, 0, 0) one -- fast, and pulling the region's edge and every orientation towards it -- and
// the fixed point found near the centre, q*, is then placed exactly on the target by the two
// symmetries: turned by THETA - theta*, shifted by the target minus the turned s*.
const std::vector<Axis> kRigidAxes = {Axis::x, Axis::y, Axis::z, Axis::rx, Axis::ry, Axis::rz};
PlateMotion rigid_motion(const std::vector<double>& p, double T) { return motion_from(p, kRigidAxes, {1, 2}, T); }

// Constraints c_k <= 0 on a motion as placed: each axis' peak within its limit times `room`, no flight
// under the part's contacts over the region, no coning beyond kConingLimit either way and no tilt drift
// beyond kTiltDriftLimit (kPlacedConstraints entries, and corner_count(opt) more after the peaks).
void placed_constraints(const PlateMotion& fin, const DesignOptions& opt, const Scene& part, double room, double* c) {
    const int k = peak_constraints(fin, opt, part, room, c);
    const double cone = coning_rate(fin) / kConingLimit;
    c[k] = cone - 1;
    c[k + 1] = -cone - 1;
    c[k + 2] = tilt_drift_rate(fin).norm() / kTiltDriftLimit - 1;
}

// The field xi_a at q and its Jacobian by central differences (steps 3 mm and 0.1 rad), warm-started
// from the cycle at q. False if a cycle did not converge.
bool twist_and_jacobian(const Scene& sc, const Vec3& q, const LimitCycleOptions& cyc, Vec3& xi, Mat3& J,
                        std::atomic<long>& cycles) {
    const LimitCycleSummary c0 = limit_cycle(sc, q, cyc);
    ++cycles;
    if (!c0.converged) return false;
    xi = c0.twist;
    const double h[3] = {0.003, 0.003, 0.1};
    for (int d = 0; d < 3; ++d) {
        Vec3 e = Vec3::Zero();
        e[d] = h[d];
        const LimitCycleSummary p = limit_cycle(sc, q + e, cyc, c0.qd_start), m = limit_cycle(sc, q - e, cyc, c0.qd_start);
        cycles += 2;
        if (!p.converged || !m.converged) return false;
        J.col(d) = (p.twist - m.twist) / (2 * h[d]);
    }
    return true;
}

struct RigidProblem : Problem<RigidProblem> {
    RigidProblem(const Scene& part_, const DesignTarget& t_, const DesignOptions& opt_, double T_, std::atomic<long>* cycles_)
        : Problem(part_, opt_, T_, cycles_), target(t_) {
        if (std::abs(part_.plate.T - T_) <= 1e-12 * T_) guess = params_from(part_.plate, kRigidAxes, {1, 2});
    }
    DesignTarget target;
    static constexpr int kParams = 24;
    static constexpr const char* kFamily = "x, y, z, rx, ry, rz at n = 1, 2";
    static constexpr int kConstraints = kPlacedConstraints;   // six peaks, the flight margin, coning both ways, tilt drift
    // The search keeps 3% of each limit in hand for the final placement's correction (shifting by the
    // found fixed point's offset, a few mm, adds alpha x offset to the linear amplitudes).
    static constexpr double kRoom = 0.97;
    double limit(int i) const { return i < 12 ? opt.lin_limit : opt.ang_limit; }
    bool is_free(int i) const { return free(kRigidAxes, {1, 2}, i); }
    void constraints(const std::vector<double>& p, double* c) const {
        placed_constraints(combined(shift_motion(rotate_motion(rigid_motion(p, T), target.theta), target.at)), opt, part, kRoom,
                           c);
    }
    // -rate at the centre, plus how far the centre is from being the fixed point (the Newton step
    // J^-1 xi there, over 1 cm / 0.1 rad), plus how much the region's edge (8 points, theta = 0) and
    // the orientations at the centre (8, all round) are not drawn towards the centre.
    double evaluate(const std::vector<double>& p, double* rate_out = nullptr, Eigen::Vector3cd* eig_out = nullptr) {
        ++evaluations;
        Scene sc = part;
        sc.plate = rigid_motion(p, T);
        Vec3 xi;
        Mat3 J;
        if (!twist_and_jacobian(sc, Vec3::Zero(), opt.cycle, xi, J, *cycles)) return 1e3;
        const Eigen::Vector3cd ev = J.eigenvalues();
        const double rate = -std::max({ev[0].real(), ev[1].real(), ev[2].real()});
        if (rate_out) *rate_out = rate;
        if (eig_out) *eig_out = ev;
        const Vec3 step = J.fullPivLu().solve(xi);
        const double off = step.allFinite() ? std::hypot(step.head<2>().norm() / 0.01, step[2] / 0.1) : 10.0;
        double outward = 0;
        for (const Vec2& s : region_edge(opt.region)) {
            const LimitCycleSummary c = limit_cycle(sc, Vec3(s.x(), s.y(), 0), opt.cycle);
            ++*cycles;
            if (!c.converged) return 1e3;
            outward += std::max(0.0, s.dot(c.twist.head<2>()) / s.squaredNorm());   // [1/s]
        }
        Vec3 warm = Vec3::Zero();
        for (int k = 0; k < 8; ++k) {
            const double th = -kPi + (k + 0.5) * kPi / 4;
            const LimitCycleSummary c = limit_cycle(sc, Vec3(0, 0, th), opt.cycle, warm);
            ++*cycles;
            if (!c.converged) return 1e3;
            warm = c.qd_start;
            outward += std::max(0.0, c.twist[2] * th / (th * th));   // [1/s]
        }
        return -rate + 10 * outward + 5 * off * off;
    }
};


// A centred motion whose fixed point is q, placed so that it lands on (at, THETA - theta_offset): turned
// by THETA - theta_offset - q_theta about the origin (the field turns), then shifted by `at` less the
// turned s (the field shifts).
PlateMotion placed_motion(const PlateMotion& centred, const Vec3& q, const Vec2& at, double theta, double theta_offset) {
    const double turn = theta - theta_offset - q[2];
    return combined(shift_motion(rotate_motion(centred, turn), at - Eigen::Rotation2Dd(turn) * Vec2(q.head<2>())));
}

// --- the rigid part's fixed point as a half-turn pair ----------------------------------------------
// Where no unique fixed point is found (fig4's part: its first harmonic in theta stays below the rest
// within the limits -- bench_orientation_drive -- and the one orientation reachable by tuning the mean
// loses the position's pull, README), the sink's motion (odd harmonics on x, y, rx, ry; n = 1, 3) with
// theta' at THETA made a stable zero as well, coning held to kConingLimit. Turning such a motion by pi is shifting it by half a
// period, so (s*, THETA) and
// (-s*, THETA + pi) are both stable fixed points, at the centre (s* ~ 0) the same position: the part
// is brought to the target's position from everywhere and to its orientation up to a half turn.
// Then broken (break_pair, where DesignOptions::break_pair): the pair's field checked first (no runs),
// and where the broken motion verifies as unique it is returned without the pair's own runs; else the
// pair is verified in full and reported as not unique, with the twin and each one's share of the
// random starts, unless a verified broken motion has the larger share.
DesignSummary design_rigid_pair(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt, double T) {
    const auto t0 = Clock::now();
    DesignSummary sum;
    sum.notes.push_back(
        "a half-turn pair: odd harmonics on x, y, rx, ry (n = 1, 3) pull the position to the target at "
        "every orientation, and THETA is made a stable zero of theta' there; such a motion turned by pi "
        "is the same motion half a period later, so THETA + pi is one as well (not unique)");
    sum.notes.push_back("coning held to 1e-4 rad/s (the plate's turn about z turns the part's orientation with it)");
    std::atomic<long> cycles{0};
    const double theta = wrap_angle(target.theta);
    const auto make = [&] { return SinkProblem(part_scene, target.at, opt, T, &cycles, &theta); };
    DesignOptions o = opt;
    o.starts = std::min(opt.starts, default_starts(part_scene, DesignTarget{}));   // (a sink's starts)
    const std::vector<double> best = multistart<SinkProblem>(o, -HUGE_VAL, make, sum.evaluations);
    start_summary(sum, part_scene, "_fixed_point", T);
    sum.starts = o.starts;
    if (best.empty()) {
        sum.failure = kNoFeasibleMotion;
        return finished(sum, cycles, t0);
    }
    // (the search's motion is centred: the placement shifts it by the target less the small offset of
    // the fixed point found.) Broken first: where that verifies as unique the pair's own runs are not needed (its field is
    // checked, a pair that does not hold the target is not broken); else the pair verified in full and the better kept.
    DesignSummary broken;
    broken.failure = "not tried";
    // (the broken pair returned, saying what the pair was)
    auto adopt = [&](const std::string& pair_was) -> DesignSummary {
        broken.notes.insert(broken.notes.begin(),
                            "from a half-turn pair (odd harmonics n = 1, 3 on x, y, rx, ry with THETA "
                            "a stable zero of theta'; " +
                                pair_was + ")");
        broken.evaluations += sum.evaluations;
        broken.starts = sum.starts;
        return finished(broken, cycles, t0);
    };
    if (opt.break_pair) {
        DesignOptions quick = opt;
        quick.verify_starts = 0;
        quick.hold = 0;
        DesignSummary probe = sum;
        place_and_verify_rigid(probe, part_scene, sink_motion(best, T), Vec3(0, 0, theta), target, quick, cycles, t0, true);
        if (probe.verified)
            broken = break_pair(part_scene, sink_motion(best, T), target, opt, T, cycles, t0);
        else
            broken.failure = "not tried: the pair's field does not hold the target (" + probe.failure + ")";
        if (broken.verified && broken.unique)
            return adopt("its field checked, its own full-dynamics runs not needed once the broken pair verified as unique");
    }
    place_and_verify_rigid(sum, part_scene, sink_motion(best, T), Vec3(0, 0, theta), target, opt, cycles, t0, true);
    if (!opt.break_pair) return sum;
    if (sum.verified && broken.verified && broken.basin_share > sum.basin_share) {
        std::ostringstream note;
        note.precision(2);
        note << "verified, the target's share of the runs " << sum.basin_share << ", which its pairing caps at "
             << sum.basin_share_bound;
        return adopt(note.str());
    }
    sum.notes.push_back("breaking the pairing with rz about its centre: " + broken.failure);
    sum.evaluations += broken.evaluations;
    return finished(sum, cycles, t0);
}

DesignSummary design_rigid(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt, double T) {
    const auto t0 = Clock::now();
    DesignSummary sum;
    const bool orient = target.kind == DesignTargetKind::Orient;
    sum.notes.push_back(
        "harmonics n = 1, 2 on x, y, z, rx, ry, rz: z, rz and n = 2 break the pairing of fixed points "
        "(s, theta), (-s, theta + pi) that odd x, y, rx, ry motions force");
    sum.notes.push_back(
        "designed for a fixed point at the centre, theta = 0; the one found, q*, placed on the target by "
        "turning the motion by THETA - theta* (the field turns) and adding -alpha x D (the field shifts by D)");
    sum.notes.push_back(
        "no coning (|rx, ry out of phase| turns the plate about z, which the field does not see and the "
        "full dynamics does): the plate's yaw drift held within 1e-4 rad/s");
    if (orient)
        sum.notes.push_back(
            "orient: designed as a fixed point at the region's centre with orientation THETA "
            "(a stronger target); verified on the orientation only");
    std::atomic<long> cycles{0};
    const auto make = [&] { return RigidProblem(part_scene, target, opt, T, &cycles); };
    const std::vector<double> best = multistart<RigidProblem>(opt, -HUGE_VAL, make, sum.evaluations);
    start_summary(sum, part_scene, orient ? "_orient" : "_fixed_point", T);
    if (best.empty()) {
        sum.failure = kNoFeasibleMotion;
        return finished(sum, cycles, t0);
    }
    make().evaluate(best, &sum.rate, &sum.eigenvalues3);
    return place_and_verify_rigid(sum, part_scene, rigid_motion(best, T), Vec3::Zero(), target, opt, cycles, t0);
}

// A note on what the orientation has to work with at the fixed point found (or the centre):
// theta''s first harmonic against the rest (orientation_harmonics, design.hpp).
static void note_orientation_drive(DesignSummary& sum, const Scene& centred, const Vec3& q, bool found, const DesignOptions& opt,
                                   std::atomic<long>& cycles) {
    const bool near = found && q.head<2>().norm() <= opt.region;
    const int ring = 12;
    const OrientationHarmonics oh = orientation_harmonics(centred, near ? Vec2(q.head<2>()) : Vec2::Zero(), opt.cycle, ring);
    cycles += ring;
    if (oh.defined) {
        std::ostringstream note;
        note.precision(2);
        note << "theta' at the " << (near ? "fixed point's position" : "centre") << " (12 orientations): first harmonic "
             << oh.first() << " rad/s against " << oh.rest() << " for the mean and the others ("
             << (oh.one_stable()          ? "enough for exactly one stable orientation"
                 : oh.first() > oh.rest() ? "the zeros lie in two arcs, but more than one may be stable"
                                          : "below the rest: not enough by itself for one orientation, whose stable ones pair "
                                            "about a half turn apart unless the mean is tuned near a saddle-node")
             << "; orientation_harmonics, design.hpp)";
        sum.notes.push_back(note.str());
    }
}

// A rigid design's last stages, shared: the fixed point of `centred` near q0 (Newton with the
// central-difference Jacobian, at the refinement's tolerances: field noise well below the step),
// placed exactly on the target by the two symmetries (turned by THETA - theta*, shifted by the target
// minus the turned s*), checked against the limits, and verified: the 7^3 field's fixed points, full
// dynamics from random starts (the target's basin share and each competing stable point's), the hold.
DesignSummary& place_and_verify_rigid(DesignSummary& sum, const Scene& part_scene, const PlateMotion& centred_motion,
                                      const Vec3& q0, const DesignTarget& target, const DesignOptions& opt,
                                      std::atomic<long>& cycles, Clock::time_point t0, bool pair, double run_seconds,
                                      double theta_offset) {
    // (run_seconds: the verification runs last at least this long; theta_offset: the field's fixed point
    // is placed this far short of THETA -- break_pair's, where the full dynamics settles past it)
    const bool orient = target.kind == DesignTargetKind::Orient;
    Scene centred = part_scene;
    centred.plate = centred_motion;
    LimitCycleOptions fine = opt.cycle;
    fine.integration.rtol = 1e-9;
    fine.tol = 1e-8;
    Vec3 q = q0;
    bool found = false;
    for (int it = 0; it < 12; ++it) {
        Vec3 xi;
        Mat3 J;
        if (!twist_and_jacobian(centred, q, fine, xi, J, cycles)) break;
        const Vec3 step = J.fullPivLu().solve(xi);
        if (!step.allFinite()) break;
        q -= step;
        if (step.head<2>().norm() < 1e-7 && std::abs(step[2]) < 1e-6) {
            found = true;
            sum.eigenvalues3 = J.eigenvalues();   // (at the fixed point, a step away)
            sum.rate = -std::max({sum.eigenvalues3[0].real(), sum.eigenvalues3[1].real(), sum.eigenvalues3[2].real()});
            break;
        }
    }
    note_orientation_drive(sum, centred, q, found, opt, cycles);
    if (!found || q.head<2>().norm() > opt.region || std::abs(wrap_angle(q[2] - q0[2])) > kPi / 2) {
        sum.failure = "the search's best motion has no fixed point near the design's centre";
        return finished(sum, cycles, t0);
    }
    const Vec2 at = orient ? Vec2::Zero() : target.at;
    const Vec2 s_turned = Eigen::Rotation2Dd(target.theta - theta_offset - q[2]) * Vec2(q.head<2>());
    sum.scene.plate = placed_motion(centred.plate, q, at, target.theta, theta_offset);
    sum.min_vertical_margin = vertical_margin(sum.scene.plate, sum.scene.g, flight_region(sum.scene, opt));
    double c[kPlacedConstraints + kCornerConstraints];
    placed_constraints(sum.scene.plate, opt, sum.scene, 1.0, c);
    if (*std::max_element(c, c + kPlacedConstraints + corner_count(opt)) > 1e-9) {
        sum.failure =
            "the placed motion exceeds the peak limits, the corner limits, the flight margin or the coning (or tilt drift) "
            "limit";
        return finished(sum, cycles, t0);
    }
    const Vec3 goal(at.x(), at.y(), wrap_angle(target.theta));
    auto reached = [&](const Vec3& a, const Vec3& b, double dist, double ang) {
        return (orient || (a.head<2>() - b.head<2>()).norm() <= dist) && std::abs(wrap_angle(a[2] - b[2])) <= ang;
    };

    // --- verification: the field's fixed points on the 7^3 grid, then full dynamics from random starts.
    sum.fixed_points = find_fixed_points(sum.scene, verification_field(sum.scene, opt));
    int stable = 0, stable_at_target = 0;
    double nearest = std::numeric_limits<double>::infinity();
    std::vector<FixedPoint> others;
    for (const FixedPoint& p : sum.fixed_points.points) {
        if (p.stability != Stability::Stable) continue;
        ++stable;
        const double d = std::hypot(orient ? 0.0 : (p.q.head<2>() - at).norm() / 0.002, wrap_angle(p.q[2] - goal[2]) / 0.02);
        if (d < nearest) {
            nearest = d;
            sum.fixed_point = p.q;
            sum.fixed_point_eigenvalues = p.eigenvalues;
        }
        if (reached(p.q, goal, opt.fixed_point_tolerance, 0.02))
            ++stable_at_target;
        else
            others.push_back(p);
    }
    int stable_lines = 0;
    for (const FixedLine& l : sum.fixed_points.lines) stable_lines += l.stability == Stability::Stable;
    // A half-turn pair is never unique: its twin exists by the pairing whether or not the grid
    // resolves it (nothing else keeps a missed twin from reading unique).
    const std::string gaps = unsearched(sum.fixed_points);
    sum.unique = !pair && stable == 1 && stable_at_target == 1 && stable_lines == 0 && gaps.empty();
    if (!gaps.empty()) sum.notes.push_back("the grid's fixed-point search did not cover " + gaps + ": not called unique");
    sum.coning = coning_rate(sum.scene.plate);
    const int stopped = verification_runs(
        sum, opt,
        [&](const DesignStartRun&) {
            return std::max(settle_time(2 * opt.region, sum.rate, opt), run_seconds);
        },   // (from across the region)
        [&](const DesignStartRun&, const Vec3& end) {
            return std::max(orient ? 0.0 : (end.head<2>() - at).norm(),
                            std::abs(wrap_angle(end[2] - goal[2])) * opt.verify_distance / 0.05);
        },
        stable_at_target == 1 ? &goal : nullptr);   // (the hold only where the target is a stable fixed point)
    const std::string unheld = hold_failure(sum, opt, " m (0.05 rad counted as " + std::to_string(opt.verify_distance) + " m)");
    // The basin shares: of the runs, those that end at the target and at each competing stable point
    // (each run counted once: at the target, else at the first competitor it reached).
    std::vector<int> ended(others.size() + 1, 0);   // ended[0]: at the target
    int accounted = 0;
    for (const DesignStartRun& r : sum.runs) {
        if (!r.stop.empty()) continue;
        std::size_t where = r.end_distance <= opt.verify_distance ? 0 : ended.size();
        for (std::size_t k = 0; where == ended.size() && k < others.size(); ++k)
            if (reached(r.end, others[k].q, opt.verify_distance, 0.05)) where = k + 1;
        if (where < ended.size()) ++ended[where], ++accounted;
    }
    const double runs = static_cast<double>(std::max<std::size_t>(sum.runs.size(), 1));
    sum.basin_share = ended[0] / runs;
    for (std::size_t k = 0; k < others.size(); ++k) sum.competitors.push_back({others[k], ended[k + 1] / runs});
    // A half-turn pair: exactly one competitor, the target's image under the pairing about the design's
    // centre D = target - s_turned, i.e. at (2 D - target, THETA + pi).
    const Vec2 twin_at = at - 2 * s_turned;
    if (pair) {
        sum.basin_share_bound = pair_basin_bound(at - s_turned, opt.region);
        std::ostringstream note;
        note.precision(2);
        note << "the pairing caps the target's basin share in the field's flow at " << sum.basin_share_bound
             << " of starts uniform over the region: the twin's basin is the image of the target's under the half turn about "
                "the design's centre, so where the region is its own image at most half of it can go to the target (the "
                "full-dynamics runs' share is a sample of "
             << sum.runs.size() << " from phase 0 and can exceed it by chance)";
        sum.notes.push_back(note.str());
    }
    const bool twin_ok = others.size() == 1 && (others[0].q.head<2>() - twin_at).norm() <= opt.fixed_point_tolerance &&
                         std::abs(wrap_angle(others[0].q[2] - goal[2] - kPi)) <= 0.02;
    if (stable_at_target != 1)
        sum.failure = "the designed field has " + std::to_string(stable_at_target) +
                      " stable fixed point(s) at the target on the " + std::to_string(opt.verify_grid) + "^3 grid (" +
                      std::to_string(stable) + " stable in all)";
    else if (stopped)
        sum.failure = std::to_string(stopped) + " full-dynamics run(s) left the model";
    else if (sum.unique && !(sum.worst_end_distance <= opt.verify_distance))
        sum.failure = "a full-dynamics run ended " + std::to_string(sum.worst_end_distance) + " m (0.05 rad counted as " +
                      std::to_string(opt.verify_distance) + " m) from the target";
    else if (!sum.unique && accounted < static_cast<int>(sum.runs.size()))
        sum.failure = "of " + std::to_string(sum.runs.size()) + " full-dynamics runs, " +
                      std::to_string(static_cast<int>(sum.runs.size()) - accounted) +
                      " ended at neither the target nor a competing stable fixed point";
    else if (!sum.unique && ended[0] == 0 && opt.verify_starts > 0)   // (0, design_rigid_pair's probe: the field only)
        sum.failure = "no full-dynamics run ended at the target";
    else if (pair && !twin_ok)
        sum.failure = "the half-turn pair's stable fixed points are not the target and its twin alone (" +
                      std::to_string(others.size()) + " other stable fixed point(s))";
    return last_checks(sum, opt, unheld, cycles, t0);
}


}   // namespace plate::design_detail
