#include "internal.hpp"

namespace plate::design_detail {

// --- the half-turn pair broken: rz about its centre ---------------------------------------------------
// At the pair's fixed point theta' has a mean M and a second harmonic B_2 and no first harmonic. rz at
// n = 2 about the design's centre keeps the pairing (a half turn leaves rz, half a period leaves n = 2)
// but moves M and B_2, so the pair's two stable orientations, at theta''s two minima, come near a
// saddle-node; rz at n = 1 breaks the pairing (half a period reverses it) and adds a first harmonic,
// which lifts one minimum above zero and leaves one stable orientation (fig4's figures:
// docs/inverse-design.md). First rx and ry at n = 1 are made parallel and rz at n = 1 takes their
// direction: rotations about two axes a quarter period apart turn the plate steadily (tilt_drift_rate;
// docs/decisions.md: the trial that left the plate). A grid over rz's amplitudes, its phase at n =
// 2 and its sense at n = 1 is screened by theta' on a ring of orientations at the pair's fixed point
// (exactly one stable zero), the survivors refined to their fixed point (stable, near the centre) and
// verified like every rigid design, the shortest passage round the ring first (it sets the runs'
// length), each first with theta''s other wells along s*(theta), where the field's fixed points lie,
// lifted clear of zero (lift_wells: the screen's ring at the centre misses a shallow one); the first
// that verifies as unique is returned, else the verified one with the largest share of the runs
// (design_rigid_pair keeps it where that beats the pair's).
constexpr int kBreakRing = 24;      // orientations of the screening ring
constexpr int kBreakVerified = 3;   // candidates verified at most
constexpr int kWellRing = 48;       // orientations of the ring along s* (lift_wells)
constexpr int kLiftSteps = 16;      // lift_wells's pattern-search steps at most
// [rad/s] the shallowest other well's clearance above zero (fig4 with 0.006 or 0.01: lifted to 0.012, where
// the candidate's fixed point was not found again, and the pair's remnant stayed)
constexpr double kWellMargin = 0.003;

// The pair's motion with rx and ry at n = 1 turned onto one line (each keeps its amplitude; the line is
// their amplitude-weighted direction, b + a or b - a), and that line's phase psi.
PlateMotion aligned_tilts(const PlateMotion& u, double& psi) {
    auto ph = phasors(u);
    const std::pair<int, int> kx{static_cast<int>(Axis::rx), 1}, ky{static_cast<int>(Axis::ry), 1};
    const std::complex<double> a = ph.count(kx) ? ph[kx] : 0.0, b = ph.count(ky) ? ph[ky] : 0.0;
    const double sense = std::real(a * std::conj(b)) < 0 ? -1.0 : 1.0;
    const std::complex<double> line = b + sense * a;
    psi = std::abs(line) > 0 ? std::arg(line) : 0.0;
    PlateMotion r;
    r.T = u.T;
    for (const auto& [k, z] : ph) {
        double amp = std::abs(z), phase = std::arg(z);
        if (k == kx) phase = psi + (sense < 0 ? kPi : 0.0);
        if (k == ky) phase = psi;
        if (amp > 0) r.harmonics.push_back({static_cast<Axis>(k.first), k.second, amp, phase});
    }
    return r;
}

// theta' along the position's fixed points: on n orientations theta_k, s*(theta_k), where the position's
// twist vanishes, linearised about `base` (one-sided differences, 2 mm), and w*(theta_k), theta' there.
// The field's fixed points are exactly the zeros of w*; where the position converges faster than the
// orientation, a stable one is a zero w* falls through. (theta' at one position alone misses them:
// on fig4's broken pair s* strays 6 mm from the centre, where theta' differs by 0.02 rad/s, and a
// shallow well that stays above zero at the centre dips below it along s*.) False where a cycle did
// not converge.
bool reduced_ring(const Scene& sc, const Vec2& base, int n, const LimitCycleOptions& cyc, long& own, double* w) {
    Vec3 warm = Vec3::Zero();
    const double hs = 0.002;
    for (int k = 0; k < n; ++k) {
        const Vec3 q0(base.x(), base.y(), -kPi + 2 * kPi * k / n);
        const LimitCycleSummary c = limit_cycle(sc, q0, cyc, warm);
        ++own;
        if (!c.converged) return false;
        warm = c.qd_start;
        const LimitCycleSummary cx = limit_cycle(sc, q0 + Vec3(hs, 0, 0), cyc, warm),
                                cy = limit_cycle(sc, q0 + Vec3(0, hs, 0), cyc, warm);
        own += 2;
        if (!cx.converged || !cy.converged) return false;
        Eigen::Matrix2d Jss;
        Jss.col(0) = (cx.twist - c.twist).head<2>() / hs;
        Jss.col(1) = (cy.twist - c.twist).head<2>() / hs;
        const Vec2 ds = -Jss.fullPivLu().solve(Vec2(c.twist.head<2>()));
        if (!ds.allFinite()) return false;
        w[k] = c.twist[2] + (cx.twist[2] - c.twist[2]) / hs * ds.x() + (cy.twist[2] - c.twist[2]) / hs * ds.y();
    }
    return true;
}

// The shallowest well of theta' round a ring of n other than the target's: the target's well is the arc
// where theta' < 0 from the stable zero nearest theta_target (theta' falls through it) to the unstable
// one; every local minimum outside that arc (a parabola through it and its neighbours) is another well,
// and the lowest of them is returned -- negative where it holds a second stable orientation, the
// ring's largest value where there is none, -infinity without a stable zero.
double other_well(const double* w, int n, double theta_target) {
    const double h = 2 * kPi / n;
    int at = -1;
    for (int k = 0; k < n; ++k)
        if (w[k] > 0 && w[(k + 1) % n] <= 0 &&
            (at < 0 || std::abs(wrap_angle(-kPi + h * (k + 0.5) - theta_target)) <
                           std::abs(wrap_angle(-kPi + h * (at + 0.5) - theta_target))))
            at = k;
    if (at < 0) return -HUGE_VAL;
    std::vector<bool> own(n, false);
    for (int k = (at + 1) % n; w[k] <= 0 && !own[k]; k = (k + 1) % n) own[k] = true;
    double lowest = *std::max_element(w, w + n);
    for (int k = 0; k < n; ++k) {
        const double a = w[(k + n - 1) % n], b = w[k], c = w[(k + 1) % n];
        if (own[k] || !(b <= a && b < c)) continue;
        const double curv = a - 2 * b + c;
        lowest = std::min(lowest, curv > 0 ? b - (c - a) * (c - a) / (8 * curv) : b);
    }
    return lowest;
}

// theta' = w(theta) round a ring of n (linear between its points), with exactly one stable zero: the
// time to within 0.05 rad of it, both ways from 0.01 rad past the unstable zero (of 20 uniform starts,
// one lies that close with probability 0.06) -- the slowest start's time, which the narrowest passage
// sets (the linear rate alone says nothing of it); infinity without exactly one stable zero.
double ring_passage(const double* w, int n) {
    int stable = 0, at = -1, unstable = -1;
    for (int k = 0; k < n; ++k) {
        if (w[k] > 0 && w[(k + 1) % n] <= 0) ++stable, at = k;
        if (w[k] < 0 && w[(k + 1) % n] >= 0) unstable = k;
    }
    if (stable != 1 || unstable < 0) return HUGE_VAL;
    const double h = 2 * kPi / n;
    const double th_s = -kPi + h * (at + w[at] / (w[at] - w[(at + 1) % n]));
    const double th_u = -kPi + h * (unstable + w[unstable] / (w[unstable] - w[(unstable + 1) % n]));
    auto w_at = [&](double th) {
        const double x = (wrap_angle(th) + kPi) / h;
        const int k = static_cast<int>(std::floor(x)) % n;
        const double f = x - std::floor(x);
        return (1 - f) * w[k] + f * w[(k + 1) % n];
    };
    double passage = 0;
    for (double dir : {1.0, -1.0}) {
        double th = th_u + dir * 0.01, t = 0;
        while (std::abs(wrap_angle(th - th_s)) > 0.05 && t < 1000) {
            const double v = w_at(th);
            const double dt = std::min(1.0, 0.01 / std::max(std::abs(v), 1e-6));
            th += v * dt;
            t += dt;
        }
        passage = std::max(passage, t);
    }
    return passage;
}

namespace {

// A candidate of the screen: rz's setting on the pair's motion, with its fixed point near the centre.
struct Candidate {
    PlateMotion u;
    Vec3 q;
    double rate;
    double passage;            // [s] the slowest start's way round the ring to the stable orientation
    int index;                 // in the grid (ties)
    PlateMotion base;          // the motion before rz: the pair's, tilts aligned, scaled
    std::array<double, 4> g;   // rz's setting
    double scale;
};

// break_pair's stages over what they share: the part, the target, the options, the tilts' phase psi,
// rz's room under the limit, and the cycles counted.
struct PairBreaker {
    const Scene& part_scene;
    const DesignTarget& target;
    const DesignOptions& opt;
    std::atomic<long>& cycles;
    double psi = 0;
    double room = 0;

