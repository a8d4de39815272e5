// Rotating attractors of a rigid part's field: periodic orbits of q' = xi_a(q) that turn once in
// theta while the position returns. Found as fixed points of the return map on the section
// theta = theta0 (a Poincare map), from the grid's columns where omega keeps one sign; on a plate
// motion symmetric about the plate's z axis, as zeros of the field of the axis seen from the part
// (relative equilibria: the part turns rigidly about the axis), which the return map cannot follow
// cheaply (fig6: docs/decisions/cycles-and-fields.md, Fixed-point outputs named right).
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
// Newton iterations on the axis field G (plate motions symmetric about z) from one start.
constexpr int kMaxAxisNewton = 12;
// Starts on G per FixedPointOptions::max_orbit_starts (a 2-D Newton each, tens of field evaluations).
constexpr int kAxisStartsPerOrbitStart = 4;

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

// Every harmonic on z or rz: the plate motion (and gravity) look the same after any turn about the
// plate's z axis, so the field is equivariant: xi(R(a) s, theta + a) = (R(a) v, omega).
bool symmetric_about_z(const Scene& sc) {
    for (const Harmonic& h : sc.plate.harmonics)
        if (h.amp != 0 && h.axis != Axis::z && h.axis != Axis::rz) return false;
    return true;
}

// On such a motion the plate's axis seen from the part, b = -R(theta)^T s, moves by a field of its own,
// db/dt = G(b) = R(theta)^T (omega J s - v), the same at every theta. A zero of G is a relative
// equilibrium: the part's point b stays on the axis while the part turns about it at a constant omega.
// G is evaluated on the section theta = theta0.
struct AxisField {
    const Scene& sc;
    const LimitCycleOptions& cycle;
    double theta0;
    long budget;
    long evals = 0, rhs_evals = 0;
    Vec3 warm = Vec3::Zero();

    static Vec2 g(const Vec2& s, const Vec3& v, double th) {
        const Vec2 d(-v[2] * s[1] - v[0], v[2] * s[0] - v[1]);   // omega J s - v
        return Eigen::Rotation2Dd(-th) * d;
    }
    static Vec2 b_of(const Vec2& s, double th) { return -(Eigen::Rotation2Dd(-th) * s); }
    Vec2 s_of(const Vec2& b) const { return -(Eigen::Rotation2Dd(theta0) * b); }
    Vec2 operator()(const Vec2& b, double* omega = nullptr) {
        ++evals;
        if (budget > 0 && rhs_evals >= budget) throw BudgetSpent{};
        const Vec2 s = s_of(b);
        const Vec3 v = field_at(sc, Vec3(s[0], s[1], theta0), cycle, &warm, &rhs_evals);
        if (omega) *omega = v[2];
        return g(s, v, theta0);
    }
    // Forward differences (Newton's), or central (gb unused) for the eigenvalues: at b = 0 of a
    // symmetric part G has quadratic terms that bias the forward difference beyond its own error.
    Eigen::Matrix2d jacobian(const Vec2& b, const Vec2& gb, double h, bool central = false) {
        Eigen::Matrix2d D;
        for (int a = 0; a < 2; ++a) {
            Vec2 bp = b, bm = b;
            bp[a] += h;
            bm[a] -= h;
            D.col(a) = central ? ((*this)(bp) - (*this)(bm)) / (2 * h) : ((*this)(bp)-gb) / h;
        }
        return D;
    }
};

