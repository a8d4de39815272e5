#include "plate/robustness.hpp"

#include "plate/random_scene.hpp"
#include "plate/simulate.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace plate {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity(), kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr std::uint64_t kNominal = std::numeric_limits<std::uint64_t>::max();

// Within `scale` times the arrival tolerances of `at` (a point part: position only): scale 1 is an
// arrival at the target; 0.1 is caught by a fixed point, where the field is linear about it.
bool within(const Vec3& q, const Vec3& at, bool point, const RobustnessOptions& opt, double scale = 1) {
    const bool near = std::hypot(q[0] - at[0], q[1] - at[1]) <= scale * opt.arrive_distance;
    return near && (point || std::abs(wrap_angle(q[2] - at[2])) <= scale * opt.arrive_angle);
}

// The field's integral curve from q0 (classical RK4, step opt.curve_step) until it comes within the
// arrival tolerances of the target: that time, inf past the horizon, NaN where the field is undefined.
// A curve caught by one of the stable fixed points `elsewhere` (none within the tolerances of the
// target) ends there: it converges to that point and never arrives (inf).
double field_arrival(const Scene& sc, const Vec3& q0, const Vec3& target, const std::vector<Vec3>& elsewhere,
                     const RobustnessOptions& opt) {
    const bool point = sc.part.point;
    const LimitCycleOptions& lo = opt.fixed.cycle;
    const double h = opt.curve_step;
    Vec3 q = q0, warm = Vec3::Zero();
    try {
        for (double t = 0;; t += h) {
            if (within(q, target, point, opt)) return t;
            for (const Vec3& e : elsewhere)
                if (within(q, e, point, opt, 0.1)) return kInf;
            if (t + h > opt.horizon * (1 + 1e-12)) return kInf;
            const Vec3 k1 = field_at(sc, q, lo, &warm);
            const Vec3 k2 = field_at(sc, q + h / 2 * k1, lo, &warm);
            const Vec3 k3 = field_at(sc, q + h / 2 * k2, lo, &warm);
            const Vec3 k4 = field_at(sc, q + h * k3, lo, &warm);
            q += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
            if (point) q[2] = 0;
        }
    } catch (const FieldUndefined&) {
        return kNaN;
    }
}

// The full dynamics from rest at q0 over the horizon, seen at the period's starts: the time after which
// the part stays within the arrival tolerances to the end; inf if it is not within them at the end, NaN
// if the run stopped (contact lost, budget).
double full_arrival(const Scene& sc, const Vec3& q0, const Vec3& target, const RobustnessOptions& opt) {
    const double T = sc.plate.T;
    IntegrationOptions io;
    io.rtol = opt.fixed.cycle.integration.rtol;
    const Trajectory tr = simulate(sc, Dynamics::Full, q0, Vec3::Zero(), opt.horizon, T, io);
    if (tr.stop.reason != StopReason::None) return kNaN;
    double since = kInf;
    for (const Sample& s : tr.samples) {
        if (!within(s.q, target, sc.part.point, opt))
            since = kInf;
        else if (!(since < kInf))
            since = s.t;
    }
    return since;
}

