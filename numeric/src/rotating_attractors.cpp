// Rotating attractors of a rigid part's field: periodic orbits of q' = xi_a(q) that turn once in
// theta while the position returns. Found as fixed points of the return map on the section
// theta = theta0 (a Poincare map), from the grid's columns where omega keeps one sign.
#include "fixed_regions.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace plate {
namespace {

struct BudgetSpent {};

// The return map: with omega of one sign along the orbit, theta is the orbit's clock, and
// d(x, y)/dtheta = (v_x, v_y) / omega, dt/dtheta = 1 / omega integrate over one turn by classical RK4 in
// theta (kSteps steps).
constexpr int kSteps = 24;
// Newton iterations on the return map from one start (each costs three maps).
constexpr int kMaxOrbitNewton = 6;

struct ReturnMap {
    const Scene& sc;
    const LimitCycleOptions& cycle;
    double theta0;
    double turn;   // +-2 pi: the direction omega turns
    long budget;
    long evals = 0, rhs_evals = 0;
    Vec3 warm = Vec3::Zero();

    // (dx/dtheta, dy/dtheta, dt/dtheta) at (x, y, theta).
    Vec3 slope(const Vec2& p, double th) {
        ++evals;
        if (budget > 0 && rhs_evals >= budget) throw BudgetSpent{};
        const Vec3 v = field_at(sc, Vec3(p[0], p[1], th), cycle, &warm, &rhs_evals);
        if (!(v[2] * turn > 0)) throw FieldUndefined("omega changes sign on the orbit", StopReason::None);
        return Vec3(v[0] / v[2], v[1] / v[2], 1 / v[2]);
    }
    // (x, y) after one turn from p, the time it took and the largest distance from p on the way.
    Vec2 operator()(const Vec2& p, double* time = nullptr, double* wobble = nullptr) {
        Vec3 y(p[0], p[1], 0);
        const double dth = turn / kSteps;
        double far = 0;
        for (int s = 0; s < kSteps; ++s) {
            const double th = theta0 + s * dth;
            const Vec3 k1 = slope(y.head<2>(), th);
            const Vec3 k2 = slope((y + 0.5 * dth * k1).head<2>(), th + 0.5 * dth);
            const Vec3 k3 = slope((y + 0.5 * dth * k2).head<2>(), th + 0.5 * dth);
            const Vec3 k4 = slope((y + dth * k3).head<2>(), th + dth);
            y += dth / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
            far = std::max(far, (y.head<2>() - p).norm());
        }
        if (time) *time = y[2];
        if (wobble) *wobble = far;
        return y.head<2>();
    }
};

// Columns (i, j) of the grid where omega keeps one sign over every theta and the mean translation
// (relative to rho |omega|) is a local minimum among the neighbouring columns, smallest first: where
// the position may settle while theta turns.
std::vector<std::array<int, 2>> turning_columns(const Field& f, double rho) {
    const GridSpec& g = f.grid;
    std::vector<double> ratio(g.nx * g.ny, std::numeric_limits<double>::infinity());
    for (int i = 0; i < g.nx; ++i)
        for (int j = 0; j < g.ny; ++j) {
            Vec3 mean = Vec3::Zero();
            int pos = 0, neg = 0;
            for (int k = 0; k < g.nth; ++k) {
                const FieldPoint& p = f.points[g.index(i, j, k)];
                if (!p.converged) break;
                pos += p.twist[2] > 0;
                neg += p.twist[2] < 0;
                mean += p.twist / g.nth;
            }
            if (pos == g.nth || neg == g.nth) ratio[i * g.ny + j] = mean.head<2>().norm() / (rho * std::abs(mean[2]));
        }
    std::vector<std::pair<double, std::array<int, 2>>> cols;
    for (int i = 0; i < g.nx; ++i)
        for (int j = 0; j < g.ny; ++j) {
            const double r = ratio[i * g.ny + j];
            bool minimum = std::isfinite(r);
            for (int a = std::max(0, i - 1); a <= std::min(g.nx - 1, i + 1) && minimum; ++a)
                for (int b = std::max(0, j - 1); b <= std::min(g.ny - 1, j + 1); ++b)
                    minimum = minimum && r <= ratio[a * g.ny + b];
            if (minimum) cols.push_back({r, {i, j}});
        }
    std::sort(cols.begin(), cols.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<std::array<int, 2>> out;
    for (const auto& c : cols) out.push_back(c.second);
    return out;
}

Stability multiplier_stability(const Eigen::Vector2cd& mu) {
    const double a = std::abs(mu[0]), b = std::abs(mu[1]);
    return std::max(a, b) < 1 ? Stability::Stable : std::min(a, b) > 1 ? Stability::Unstable : Stability::Saddle;
}

}   // namespace

void find_rotating_attractors(const Scene& sc, const Field& field, const FixedPointOptions& opt, const LimitCycleOptions& cycle,
                              FixedPoints& fp) {
    const GridSpec& g = field.grid;
    if (sc.part.point || g.nth < 2 || opt.max_orbit_starts <= 0) return;
    const double rho = sc.part.rho();
    const double cell = std::min(g.dx() > 0 ? g.dx() : 1.0, g.dy() > 0 ? g.dy() : 1.0);
    const double tol = 1e-5 * cell;   // |return(q) - q| accepted as closed [m]
    const double h = 1e-3 * cell;     // the map's difference step
    const std::vector<std::array<int, 2>> cols = turning_columns(field, rho);
    const long left = opt.max_rhs_evaluations > 0 ? std::max(1L, opt.max_rhs_evaluations - fp.rhs_evaluations) : 0;
    int starts = 0;
    for (const auto& c : cols) {
        if (starts >= opt.max_orbit_starts) break;
        const Vec3 q0 = g.at(c[0], c[1], 0);
        bool near_known = false;
        for (const auto& r : fp.rotating) near_known = near_known || (r.q.head<2>() - q0.head<2>()).norm() < cell;
        if (near_known) continue;
        ++starts;
        const double omega = field.points[g.index(c[0], c[1], 0)].twist[2];
        ReturnMap P{sc, cycle, g.th0, omega > 0 ? 2 * kPi : -2 * kPi, left};
        Vec2 p = q0.head<2>();
        bool closed = false, spent = false;
        Eigen::Matrix2d D = Eigen::Matrix2d::Identity();
        RotatingAttractor ra;
        try {
            for (int it = 0; it < kMaxOrbitNewton && !closed; ++it) {
                const Vec2 r = P(p) - p;
                // The map's Jacobian by forward differences; Newton on return(p) - p = 0.
                for (int a = 0; a < 2; ++a) {
                    Vec2 pa = p;
                    pa[a] += h;
                    D.col(a) = (P(pa) - pa - r) / h;
                }
                closed = r.norm() < tol;
                if (closed) break;
                Vec2 step = -D.fullPivLu().solve(r);
                if (step.norm() > cell) step *= cell / step.norm();
                p += step;
                if (p[0] < g.x0 - cell || p[0] > g.x1 + cell || p[1] < g.y0 - cell || p[1] > g.y1 + cell) break;
            }
            if (closed) ra.residual = (P(p, &ra.period, &ra.wobble) - p).norm();
        } catch (const FieldUndefined&) {
            closed = false;
        } catch (const BudgetSpent&) {
            closed = false;
            spent = true;
        }
        fp.evaluations += P.evals;
        fp.rhs_evaluations += P.rhs_evals;
        if (spent) break;
        if (!closed) continue;
        ra.q = Vec3(p[0], p[1], wrap_angle(g.th0));
        ra.rate = P.turn / ra.period;
        ra.period = std::abs(ra.period);
        Eigen::EigenSolver<Eigen::Matrix2d> es(D + Eigen::Matrix2d::Identity());
        ra.multipliers = es.eigenvalues();
        ra.stability = multiplier_stability(ra.multipliers);
        bool dup = false;
        for (const auto& r : fp.rotating) dup = dup || (r.q.head<2>() - ra.q.head<2>()).norm() < 0.1 * cell;
        if (!dup) fp.rotating.push_back(ra);
    }
}

std::string rotating_attractor_words(const RotatingAttractor& r) {
    const std::string at = "(" + short_num(r.q[0]) + ", " + short_num(r.q[1]) + ") m";
    const std::string head = r.stability == Stability::Stable     ? "a rotating attractor: the position settles at " + at
                             : r.stability == Stability::Unstable ? "an unstable rotating orbit about " + at
                                                                  : "a saddle rotating orbit about " + at;
    return head + " while theta turns at " + short_num(r.rate) + " rad/s (" + (r.rate > 0 ? "counter-clockwise" : "clockwise") +
           ", a turn in " + short_num(r.period) + " s)";
}

}   // namespace plate