// Starts for Newton on G: the grid's configurations, every theta, seen from the part (b), where
// |G| relative to rho |omega| is smallest, at least a cell apart; at most `max`.
std::vector<Vec2> axis_starts(const Field& f, double rho, double cell, int max) {
    const GridSpec& g = f.grid;
    std::vector<std::pair<double, Vec2>> all;
    for (int i = 0; i < g.nx; ++i)
        for (int j = 0; j < g.ny; ++j)
            for (int k = 0; k < g.nth; ++k) {
                const FieldPoint& p = f.points[g.index(i, j, k)];
                if (!p.converged || p.twist[2] == 0) continue;
                const Vec2 s = p.q.head<2>();
                all.push_back(
                    {AxisField::g(s, p.twist, p.q[2]).norm() / (rho * std::abs(p.twist[2])), AxisField::b_of(s, p.q[2])});
            }
    std::sort(all.begin(), all.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<Vec2> out;
    for (const auto& c : all) {
        if (static_cast<int>(out.size()) >= max) break;
        bool near = false;
        for (const Vec2& o : out) near = near || (o - c.second).norm() < cell;
        if (!near) out.push_back(c.second);
    }
    return out;
}

// The error of the real parts of ev (what decides stability) from ev2, the same Jacobian's at twice the
// step: each eigenvalue against the nearest of the other's. (Not eigen_error: at b = 0 of a symmetric
// part the swirl's frequency grows with the distance from the axis, so the imaginary parts differ by
// the step -- spin_symmetric: 0.160 and 0.170 1/s at h and 2h -- while the real parts agree to 2e-5.)
double real_part_error(const Eigen::Vector2cd& ev, const Eigen::Vector2cd& ev2) {
    double err = 0;
    for (int i = 0; i < 2; ++i) {
        const int j = std::abs(ev2[0] - ev[i]) <= std::abs(ev2[1] - ev[i]) ? 0 : 1;
        err = std::max(err, std::abs(ev2[j].real() - ev[i].real()));
    }
    return err;
}

// Relative equilibria: Newton on G from the starts; stability from G's Jacobian (its eigenvalues'
// error from the Jacobian at twice the step), the return map's multipliers exp(lambda T).
void find_axis_rotations(const Scene& sc, const Field& field, const FixedPointOptions& opt, const LimitCycleOptions& cycle,
                         FixedPoints& fp, double cell) {
    const GridSpec& g = field.grid;
    const double tol = 1e-5 * cell, h = 1e-3 * cell;
    const double reach = Vec2(std::max(-g.x0, g.x1), std::max(-g.y0, g.y1)).norm() + cell;
    const long left = opt.max_rhs_evaluations > 0 ? std::max(1L, opt.max_rhs_evaluations - fp.rhs_evaluations) : 0;
    AxisField G{sc, cycle, g.th0, left};
    for (Vec2 b : axis_starts(field, sc.part.rho(), cell, kAxisStartsPerOrbitStart * opt.max_orbit_starts)) {
        bool closed = false;
        double omega = 0;
        Vec2 gb;
        Eigen::Vector2cd ev, ev2;
        try {
            gb = G(b, &omega);
            Eigen::Matrix2d D = G.jacobian(b, gb, h);
            for (int it = 0; it < kMaxAxisNewton && !closed; ++it) {
                Vec2 step = -D.fullPivLu().solve(gb);
                if (step.norm() > cell) step *= cell / step.norm();
                b += step;
                if (b.norm() > reach) break;
                gb = G(b, &omega);
                D = G.jacobian(b, gb, h);
                closed = step.norm() < tol;
            }
            // omega zero within the zero search's tolerance: a fixed point of the field, not a rotation.
            closed = closed && sc.part.rho() * std::abs(omega) > opt.ftol * sc.v_ref();
            for (const auto& r : fp.rotating) closed = closed && (r.pivot - b).norm() >= 0.1 * cell;
            if (closed) {
                ev = Eigen::EigenSolver<Eigen::Matrix2d>(G.jacobian(b, gb, h, true)).eigenvalues();
                ev2 = Eigen::EigenSolver<Eigen::Matrix2d>(G.jacobian(b, gb, 2 * h, true)).eigenvalues();
            }
        } catch (const FieldUndefined&) {
            closed = false;   // this start's Newton left the defined field; the next start goes on
        } catch (const BudgetSpent&) {
            break;
        }
        if (!closed) continue;
        RotatingAttractor ra;
        const Vec2 s = G.s_of(b);
        ra.q = Vec3(s[0], s[1], wrap_angle(g.th0));
        ra.rate = omega;
        ra.period = 2 * kPi / std::abs(omega);
        ra.multipliers = (ev * ra.period).array().exp();
        ra.stability = classify_eigenvalues(ev, real_part_error(ev, ev2));
        ra.residual = gb.norm() * ra.period;
        // Within the closing tolerance of the axis the position itself is settled there.
        const bool settled = b.norm() < tol;
        ra.centre = settled ? s : Vec2::Zero();
        ra.radius = settled ? 0 : b.norm();
        ra.wobble = 2 * ra.radius;
        ra.pivot = settled ? Vec2::Zero() : b;
        fp.rotating.push_back(ra);
    }
    fp.evaluations += G.evals;
    fp.rhs_evaluations += G.rhs_evals;
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
    if (symmetric_about_z(sc)) {
        find_axis_rotations(sc, field, opt, cycle, fp, cell);
        return;
    }
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
        ra.centre = p;
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
    const bool circling = r.radius > 0;
    const std::string at = circling ? "(" + short_num(r.centre[0]) + ", " + short_num(r.centre[1]) + ") m"
                                    : "(" + short_num(r.q[0]) + ", " + short_num(r.q[1]) + ") m";
    std::string head = r.stability == Stability::Stable     ? "a rotating attractor"
                       : r.stability == Stability::Unstable ? "an unstable rotating orbit"
                       : r.stability == Stability::Centre   ? "a rotating orbit neutral to first order (a centre)"
                                                            : "a saddle rotating orbit";
    if (circling)
        head += ": the part turns about its point (" + short_num(r.pivot[0]) + ", " + short_num(r.pivot[1]) + ") m held at " +
                at + ", its position circling at radius " + short_num(r.radius) + " m,";
    else
        head += r.stability == Stability::Stable ? ": the position settles at " + at : " about " + at;
    return head + " while theta turns at " + short_num(r.rate) + " rad/s (" + (r.rate > 0 ? "counter-clockwise" : "clockwise") +
           ", a turn in " + short_num(r.period) + " s)";
}

}   // namespace plate
