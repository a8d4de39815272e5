// Profile likelihood (profile.hpp): each profiled parameter stepped outward from the estimate, the rest
// and the tracks' starts re-minimised by the fit's own Levenberg-Marquardt (internal.hpp: minimise) at
// each step, warm-started from the step before.
#include "plate/profile.hpp"

#include "internal.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <stdexcept>

namespace plate {
namespace {

using namespace identify_detail;
using Clock = std::chrono::steady_clock;

constexpr int kRefinements = 3;   // re-minimised points at most to place a crossing, within max_steps

// Ends the re-minimisation under way once the profiles' simulations or time are spent.
class Budget final : public ceres::IterationCallback {
public:
    Budget(const std::vector<TrackCost*>& costs, const ProfileOptions& po, Clock::time_point t0)
        : costs_(costs), po_(po), t0_(t0) {}
    long simulations() const {
        long n = 0;
        for (const TrackCost* c : costs_) n += c->simulations();
        return n;
    }
    double left() const { return po_.time_limit - std::chrono::duration<double>(Clock::now() - t0_).count(); }
    bool spent() const { return simulations() >= po_.max_simulations || left() <= 0; }
    ceres::CallbackReturnType operator()(const ceres::IterationSummary&) override {
        return spent() ? ceres::SOLVER_ABORT : ceres::SOLVER_CONTINUE;
    }

private:
    const std::vector<TrackCost*>& costs_;
    const ProfileOptions& po_;
    Clock::time_point t0_;
};

// One profile under way: the fit's optimum in the profile's coordinates z (the profiled one in scene
// units), the bounds, and the re-minimisation at a value.
struct Walk {
    const Layout& layout;
    const IdentifyOptions& o;
    const ProfileOptions& po;
    const std::vector<TrackCost*>& costs;
    Budget& budget;
    int j;
    std::vector<double> z_hat;
    std::vector<std::vector<double>> q0_hat;
    std::vector<int> bases;   // the kinetic coordinates a profiled static coefficient must stay above
    double chi2_min;

    struct Point {
        bool ok = false;
        double value = 0, dchi2 = 0;
        std::vector<double> z;
        std::vector<std::vector<double>> q0;
    };