    PlateMotion with_rz(const PlateMotion& base, const std::array<double, 4>& g) const {
        PlateMotion u = base;
        u.harmonics.push_back({Axis::rz, 1, g[0], psi + (g[1] < 0 ? kPi : 0.0)});
        u.harmonics.push_back({Axis::rz, 2, g[2], g[3]});
        return u;
    }
    // The motion with fixed point q, placed as place_and_verify_rigid will place it: within the limits,
    // the flight margin, and the coning and tilt-drift limits.
    bool fits(const PlateMotion& u, const Vec3& q) const {
        double con[kPlacedConstraints + kCornerConstraints];
        placed_constraints(placed_motion(u, q, target.at, target.theta), opt, part_scene, 1.0, con);
        return *std::max_element(con, con + kPlacedConstraints + corner_count(opt)) <= 0;
    }
    // A ring of n values of theta' with exactly one stable zero: its fixed point by Newton from q (not
    // finite: the middle of the zero's cell at the centre), stable and within `reach` of the centre
    // (the screen's 5 mm; 10 mm once lifted, its fixed point found again along s*), the placed motion
    // within the limits and the flight margin; "" where it fails, else "q0 q1 q2 rate passage" (exact
    // text: a task may run in another process).
    std::string fixed_point_on(const Scene& sc, const double* w, int n, Vec3 q, double reach, long& own) const {
        int stable = 0, at = -1;
        for (int k = 0; k < n; ++k)
            if (w[k] > 0 && w[(k + 1) % n] <= 0) ++stable, at = k;
        if (stable != 1) return "";
        if (!q.allFinite()) q = Vec3(0, 0, -kPi + 2 * kPi * (at + 0.5) / n);
        Vec3 xi;
        Mat3 J;
        bool conv = false;
        std::atomic<long> newton{0};
        for (int it = 0; it < 8 && !conv; ++it) {
            if (!twist_and_jacobian(sc, q, opt.cycle, xi, J, newton)) break;
            const Vec3 step = J.fullPivLu().solve(xi);
            if (!step.allFinite()) break;
            q -= step;
            conv = step.head<2>().norm() < 1e-6 && std::abs(step[2]) < 1e-4;
        }
        own += newton.load();
        if (!conv || q.head<2>().norm() > reach) return "";
        const Eigen::Vector3cd ev = J.eigenvalues();
        const double rate = -std::max({ev[0].real(), ev[1].real(), ev[2].real()});
        if (!(rate > 0) || !fits(sc.plate, q)) return "";
        const double passage = ring_passage(w, n);
        return exact_text(q[0]) + ' ' + exact_text(q[1]) + ' ' + exact_text(q[2]) + ' ' + exact_text(rate) + ' ' +
               exact_text(passage);
    }
    // One setting's screen: theta' on the ring at the centre, then its fixed point.
    std::string screen(const PlateMotion& base, const std::array<double, 4>& g, long& own) const {
        Scene sc = part_scene;
        sc.plate = with_rz(base, g);
        double w[kBreakRing];
        Vec3 warm = Vec3::Zero();
        for (int k = 0; k < kBreakRing; ++k) {
            const LimitCycleSummary c = limit_cycle(sc, Vec3(0, 0, -kPi + 2 * kPi * k / kBreakRing), opt.cycle, warm);
            ++own;
            if (!c.converged) return "";
            warm = c.qd_start;
            w[k] = c.twist[2];
        }
        return fixed_point_on(sc, w, kBreakRing, Vec3::Constant(NAN), 0.005, own);
    }
    std::vector<Candidate> screen_grid(const PlateMotion& aligned0, int& tried) const;
    bool lift_wells(Candidate& c, std::string& lift) const;
    double settle_offset(const Candidate& c, double settle, double T) const;
};

std::string describe(const Candidate& c) {
    std::ostringstream what;
    what.precision(3);
    what << "rz " << c.g[0] << " rad/s^2 at n = 1 along the tilts (" << (c.g[1] > 0 ? "+" : "-") << "), " << c.g[2]
         << " rad/s^2 at n = 2, phase " << c.g[3] << ", the sink's harmonics scaled by " << c.scale;
    return what.str();
}

// The grid of rz's settings (amplitude at n = 1, its sense, amplitude at n = 2, its phase) screened on
// the pair's motion. The placement turns the motion by THETA less the orientation found, and a pair
// searched at the flight margin turned that far tilts its corners beyond it (fig4: 0.04-0.09 g over):
// the sink's harmonics scaled down until some settings fit. rz's two harmonics share its peak limit: a
// setting whose rz peaks beyond `room` is scaled down onto it (its ratio and phases kept). The
// candidates ranked by the slowest start's passage (the runs' length and the design's real speed), ties
// by the grid's order (tasks finish in any order).
std::vector<Candidate> PairBreaker::screen_grid(const PlateMotion& aligned0, int& tried) const {
    std::vector<Candidate> found;
    std::vector<std::array<double, 4>> grid;   // (rz amplitude at n = 1, its sense, at n = 2, its phase)
    for (double a1 : {2.0 / 3, 1.0})
        for (double s1 : {1.0, -1.0})
            for (double a2 : {0.4, 0.5, 0.6, 0.7, 0.8, 1.0})
                for (int k = 0; k < 24; ++k) {
                    std::array<double, 4> g{a1 * room, s1, a2 * room, -kPi + k * kPi / 12};
                    PlateMotion rz = with_rz(PlateMotion{aligned0.T, {}}, g);
                    const double over = axis_peaks(rz)[5] / room;
                    if (over > 1) g[0] /= over, g[2] /= over;
                    grid.push_back(g);
                }
    for (double scale : {1.0, 0.95, 0.9, 0.85, 0.8}) {
        PlateMotion base = aligned0;
        for (Harmonic& hm : base.harmonics) hm.amp *= scale;
        const int n = static_cast<int>(grid.size());
        runner(opt)(
            n,
            [&](int k) -> std::string {
                long own = 0;
                const std::string r = screen(base, grid[k], own);
                return std::to_string(own) + (r.empty() ? "" : " " + r);
            },
            [&](int k, const std::string& text) {
                std::istringstream in(text);
                long own = 0;
                std::string x[5];
                in >> own;
                cycles += own;
                if (!(in >> x[0] >> x[1] >> x[2] >> x[3] >> x[4])) return;
                found.push_back({with_rz(base, grid[k]), Vec3(exact_value(x[0]), exact_value(x[1]), exact_value(x[2])),
                                 exact_value(x[3]), exact_value(x[4]), k, base, grid[k], scale});
            });
        tried += n;
        if (!found.empty()) break;
    }
    std::sort(found.begin(), found.end(), [](const Candidate& a, const Candidate& b) {
        return a.passage != b.passage ? a.passage < b.passage : a.index < b.index;
    });
    return found;
}

// The screen's ring lies at the centre; the field's fixed points lie on the curve s*(theta) where the
// position's twist vanishes, up to 6 mm away, where a shallow well of theta' can dip below zero
// (fig4: -0.0016 rad/s, a second stable fixed point the runs never reach). Lifting: rz's three
// settings (amplitudes, phase at n = 2) moved by a pattern search, each step to the neighbour that
// lifts the shallowest other well of w* (reduced_ring) the most, steps halved where none does, until
// it clears kWellMargin; the candidate is replaced where its fixed point is found again within the
// limits. `lift` says from what to what.
bool PairBreaker::lift_wells(Candidate& c, std::string& lift) const {
    // (the well's clearance, and the passage round the ring for the note: the smallest change that
    // clears the margin keeps the pair's small offset between field and full dynamics; a search for the
    // shortest passage instead was tried and not kept, docs/decisions.md)
    struct Score {
        double well = -HUGE_VAL, passage = HUGE_VAL;
    };
    auto score = [&](const std::array<double, 4>& g, long& own) -> Score {
        Score sc0;
        if (g[0] < 0 || g[0] > room || g[2] < 0 || g[2] > room) return sc0;
        Scene sc = part_scene;
        sc.plate = with_rz(c.base, g);
        if (!fits(sc.plate, c.q)) return sc0;
        double w[kWellRing];
        if (!reduced_ring(sc, c.q.head<2>(), kWellRing, opt.cycle, own, w)) return sc0;
        return Score{other_well(w, kWellRing, c.q[2]), ring_passage(w, kWellRing)};
    };
    std::array<double, 4> g = c.g;
    long own0 = 0;
    const Score start = score(g, own0);
    cycles += own0;
    Score now = start;
    double step[3] = {0.05 * room, 0.05 * room, kPi / 48};
    for (int it = 0; it < kLiftSteps && start.well > -HUGE_VAL && now.well < kWellMargin; ++it) {
        std::vector<std::array<double, 4>> next;
        for (int d = 0; d < 3; ++d)
            for (double sgn : {1.0, -1.0}) {
                std::array<double, 4> t = g;
                t[d == 0 ? 0 : d == 1 ? 2 : 3] += sgn * step[d];
                next.push_back(t);
            }
        std::vector<Score> got(next.size());
        runner(opt)(
            static_cast<int>(next.size()),
            [&](int k) -> std::string {
                long own = 0;
                const Score v = score(next[k], own);
                return std::to_string(own) + ' ' + exact_text(v.well) + ' ' + exact_text(v.passage);
            },
            [&](int k, const std::string& text) {
                std::istringstream in(text);
                long own = 0;
                std::string a, b;
                in >> own >> a >> b;
                cycles += own;
                got[k] = Score{exact_value(a), exact_value(b)};
            });
        std::size_t best = 0;
        for (std::size_t k = 1; k < got.size(); ++k)
            if (got[k].well > got[best].well) best = k;
        if (got[best].well > now.well) {
            now = got[best];
            g = next[best];
        } else {
            for (double& st : step) st /= 2;
        }
    }
    std::ostringstream note;
    note.precision(2);
    note << "theta' along the position's fixed points (" << kWellRing << " orientations, linearised): its shallowest "
         << "other well " << start.well << " rad/s";
    if (now.well != start.well) note << ", lifted to " << now.well << " rad/s";
    note << " (" << kWellMargin << " needed), the slowest passage round it " << std::min(now.passage, 1e9) << " s";
    lift = note.str();
    if (now.well < kWellMargin) {
        lift += " -- not applied: the margin not reached";
        return false;
    }
    if (g == c.g) return true;
    Scene sc = part_scene;
    sc.plate = with_rz(c.base, g);
    double w[kWellRing];
    long own = 0;
    const bool ring_ok = reduced_ring(sc, c.q.head<2>(), kWellRing, opt.cycle, own, w);
    const std::string r = ring_ok ? fixed_point_on(sc, w, kWellRing, c.q, 0.01, own) : "";
    cycles += own;
    std::istringstream in(r);
    std::string x[5];
    if (!(in >> x[0] >> x[1] >> x[2] >> x[3] >> x[4])) {
        lift += " -- not applied: the lifted motion's fixed point not found again within the limits";
        return false;
    }
    c.u = sc.plate;
    c.g = g;
    c.q = Vec3(exact_value(x[0]), exact_value(x[1]), exact_value(x[2]));
    c.rate = exact_value(x[3]);
    c.passage = exact_value(x[4]);
    return true;
}

// Where the full dynamics settles: from the field's fixed point, as placed, over whole periods until
// the slow mode has decayed (`settle`), theta averaged over the last period (it swings within each);
// its offset from THETA [rad] (0 if the run stopped).
double PairBreaker::settle_offset(const Candidate& c, double settle, double T) const {
    double offset = 0;
    Scene placed = part_scene;
    placed.plate = placed_motion(c.u, c.q, target.at, target.theta);
    IntegrationOptions io;
    io.rtol = 1e-7;
    const Trajectory tr =
        simulate(placed, Dynamics::Full, Vec3(target.at.x(), target.at.y(), target.theta), Vec3::Zero(), settle, T / 20, io);
    double sum_off = 0;
    int count = 0;
    for (const Sample& smp : tr.samples)
        if (smp.t > settle - T + 1e-9 * T) sum_off += wrap_angle(smp.q[2] - target.theta), ++count;
    if (tr.stop.reason == StopReason::None && count > 0) offset = sum_off / count;
    return offset;
}

}   // namespace

DesignSummary break_pair(const Scene& part_scene, const PlateMotion& pair_motion, const DesignTarget& target,
                         const DesignOptions& opt, double T, std::atomic<long>& cycles, Clock::time_point t0) {
    std::string failure = "no rz about the pair's centre left one stable orientation there";
    PairBreaker pb{part_scene, target, opt, cycles};
    const PlateMotion aligned0 = aligned_tilts(pair_motion, pb.psi);
    pb.room = 0.97 * opt.ang_limit;
    int tried = 0;
    const std::vector<Candidate> found = pb.screen_grid(aligned0, tried);
    DesignSummary kept;   // the best verified so far: unique, else the largest share of the runs
    for (std::size_t i = 0; i < found.size() && static_cast<int>(i) < kBreakVerified; ++i) {
        Candidate c = found[i];
        std::string lift;
        if (opt.lift_wells && !pb.lift_wells(c, lift)) c = found[i];
        DesignSummary sum;
        start_summary(sum, part_scene, "_fixed_point", T);
        sum.evaluations = tried;
        // The full dynamics' offset split in proportion to the two tolerances (the field's fixed point
        // within 0.02 rad of THETA, the runs within 0.05): the field's placed 2/7 of it short of THETA,
        // the full dynamics' 5/7 past it.
        const double settle = std::ceil(settle_time(2 * opt.region, c.rate, opt) / T) * T;
        const double offset = pb.settle_offset(c, settle, T);
        const double short_of = offset * 0.02 / (0.02 + 0.05);
        place_and_verify_rigid(sum, part_scene, c.u, c.q, target, opt, cycles, t0, false, 1.5 * c.passage + settle, short_of);
        if (!lift.empty()) sum.notes.push_back(lift);
        sum.notes.push_back("the half-turn pair broken by " + describe(c) +
                            " about its centre (rx and ry at n = 1 made parallel first: no tilt drift)");
        if (offset != 0) {
            std::ostringstream note;
            note.precision(2);
            note << "the full dynamics settles " << offset << " rad past the field's fixed point (averaged over a period): "
                 << "the field's is placed " << short_of << " rad short of THETA, the full dynamics' " << offset - short_of
                 << " past it (the tolerances' 0.02 : 0.05)";
            sum.notes.push_back(note.str());
        }
        if (sum.verified && sum.unique) return sum;
        if (sum.verified && (!kept.verified || sum.basin_share > kept.basin_share)) kept = sum;
        failure =
            "the first " + std::to_string(i + 1) + " of " + std::to_string(found.size()) +
            " candidates with one stable orientation at the centre did not verify as unique (the last: " +
            (sum.failure.empty() ? "verified with another stable fixed point, or unsearched cells, on the grid" : sum.failure) +
            ")";
        if (kept.verified && kept.basin_share >= 0.9) break;
    }
    if (kept.verified) {
        kept.notes.push_back("not unique: " + failure);
        return kept;
    }
    DesignSummary none;
    none.evaluations = tried;
    none.failure = found.empty() ? failure + " within the flight margin (" + std::to_string(tried) + " tried)" : failure;
    return none;
}

}   // namespace plate::design_detail
