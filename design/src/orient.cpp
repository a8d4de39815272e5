#include "internal.hpp"

namespace plate::design_detail {

// --- the rigid part's orientation: a weathervane ------------------------------------------------
// A plate that only translates (transport_motion) gives the part nothing that depends on where it is
// (no alpha x r, no tilt, no coning: its full dynamics are its U-dynamics), so the twist is a function
// of theta alone, the same at every position. With every contact sliding along one direction u (the
// part not turning), friction's torque about the centre of mass is -(sum_i mu_i N_i r_i) x u, and the
// normal forces balance friction's moment about the horizontal axes, which makes sum_i N_i r_i
// parallel to u: with one friction coefficient the torque vanishes, and such a plate never turns the
// part (tests/design/test_design_orient.cpp). With unequal ones it is a weathervane: the torque vanishes where
// sum_i (mu_i - mu) N_i r_i lies along u; on a plate shaken along one line with a heave in phase
// (the transport driven by the normal force: the part slips backwards while pressed hardest, and
// friction pushes it on) the part turns until its high-friction contact leads -- one stable
// orientation in the turn (where the transport is driven otherwise, e.g. by a sawtooth, the foot
// may trail; other motions put it elsewhere, still one). The search
// shapes theta'(theta) on a ring of kRing orientations to one stable zero, as steep as it can be,
// and rotate_motion turns that zero onto THETA.
constexpr int kRing = 12, kFineRing = 72;

// theta' at the centre on a ring of n equally spaced orientations from 0 (false if a cycle did not
// converge); twist receives the whole twists if given.
bool orientation_ring(const Scene& sc, int n, const LimitCycleOptions& cyc, std::atomic<long>& cycles, std::vector<double>& th,
                      std::vector<double>& w, std::vector<Vec3>* twist = nullptr) {
    th.resize(n);
    w.resize(n);
    if (twist) twist->resize(n);
    for (int k = 0; k < n; ++k) {
        th[k] = 2 * kPi * k / n;
        const LimitCycleSummary lc = limit_cycle(sc, Vec3(0, 0, th[k]), cyc);
        ++cycles;
        if (!lc.converged) return false;
        w[k] = lc.twist[2];
        if (twist) (*twist)[k] = lc.twist;
    }
    return true;
}

// The stable zeros of theta' on a ring (theta' falls through zero going round): their number, and
// the steepest one's angle (linear between the ring's points) and rate -d theta'/d theta.
struct RingZeros {
    int stable = 0;
    double theta = 0, rate = 0;
};
RingZeros ring_zeros(const std::vector<double>& th, const std::vector<double>& w) {
    RingZeros z;
    const int n = static_cast<int>(w.size());
    const double h = 2 * kPi / n;
    for (int k = 0; k < n; ++k) {
        const double a = w[k], b = w[(k + 1) % n];
        if (!(a > 0 && b <= 0)) continue;
        ++z.stable;
        if ((a - b) / h > z.rate) {
            z.rate = (a - b) / h;
            z.theta = wrap_angle(th[k] + h * a / (a - b));
        }
    }
    return z;
}

struct OrientProblem : Problem<OrientProblem> {
    using Problem::Problem;
    static constexpr int kParams = 12;   // transport_motion's layout: x, y, z; n = 1, 2; cos, sin
    static constexpr const char* kFamily = "x, y, z at n = 1, 2";
    static constexpr int kConstraints = 3;   // x and y's peaks at any turn, z's, the flight margin
    double limit(int) const { return opt.lin_limit; }
    bool is_free(int i) const { return free(kTranslationAxes, {1, 2}, i); }
    // The design is turned onto THETA afterwards, so x's and y's peak limits must hold at every turn:
    // max_t |(u_x, u_y)| (horizontal_peak) within the limit.
    void constraints(const std::vector<double>& p, double* c) const {
        const double L = std::max(opt.lin_limit, 1e-12);
        const PlateMotion u = transport_motion(p, T);
        c[0] = (horizontal_peak(u) - opt.lin_limit) / L;
        c[1] = (axis_peaks(u)[2] - opt.lin_limit) / L;
        c[2] = opt.flight_margin - vertical_margin(u, part.g, opt.region);
        corner_constraints(u, opt, part, 1.0, c + 3);   // (x, y, z alone: the same at every turn)
    }
    // One stable orientation on the ring: minus its rate [1/s]; else the number of stable ones less
    // one, or 1 for none (a part that does not turn).
    double evaluate(const std::vector<double>& p) {
        ++evaluations;
        Scene sc = part;
        sc.plate = transport_motion(p, T);
        std::vector<double> th, w;
        if (!orientation_ring(sc, kRing, opt.cycle, *cycles, th, w)) return 1e3;
        const RingZeros z = ring_zeros(th, w);
        return z.stable == 1 ? -z.rate : z.stable == 0 ? 1.0 : z.stable - 1.0;
    }
};

// The time the averaged turning, theta' = w(theta) linear between the ring's points, takes from
// theta0 to within `within` of the stable orientation theta_s (steps of 5 mrad; at most `cap`).
double turn_time(const std::vector<double>& w, double theta0, double theta_s, double within, double cap) {
    const int n = static_cast<int>(w.size());
    const double h = 2 * kPi / n;
    auto at = [&](double x) {
        const double u = (x - 2 * kPi * std::floor(x / (2 * kPi))) / h;
        const int k = static_cast<int>(u) % n;
        return w[k] + (u - std::floor(u)) * (w[(k + 1) % n] - w[k]);
    };
    double t = 0, x = theta0;
    while (std::abs(wrap_angle(x - theta_s)) > within && t < cap) {
        const double v = at(x);
        if (v == 0) return cap;
        t += 5e-3 / std::abs(v);
        x += v > 0 ? 5e-3 : -5e-3;
    }
    return std::min(t, cap);
}

double orient_end_distance(const Vec3& end, double theta, const DesignOptions& opt) {
    return std::abs(wrap_angle(end[2] - theta)) * opt.verify_distance / 0.05;
}

DesignSummary design_orient(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt, double T) {
    const auto t0 = Clock::now();
    DesignSummary sum;
    sum.notes.push_back(
        "orient by transport, a weathervane: a plate that only translates (x, y, z; n = 1, 2) gives the "
        "part the same twist at every position and full dynamics equal to its U-dynamics (no tilt, no "
        "coning); with unequal friction coefficients on its contacts the part turns to where friction's "
        "torque vanishes (on a plate shaken along one line with a heave in phase: its high-friction contact "
        "leads)");
    sum.notes.push_back("position free: the part travels while it turns and after (velocity_at_orientation)");
    sum.notes.push_back("designed on a ring of " + std::to_string(kRing) +
                        " orientations and turned onto THETA "
                        "(the field turns with the motion); the limits hold at every turn");
    std::atomic<long> cycles{0};
    const auto make = [&] {
        OrientProblem p(part_scene, opt, T, &cycles);
        p.guess = params_from(part_scene.plate, kTranslationAxes, {1, 2});
        return p;
    };
    const std::vector<double> best = multistart<OrientProblem>(opt, -HUGE_VAL, make, sum.evaluations);
    start_summary(sum, part_scene, "_orient", T);
    if (best.empty()) {
        sum.failure = kNoFeasibleMotion;
        return finished(sum, cycles, t0);
    }
    Scene centred = part_scene;
    centred.plate = transport_motion(best, T);
    std::vector<double> th, w;
    RingZeros z;
    if (orientation_ring(centred, kRing, opt.cycle, cycles, th, w)) z = ring_zeros(th, w);
    if (z.stable != 1) {
        sum.failure = "no plate motion that only translates found turns the part to one orientation" +
                      std::string(z.stable == 0 ? " (it does not turn it at all: with one friction coefficient on "
                                                  "every contact none can)"
                                                : "");
        return finished(sum, cycles, t0);
    }
    // The stable orientation by bisection on theta' (at the refinement's tolerances), its rate by
    // central differences.
    LimitCycleOptions fine = opt.cycle;
    fine.integration.rtol = 1e-9;
    fine.tol = 1e-8;
    auto w_at = [&](double a) {
        const LimitCycleSummary lc = limit_cycle(centred, Vec3(0, 0, a), fine);
        ++cycles;
        return lc.converged ? lc.twist[2] : std::numeric_limits<double>::quiet_NaN();
    };
    const double h = 2 * kPi / kRing;
    double lo = z.theta - 0.5 * h, hi = z.theta + 0.5 * h;
    if (!(w_at(lo) > 0 && w_at(hi) <= 0)) {
        sum.failure = "the ring's stable orientation did not survive the refinement's tolerances";
        return finished(sum, cycles, t0);
    }
    bool defined = true;
    while (defined && hi - lo > 1e-7) {
        const double m = 0.5 * (lo + hi), wm = w_at(m);
        defined = std::isfinite(wm);
        (wm > 0 ? lo : hi) = m;
    }
    const double theta_s = 0.5 * (lo + hi);
    sum.rate = -(w_at(theta_s + 0.01) - w_at(theta_s - 0.01)) / 0.02;
    if (!defined || !std::isfinite(sum.rate)) {
        sum.failure = "a cycle did not converge while the stable orientation was refined";
        return finished(sum, cycles, t0);
    }
    sum.eigenvalues3 = Eigen::Vector3cd(0, 0, -sum.rate);   // positions are neutral: the field is theta's alone
    sum.scene.plate = combined(rotate_motion(centred.plate, target.theta - theta_s));
    sum.min_vertical_margin = vertical_margin(sum.scene.plate, sum.scene.g, flight_region(sum.scene, opt));
    double c[OrientProblem::kConstraints + kCornerConstraints];
    const OrientProblem check(part_scene, opt, T, &cycles);
    check.constraints(params_from(sum.scene.plate, kTranslationAxes, {1, 2}), c);
    if (*std::max_element(c, c + check.constraint_count()) > 1e-9) {
        sum.failure = "the turned motion exceeds the peak limits, the corner limits or the flight margin";
        return finished(sum, cycles, t0);
    }

    // --- verification: a fine ring at the centre (one stable orientation, at THETA), the 7^3 field
    // (the same twist at every position), full dynamics from random starts.
    std::vector<Vec3> ring;
    if (!orientation_ring(sum.scene, kFineRing, opt.cycle, cycles, th, w, &ring)) {
        sum.failure = "a cycle on the verification ring did not converge";
        return finished(sum, cycles, t0);
    }
    sum.ring_theta = th;
    sum.ring_twist = ring;
    const RingZeros zf = ring_zeros(th, w);
    sum.fixed_point = Vec3(0, 0, zf.theta);
    sum.fixed_point_eigenvalues = sum.eigenvalues3;
    {   // the twist at the orientation: the travel (linear between the ring's points)
        const double u = (zf.theta - 2 * kPi * std::floor(zf.theta / (2 * kPi))) / (2 * kPi / kFineRing);
        const int k = static_cast<int>(u) % kFineRing;
        sum.transport_mean = ring[k].head<2>() + (u - std::floor(u)) * (ring[(k + 1) % kFineRing] - ring[k]).head<2>();
    }
    const bool at_theta = zf.stable == 1 && std::abs(wrap_angle(zf.theta - target.theta)) <= 0.02;
    sum.unique = at_theta;
    const Field f = verification_field(sum.scene, opt);
    // (each of the field's cycles is within cycle_noise of its limit, from its own warm start)
    const Vec3 S(part_scene.v_ref(), part_scene.v_ref(), part_scene.v_ref() / part_scene.part.rho());
    int undefined = 0;
    double spread = 0;
    for (const FieldPoint& p : f.points) {
        if (!p.converged) {
            ++undefined;
            continue;
        }
        for (const FieldPoint& o : f.points)
            if (o.converged && o.q[2] == p.q[2])
                spread = std::max(spread, (p.twist - o.twist).cwiseQuotient(S).cwiseAbs().maxCoeff());
    }
    sum.transport_spread = spread;   // (relative to v_ref and v_ref / rho)
    sum.transport_tolerance = 2 * cycle_noise(opt.cycle);
    const int stopped = verification_runs(
        sum, opt, [&](const DesignStartRun& r) { return 1.5 * turn_time(w, r.theta, zf.theta, 0.01, 200) + 2; },
        [&](const DesignStartRun&, const Vec3& end) { return orient_end_distance(end, target.theta, opt); });
    int reached = 0;
    for (const DesignStartRun& r : sum.runs) reached += r.stop.empty() && r.end_distance <= opt.verify_distance;
    sum.basin_share = sum.runs.empty() ? 0.0 : static_cast<double>(reached) / sum.runs.size();
    if (!at_theta)
        sum.failure = "the verification ring has " + std::to_string(zf.stable) + " stable orientation(s), the nearest " +
                      std::to_string(zf.theta) + " rad";
    else if (undefined)
        sum.failure = std::to_string(undefined) + " configurations of the field are undefined";
    else if (!(spread <= sum.transport_tolerance))
        sum.failure = "the field is not the same at every position (the motion is not a translation?)";
    else if (stopped)
        sum.failure = std::to_string(stopped) + " full-dynamics run(s) left the model";
    else if (!(sum.worst_end_distance <= opt.verify_distance))
        sum.failure = "a full-dynamics run ended " + std::to_string(sum.worst_end_distance / opt.verify_distance * 0.05) +
                      " rad from THETA";
    else if (!(sum.min_vertical_margin >= opt.flight_margin - 1e-9))
        sum.failure = "the vertical acceleration margin is below the one asked";
    sum.verified = sum.failure.empty();
    return finished(sum, cycles, t0);
}


}   // namespace plate::design_detail