// The field of one plate and its fixed points: the outcome, the target's fixed point, the attractors.
// The stable fixed points go to `stable`.
void classify(const Scene& sc, const Vec3& target, const RobustnessOptions& opt, DrawResult& r, std::vector<Vec3>& stable) {
    FieldOptions fo;
    fo.cycle = opt.fixed.cycle;
    fo.threads = 1;
    const Field field = compute_field(sc, opt.grid, fo);
    int undefined = 0;
    for (const FieldPoint& fp : field.points) {
        if (fp.converged) continue;
        if (fp.stop == StopReason::ContactLost) {
            r.outcome = Outcome::contact_lost;
            r.note = "contact lost at (" + std::to_string(fp.q[0]) + " m, " + std::to_string(fp.q[1]) + " m, " +
                     std::to_string(fp.q[2]) + " rad)";
            return;
        }
        ++undefined;
    }
    if (undefined > 0) {
        r.outcome = Outcome::failed;
        r.note = std::to_string(undefined) + " configurations of the grid without a cycle";
        return;
    }
    const FixedPoints fps = find_fixed_points(sc, field, opt.fixed);
    if (fps.unsearched_cells > 0) {
        r.outcome = Outcome::failed;
        r.note = "the refinement's budget was spent (" + std::to_string(fps.unsearched_cells) + " cells not searched)";
        return;
    }
    const bool point = sc.part.point;
    const FixedPoint* best = nullptr;
    double best_distance = kInf;
    for (const FixedPoint& p : fps.points) {
        if (p.stability != Stability::Stable) continue;
        ++r.attractors;
        stable.push_back(p.q);
        const double d = std::hypot(p.q[0] - target[0], p.q[1] - target[1]);
        const double a = point ? 0 : std::abs(wrap_angle(p.q[2] - target[2]));
        if (d <= opt.match_distance && a <= opt.match_angle && d < best_distance) {
            best = &p;
            best_distance = d;
        }
    }
    std::string other;
    for (const FixedPoint& p : fps.points)
        if (p.stability == Stability::Stable && &p != best && other.empty())
            other = "a stable fixed point at (" + std::to_string(p.q[0]) + " m, " + std::to_string(p.q[1]) + " m, " +
                    std::to_string(p.q[2]) + " rad)";
    if (best) {
        r.matched = true;
        r.fixed_point = best->q;
        const Eigen::Vector3cd& ev = best->eigenvalues;
        r.rate = -(point ? std::max(ev[0].real(), ev[1].real()) : ev.real().maxCoeff());
    }
    for (const FixedLine& l : fps.lines)
        if (l.stability == Stability::Stable) {
            ++r.attractors;
            if (other.empty()) other = "a stable line of fixed points";
        }
    for (std::size_t k = 0; k < fps.stuck_regions.size(); ++k) {
        ++r.attractors;
        if (other.empty())
            other = "a region where the part sticks (x in [" + std::to_string(fps.stuck_regions[k].lo[0]) + ", " +
                    std::to_string(fps.stuck_regions[k].hi[0]) + "] m, y in [" + std::to_string(fps.stuck_regions[k].lo[1]) +
                    ", " + std::to_string(fps.stuck_regions[k].hi[1]) + "] m)";
    }
    for (const RotatingAttractor& ra : fps.rotating)
        if (ra.stability == Stability::Stable) {
            ++r.attractors;
            if (other.empty()) other = "a rotating attractor";
        }
    if (!r.matched) {
        r.outcome = Outcome::none;
        r.note = other.empty() ? "no stable fixed point" : "no stable fixed point at the target; " + other;
    } else if (r.attractors > 1) {
        r.outcome = Outcome::competing;
        r.note = other;
    } else {
        r.outcome = Outcome::unique;
    }
}

DrawResult analyse(const Scene& sc, std::uint64_t index, const Vec3& target, const std::vector<Vec3>& starts, bool full,
                   const RobustnessOptions& opt) {
    DrawResult r;
    r.index = index;
    std::vector<Vec3> stable, elsewhere;
    classify(sc, target, opt, r, stable);
    if (r.outcome == Outcome::contact_lost || r.outcome == Outcome::failed) return r;
    for (const Vec3& q : stable)
        if (!within(q, target, sc.part.point, opt)) elsewhere.push_back(q);
    for (const Vec3& q0 : starts) r.arrival.push_back(field_arrival(sc, q0, target, elsewhere, opt));
    if (full)
        for (const Vec3& q0 : starts) r.arrival_full.push_back(full_arrival(sc, q0, target, opt));
    return r;
}

// ---- a draw's result as text (the task runner's), exactly -----------------------------------------