    // chi2 at parameter j = v minimised over the rest, started at `from`.
    Point at(double v, const Point& from) const {
        Point p = from;
        p.value = v;
        p.z[j] = v;
        std::vector<double> lo, hi;
        for (int k = 0; k < layout.size(); ++k) {
            lo.push_back(layout.lower(k, o));
            hi.push_back(layout.upper(k, o));
        }
        for (int k : bases) hi[k] = std::min(hi[k], v);
        for (int k = 0; k < layout.size(); ++k)
            if (k != j) p.z[k] = std::min(std::max(p.z[k], lo[k]), hi[k]);
        lo[j] = v - 1;   // held by the manifold; Ceres asks lower < upper
        hi[j] = v + 1;
        for (TrackCost* c : costs) c->profile(j, lo, hi);
        if (budget.spent()) return p;
        const Solve s = minimise(costs, p.z, p.q0, {j}, lo, hi, po.max_iterations, std::max(budget.left(), 1e-3), o.threads,
                                 &budget, o.initial_trust_radius);
        p.ok = s.usable && std::isfinite(s.chi2);
        p.dchi2 = s.chi2 - chi2_min;
        return p;
    }
};

// The profile's end on one side (dir -1 or +1): the points walked into `out`, the end value returned.
double walk(const Walk& w, double v_hat, double bound, double dir, double delta, ProfileEnd& end, double& drop,
            std::vector<ProfilePoint>& out) {
    const double r = std::sqrt(kProfileThreshold95);
    Walk::Point prev;
    prev.ok = true;
    prev.value = v_hat;
    prev.z = w.z_hat;
    prev.q0 = w.q0_hat;
    end = ProfileEnd::CutShort;
    for (int step = 0; step < w.po.max_steps; ++step) {
        const double v = dir > 0 ? std::min(prev.value + delta, bound) : std::max(prev.value - delta, bound);
        const Walk::Point p = w.at(v, prev);
        if (!p.ok) return prev.value;
        out.push_back({p.value, p.dchi2});
        drop = std::max(drop, -p.dchi2);
        if (p.dchi2 >= kProfileThreshold95) {
            // Between prev and p: interpolated on sqrt(dchi2), linear in the value for a quadratic profile.
            Walk::Point a = prev, b = p;
            auto cross = [&] {
                const double sa = std::sqrt(std::max(a.dchi2, 0.0)), sb = std::sqrt(b.dchi2);
                return a.value + (r - sa) / (sb - sa) * (b.value - a.value);
            };
            double c = cross();
            // Refined by re-minimised points while the bracket is wider than a tenth of the distance to the
            // estimate and the last point is off the line by 0.02 or more (a profile that is a step, not a
            // parabola, needs several).
            for (int refine = 0; refine < kRefinements && step + 1 + refine < w.po.max_steps &&
                                 std::abs(b.value - a.value) > 0.1 * std::abs(c - v_hat);
                 ++refine) {
                // The first at the interpolated crossing; then the bracket's middle (sqrt-interpolation
                // creeps along a step's flat side).
                const Walk::Point m = w.at(refine == 0 ? c : 0.5 * (a.value + b.value), a);
                if (!m.ok) break;
                out.push_back({m.value, m.dchi2});
                drop = std::max(drop, -m.dchi2);
                (m.dchi2 >= kProfileThreshold95 ? b : a) = m;
                c = cross();
                if (std::abs(m.dchi2 - kProfileThreshold95) < 0.02) break;   // on the line: done
            }
            end = ProfileEnd::Crossed;
            return c;
        }
        if (v == bound) {
            end = ProfileEnd::AtBound;
            return bound;
        }
        // The next step towards the crossing a quadratic through the estimate predicts, at least 1.5 and
        // at most 4 times the last (flat: 4 times).
        const double dist = std::abs(v - v_hat), c2 = std::max(p.dchi2, 0.0) / (dist * dist);
        const double predicted = c2 > 0 ? 1.1 * r / std::sqrt(c2) - dist : 4 * delta;
        delta = std::min(std::max(predicted, 1.5 * delta), 4 * delta);
        prev = p;
    }
    return prev.value;
}

// Which interval is THE interval, and the verdict.
void judge_profile(ParameterProfile& p, double agreement) {
    const bool lin = std::isfinite(p.linear_lo) && std::isfinite(p.linear_hi);
    const auto num = [](double x) {
        char b[32];
        std::snprintf(b, sizeof b, "%.4g", x);
        return std::string(b);
    };
    if (p.lo_end == ProfileEnd::CutShort || p.hi_end == ProfileEnd::CutShort) {
        p.interval_is_profile = !lin;
        p.identifiable = lin;
        p.verdict = std::string("profile cut short (a cap reached or a simulation stopped): ") +
                    (lin ? "the linearised interval kept" : "no interval");
        return;
    }
    if (p.lo_end == ProfileEnd::AtBound && p.hi_end == ProfileEnd::AtBound) {
        p.interval_is_profile = true;
        p.identifiable = false;
        p.verdict = "not identifiable from these tracks: the profile stays within 3.84 of its minimum from bound to bound (" +
                    num(p.bound_lo) + " to " + num(p.bound_hi) + ")";
        return;
    }
    if (p.lo_end == ProfileEnd::AtBound || p.hi_end == ProfileEnd::AtBound) {
        p.interval_is_profile = true;
        p.verdict = "one-sided: the profile interval runs to the bound " +
                    num(p.lo_end == ProfileEnd::AtBound ? p.bound_lo : p.bound_hi) +
                    (lin ? " (the linearised interval does not)" : "");
        return;
    }
    if (!lin) {
        p.interval_is_profile = true;
        p.verdict = "the profile closes where the linearised information did not: profile interval used";
        return;
    }
    const double half = 0.5 * (p.linear_hi - p.linear_lo);
    const double off = std::max(std::abs(p.lo - p.linear_lo), std::abs(p.hi - p.linear_hi)) / half;
    p.interval_is_profile = off > agreement;
    p.verdict = (p.interval_is_profile ? "the linearised interval's ends are off by "
                                       : "agrees with the linearised interval: ends within ") +
                num(off) + " of its half-width" + (p.interval_is_profile ? ": profile interval used" : "");
}

}   // namespace

const char* to_string(ProfileEnd e) {
    return e == ProfileEnd::Crossed ? "crossed" : e == ProfileEnd::AtBound ? "at bound" : "cut short";
}

void ProfileOptions::validate() const {
    auto bad = [](const std::string& what) { throw std::invalid_argument("profile: " + what); };
    if (max_steps < 1 || max_steps > 1000) bad("max_steps: from 1 to 1000");
    if (max_iterations < 1 || max_iterations > 10000) bad("max_iterations: from 1 to 10000");
    if (max_simulations < 1) bad("max_simulations: at least 1");
    if (!(time_limit > 0 && time_limit <= 1e6)) bad("time_limit: a positive number of seconds up to 1e6");
    if (!(agreement > 0 && agreement <= 10)) bad("agreement: in (0, 10]");
}

ProfileSummary profile_likelihood(const Scene& scene, const std::vector<Track>& tracks, const IdentifyOptions& o,
                                  const IdentifySummary& fit, const ProfileOptions& po) {
    const auto t0 = Clock::now();
    o.validate();
    po.validate();
    const Layout layout(scene, o.params);
    const int n = layout.size(), d = scene.part.point ? 2 : 3;
    if (static_cast<int>(fit.params.size()) != n || fit.tracks.size() != tracks.size())
        throw std::invalid_argument("profile: the fit is not of these parameters and tracks");
    std::vector<int> which;
    for (const std::string& name : po.params) {
        int k = 0;
        while (k < n && layout.p[k].name != name) ++k;
        if (k == n) throw std::invalid_argument("profile: " + name + " was not fitted");
        which.push_back(k);
    }
    if (po.params.empty())
        for (int k = 0; k < n; ++k) which.push_back(k);

    std::vector<std::unique_ptr<TrackCost>> owned;
    std::vector<TrackCost*> costs;
    for (const Track& tr : tracks) {
        owned.push_back(
            std::make_unique<TrackCost>(scene, layout, tr, first_used_frame(tr, scene.plate.T, o.settle_periods), o, true));
        costs.push_back(owned.back().get());
    }
    Budget budget(costs, po, t0);
    std::vector<double> v_hat;
    for (const FittedParameter& p : fit.params) v_hat.push_back(p.estimate);
    const std::vector<double> x_hat = layout.internal(v_hat);
    std::vector<std::vector<double>> q0_hat;
    for (const TrackFit& t : fit.tracks) {
        q0_hat.push_back({t.start.x() * 1e3, t.start.y() * 1e3, t.start.z()});
        q0_hat.back().resize(d);
    }

    ProfileSummary out;
    out.chi2_min = fit.chi2;
    for (int j : which) {
        const auto tj = Clock::now();
        const long sims0 = budget.simulations();
        const FittedParameter& f = fit.params[j];
        ParameterProfile p;
        p.name = f.name;
        p.unit = f.unit;
        p.estimate = f.estimate;
        const double within = within_cell_sd(f);   // (NaN: not identifiable)
        p.linear_lo = f.identifiable ? f.estimate - kZ95 * within : std::numeric_limits<double>::quiet_NaN();
        p.linear_hi = f.identifiable ? f.estimate + kZ95 * within : std::numeric_limits<double>::quiet_NaN();
        Walk w{layout, o, po, costs, budget, j, x_hat, q0_hat, {}, fit.chi2};
        w.z_hat[j] = f.estimate;
        const Param& q = layout.p[j];
        if (q.kind == Param::Kinetic) {
            p.bound_lo = o.mu_min;
            p.bound_hi = o.mu_max;
        } else if (q.kind == Param::Static) {
            p.bound_lo = f.estimate - x_hat[j];   // its kinetic base at the estimate
            p.bound_hi = o.mu_max;
            for (int k = 0; k < n; ++k)
                if (layout.p[k].kind == Param::Kinetic &&
                    (q.contact < 0 || layout.p[k].contact < 0 || layout.p[k].contact == q.contact))
                    w.bases.push_back(k);
        } else {
            p.bound_lo = -o.com_max;
            p.bound_hi = o.com_max;
        }
        // The first step: the linearised sd where there is one, else a sixteenth of the range.
        const double range = p.bound_hi - p.bound_lo;
        const double delta = f.identifiable && within > 0 ? std::min(within, range / 4) : range / 16;
        std::vector<ProfilePoint> pts{{f.estimate, 0}};
        p.lo = f.estimate > p.bound_lo ? walk(w, f.estimate, p.bound_lo, -1, delta, p.lo_end, p.chi2_drop, pts) : p.bound_lo;
        if (f.estimate <= p.bound_lo) p.lo_end = ProfileEnd::AtBound;
        p.hi = f.estimate < p.bound_hi ? walk(w, f.estimate, p.bound_hi, +1, delta, p.hi_end, p.chi2_drop, pts) : p.bound_hi;
        if (f.estimate >= p.bound_hi) p.hi_end = ProfileEnd::AtBound;
        std::sort(pts.begin(), pts.end(), [](const ProfilePoint& a, const ProfilePoint& b) { return a.value < b.value; });
        p.points = pts;
        judge_profile(p, po.agreement);
        const double cells = f.identifiable ? kZ95 * f.sd_cells : 0.0;
        p.lo_reported = std::max(p.bound_lo, p.estimate - std::hypot(p.estimate - p.lo, cells));
        p.hi_reported = std::min(p.bound_hi, p.estimate + std::hypot(p.hi - p.estimate, cells));
        if (p.chi2_drop > 1)
            p.verdict += "; the profile found a chi-square " + std::to_string(p.chi2_drop) +
                         " below the fit's: the fit was not at its minimum";
        p.simulations = budget.simulations() - sims0;
        p.seconds = std::chrono::duration<double>(Clock::now() - tj).count();
        out.profiles.push_back(p);
    }
    out.simulations = budget.simulations();
    out.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return out;
}

}   // namespace plate