void put(std::ostringstream& o, const std::vector<double>& v) {
    o << v.size();
    for (double x : v) o << ' ' << exact_text(x);
    o << '\n';
}
std::vector<double> get(std::istringstream& in) {
    std::size_t n = 0;
    in >> n;
    std::vector<double> v(n);
    for (auto& x : v) {
        std::string t;
        in >> t;
        x = exact_value(t);
    }
    return v;
}
std::string to_text(const DrawResult& r) {
    std::ostringstream o;
    o << r.index << ' ' << static_cast<int>(r.outcome) << ' ' << r.matched << ' ' << r.attractors << '\n';
    put(o, {r.fixed_point[0], r.fixed_point[1], r.fixed_point[2], r.rate});
    put(o, r.p);
    put(o, r.arrival);
    put(o, r.arrival_full);
    o << r.note;
    return o.str();
}
DrawResult from_text(const std::string& text) {
    std::istringstream in(text);
    DrawResult r;
    int outcome = 0;
    in >> r.index >> outcome >> r.matched >> r.attractors;
    r.outcome = static_cast<Outcome>(outcome);
    const std::vector<double> fp = get(in);
    r.fixed_point = Vec3(fp[0], fp[1], fp[2]);
    r.rate = fp[3];
    r.p = get(in);
    r.arrival = get(in);
    r.arrival_full = get(in);
    in.get();   // the newline before the note
    std::getline(in, r.note, '\0');
    return r;
}

// The starts: uniform over the grid's square and the full turn, from the spec's seed (their own stream:
// the same for every draw).
std::vector<Vec3> seeded_starts(const Scene& sc, const UncertaintySpec& spec, const RobustnessOptions& opt) {
    Rng r(spec.seed ^ 0x5354415254535354ull);
    std::vector<Vec3> out;
    for (int i = 0; i < opt.starts; ++i) {
        const double x = r.uniform(opt.grid.x0, opt.grid.x1), y = r.uniform(opt.grid.y0, opt.grid.y1);
        const double th = r.uniform(-kPi, kPi);
        out.emplace_back(x, y, sc.part.point ? 0 : th);
    }
    return out;
}

double percentile95(std::vector<double> v) {
    if (v.empty()) return kNaN;
    std::sort(v.begin(), v.end());
    const std::size_t k = static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(v.size()))) - 1;
    return v[std::min(k, v.size() - 1)];
}

// The Monte Carlo spread and, with sensitivities, each draw's linear prediction against it.
void spread(RobustnessSummary& s, const Vec3& reference) {
    std::vector<Vec3> d;
    std::vector<double> r, a, err;
    const double rho = s.nominal.part.point ? 0 : s.nominal.part.rho();
    for (const DrawResult& x : s.draws) {
        if (!x.matched) continue;
        Vec3 o = x.fixed_point - reference;
        o[2] = wrap_angle(o[2]);
        d.push_back(o);
        r.push_back(std::hypot(o[0], o[1]));
        a.push_back(std::abs(o[2]));
        if (s.sensitivities.empty()) continue;
        Vec3 lin = Vec3::Zero();
        for (std::size_t k = 0; k < s.sensitivities.size(); ++k) lin += s.sensitivities[k].dq * x.p[k];
        const Vec3 w(1, 1, rho);
        const double n = o.cwiseProduct(w).norm();
        if (n > 0) err.push_back((o - lin).cwiseProduct(w).norm() / n);
    }
    if (d.empty()) return;
    for (const Vec3& o : d) s.mean_offset += o / static_cast<double>(d.size());
    for (const Vec3& o : d) s.covariance += (o - s.mean_offset) * (o - s.mean_offset).transpose() / static_cast<double>(d.size());
    s.radius95 = percentile95(r);
    s.angle95 = percentile95(a);
    if (err.empty()) return;
    s.linear_error_max = *std::max_element(err.begin(), err.end());
    for (double e : err) s.nonlinear_draws += e > 0.3;
    std::sort(err.begin(), err.end());
    s.linear_error_median = err[err.size() / 2];
}

}   // namespace

const char* outcome_name(Outcome o) {
    switch (o) {
        case Outcome::unique:
            return "unique";
        case Outcome::competing:
            return "competing";
        case Outcome::none:
            return "none";
        case Outcome::contact_lost:
            return "contact lost";
        case Outcome::failed:
            return "failed";
    }
    return "?";
}

RobustnessSummary robustness(const Scene& nominal, const UncertaintySpec& spec, const RobustnessOptions& opt) {
    if (opt.draws < 1 || opt.starts < 0 || opt.full_draws < 0 || !(opt.horizon > 0) || !(opt.curve_step > 0))
        throw std::invalid_argument("robustness: draws >= 1, starts and full_draws >= 0, horizon and curve_step > 0");
    validate_uncertainty(spec);
    const auto t0 = std::chrono::steady_clock::now();
    RobustnessSummary s;
    s.nominal = nominal;
    s.starts = seeded_starts(nominal, spec, opt);
    // The target: given, or the nominal's one stable fixed point.
    RobustnessOptions o = opt;
    if (!opt.target) {
        DrawResult probe;
        std::vector<Vec3> stable;
        o.match_distance = kInf;
        o.match_angle = kInf;
        classify(nominal, Vec3::Zero(), o, probe, stable);
        if (probe.attractors != 1 || !probe.matched)
            throw std::invalid_argument("the nominal field has " + std::to_string(probe.attractors) +
                                        " attractors on the grid (" + (probe.note.empty() ? "none" : probe.note) +
                                        "): name the fixed point to follow (a target)");
        o = opt;
        o.target = probe.fixed_point;
    }
    s.target = *o.target;
    if (nominal.part.point) s.target[2] = 0;
    s.nominal_result = analyse(nominal, kNominal, s.target, s.starts, o.full_draws > 0, o);
    s.nominal_result.p.assign(uncertain_parameters(nominal, spec).size(), 0.0);
    const Vec3 reference = s.nominal_result.matched ? s.nominal_result.fixed_point : s.target;
    if (o.sensitivities && s.nominal_result.matched)
        fixed_point_sensitivities(nominal, spec, s.nominal_result.fixed_point, o.fixed.cycle, s);

    TaskRunner run = o.tasks ? o.tasks : thread_tasks(o.threads);
    s.draws.resize(o.draws);
    run(
        o.draws,
        [&](int i) {
            const auto index = static_cast<std::uint64_t>(i);
            try {
                const Draw d = draw_with_deviations(nominal, spec, index);
                DrawResult r = analyse(d.scene, index, s.target, s.starts, i < o.full_draws, o);
                r.p = d.p;
                return to_text(r);
            } catch (const std::exception& e) {   // (InputError: no valid draw; a failure is an outcome)
                DrawResult r;
                r.index = index;
                r.note = e.what();
                return to_text(r);
            }
        },
        [&, done = 0](int i, const std::string& text) mutable {
            s.draws[i] = from_text(text);
            if (o.progress) o.progress(++done, o.draws);
        });
    for (const DrawResult& r : s.draws) ++s.counts[static_cast<int>(r.outcome)];
    spread(s, reference);
    s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return s;
}

Share wilson(int k, int n) {
    if (n <= 0) return {kNaN, 0, 1};
    const double z = 1.959963984540054, p = static_cast<double>(k) / n, z2n = z * z / n;
    const double centre = (p + z2n / 2) / (1 + z2n);
    const double half = z * std::sqrt(p * (1 - p) / n + z2n / (4 * n)) / (1 + z2n);
    // (At k = 0 the lower end is 0 exactly, at k = n the upper is 1: written so, not left to rounding.)
    return {p, k == 0 ? 0.0 : centre - half, k == n ? 1.0 : centre + half};
}

}   // namespace plate
