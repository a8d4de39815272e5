#include "plate/field.hpp"

#include "fixed_regions.hpp"

#include <algorithm>
#include <cmath>

namespace plate {
namespace {

using VecX = Eigen::VectorXd;
using MatX = Eigen::MatrixXd;

// The field in scaled coordinates z = (s_x, s_y, rho theta) with values (v_x, v_y, rho omega):
// both in metres and metres per second, so that distances and singular values compare.
struct BudgetSpent {};   // FixedPointOptions::max_rhs_evaluations reached

struct ScaledField {
    const Scene& sc;
    const LimitCycleOptions& opt;
    int dim;
    double rho;
    long evals = 0;
    long rhs_evals = 0;   // the cycles' work
    long budget = 0;      // of rhs_evals (0: none); F throws BudgetSpent beyond it
    Vec3 warm = Vec3::Zero();

    Vec3 q_of(const VecX& z) const { return dim == 3 ? Vec3(z[0], z[1], z[2] / rho) : Vec3(z[0], z[1], 0); }
    VecX z_of(const Vec3& q) const {
        VecX z(dim);
        z[0] = q[0];
        z[1] = q[1];
        if (dim == 3) z[2] = rho * q[2];
        return z;
    }
    VecX F(const VecX& z) {
        ++evals;
        if (budget > 0 && rhs_evals >= budget) throw BudgetSpent{};
        const Vec3 v = field_at(sc, q_of(z), opt, &warm, &rhs_evals);
        VecX f(dim);
        f[0] = v[0];
        f[1] = v[1];
        if (dim == 3) f[2] = rho * v[2];
        return f;
    }
    MatX J(const VecX& z, double h) {
        MatX Jm(dim, dim);
        for (int c = 0; c < dim; ++c) {
            VecX zp = z, zm = z;
            zp[c] += h;
            zm[c] -= h;
            Jm.col(c) = (F(zp) - F(zm)) / (2 * h);
        }
        return Jm;
    }
};


// Gauss-Newton with SVD, the directions with singular values below `cut` * sigma_max left
// alone (so that on a line of zeros it corrects only across the line). Backtracking on |F|.
// With `chord`, that Jacobian is used throughout (chord method, for following a line).
bool newton(ScaledField& f, VecX& z, double ftol, int max_it, double max_step, double h, double cut,
            const VecX* keep_dir = nullptr, const MatX* chord = nullptr) {
    VecX F = f.F(z);
    for (int it = 0; it < max_it; ++it) {
        if (F.lpNorm<Eigen::Infinity>() < ftol) return true;
        const MatX Jm = chord ? *chord : f.J(z, h);
        Eigen::JacobiSVD<MatX> svd(Jm, Eigen::ComputeFullU | Eigen::ComputeFullV);
        const VecX s = svd.singularValues();
        VecX dz = VecX::Zero(z.size());
        for (int i = 0; i < s.size(); ++i) {
            if (s[i] <= cut * s[0]) continue;
            dz -= svd.matrixV().col(i) * (svd.matrixU().col(i).dot(F) / s[i]);
        }
        if (keep_dir) dz -= keep_dir->dot(dz) * *keep_dir;   // stay on the hyperplane
        if (dz.norm() > max_step) dz *= max_step / dz.norm();
        bool improved = false;
        for (int ls = 0; ls < 6; ++ls) {
            VecX zt = z + dz;
            VecX Ft = f.F(zt);
            if (Ft.norm() < F.norm()) {
                z = zt;
                F = Ft;
                improved = true;
                break;
            }
            dz *= 0.5;
        }
        if (!improved) return F.lpNorm<Eigen::Infinity>() < ftol;
    }
    return F.lpNorm<Eigen::Infinity>() < ftol;
}

// Singular values below kCut * sigma_max are finite-difference noise: the field is accurate to
// about 1e-7 v_ref and the difference step is 5e-3 cells, so Jacobian entries carry errors of
// order 1e-4 relative.
constexpr double kCut = 1e-3;

// A cell is searched unless a zero found lies in it or within half a cell of it: the reach of in_cell.
constexpr double kInside = 1.0;

// Cells without a sign change searched by Newton at most (the rest are counted and make a warning).
constexpr int kMaxNearZero = 16;

}   // namespace

// The error of the eigenvalues of a difference Jacobian, from the same Jacobian at twice the step:
// the largest distance from each eigenvalue to the nearest of the other's. (The central difference's
// truncation error grows 4x with the step, the field's noise halves: either way the difference of the
// two is of the size of the error.)
double eigen_error(const Eigen::VectorXcd& ev, const Eigen::VectorXcd& ev2) {
    double err = 0;
    for (int i = 0; i < ev.size(); ++i) err = std::max(err, (ev2.array() - ev[i]).abs().minCoeff());
    return err;
}

namespace {

// One find_fixed_points: the scaled field, the zeros found so far and the search's scales, with its
// stages -- a cell's corners (is it a candidate?), Newton from its centre, and the zero's
// classification as a point or a line followed both ways.
struct FixedPointSearch {
    const Field& field;
    const FixedPointOptions& opt;
    const GridSpec& g;
    const int dim;
    LimitCycleOptions cycle;
    ScaledField f;
    double ftol;
    double cell;
    double h;
    FixedPoints out;
    std::vector<int> region;                                        // each grid point's stuck region (-1: none)
    std::vector<std::pair<double, std::array<int, 3>>> near_zero;   // cells without a sign change whose
                                                                    // field is near zero, with their score
    bool from_near_zero = false;                                    // searching those now

    FixedPointSearch(const Scene& sc, const Field& field, const FixedPointOptions& opt)
        : field(field), opt(opt), g(field.grid), dim(sc.part.point ? 2 : 3), cycle(opt.cycle), f{sc, cycle, dim, sc.part.rho()} {
        // field noise well below ftol (FixedPointOptions)
        cycle.integration.rtol = std::min(cycle.integration.rtol, 1e-3 * opt.ftol);
        cycle.tol = std::min(cycle.tol, 1e-2 * opt.ftol);
        ftol = opt.ftol * sc.v_ref();
        cell = std::min(g.dx() > 0 ? g.dx() : 1.0, g.dy() > 0 ? g.dy() : 1.0);
        if (dim == 3) cell = std::min(cell, f.rho * g.dth());
        h = 5e-3 * cell;
        out.point_part = dim == 2;
        out.stuck_regions = stuck_regions(field, f.rho, ftol, &region);
    }

    bool inside(const VecX& z) const {
        const double mx = 0.25 * g.dx(), my = 0.25 * g.dy();
        return z[0] >= g.x0 - mx && z[0] <= g.x1 + mx && z[1] >= g.y0 - my && z[1] <= g.y1 + my;
    }
    // Scaled distance with theta periodic.
    double dist(const VecX& a, const VecX& b) const {
        VecX d = a - b;
        if (dim == 3) d[2] = f.rho * wrap_angle((a[2] - b[2]) / f.rho);
        return d.norm();
    }
    // The grid index of corner c (bits: +x, +y, +theta) of the cell at (i, j, k); theta wraps.
    int corner(int i, int j, int k, int c) const {
        return g.index(i + (c & 1), j + ((c >> 1) & 1), dim == 3 ? (k + ((c >> 2) & 1)) % g.nth : 0);
    }
    bool known(const VecX& z, double radius) const;
    bool in_cell(const Vec3& qc, double reach) const;
    bool candidate(int i, int j, int k);
    void search_cell(int i, int j, int k);
    bool in_region(const Vec3& q) const;
    bool resolved(int i, int j, int k, const VecX& centre) const;
    bool refined_candidate(int i, int j, int k, const Vec3& qc);
    bool follow_line(const VecX& z, const MatX& Jm, const Eigen::VectorXcd& ev, const Eigen::Vector3cd& ev3, double err,
                     const VecX& v, const Vec3& q);
};

bool FixedPointSearch::known(const VecX& z, double radius) const {
    for (const auto& p : out.points)
        if (dist(z, f.z_of(p.q)) < radius) return true;
    for (const auto& l : out.lines)
        for (const auto& q : l.points)
            if (dist(z, f.z_of(q)) < radius) return true;
    return false;
}

// Is a known zero within `reach` cells of the centre qc along each axis (0.5: in the cell; 1: in the
// cell widened by half a cell each way)?
bool FixedPointSearch::in_cell(const Vec3& qc, double reach) const {
    auto near = [&](const Vec3& q) {
        return std::abs(q[0] - qc[0]) <= reach * g.dx() && std::abs(q[1] - qc[1]) <= reach * g.dy() &&
               (dim == 2 || std::abs(wrap_angle(q[2] - qc[2])) <= reach * g.dth());
    };
    for (const auto& p : out.points)
        if (near(p.q)) return true;
    for (const auto& l : out.lines)
        for (const auto& q : l.points)
            if (near(q)) return true;
    return false;
}

// Does the cell at (i, j, k) hold a zero, by its corners' twists (counted in out: every cell, the
// undefined, the stuck and the candidates)?
bool FixedPointSearch::candidate(int i, int j, int k) {
    // Corners of the cell; theta wraps.
    Eigen::Vector3d lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
    bool ok = true;
    for (int c = 0; c < (dim == 3 ? 8 : 4); ++c) {
        const int at = corner(i, j, k, c);
        const FieldPoint& p = field.points[at];
        if (!p.converged) {
            ok = false;
            break;
        }
        const Vec3 v(p.twist[0], p.twist[1], f.rho * p.twist[2]);
        lo = lo.cwiseMin(v);
        hi = hi.cwiseMax(v);
    }
    ++out.cells;
    if (!ok) {
        ++out.undefined_cells;
        return false;
    }
    bool stuck = false;
    for (int c = 0; c < (dim == 3 ? 8 : 4) && !stuck; ++c) {
        const int at = corner(i, j, k, c);
        stuck = region[at] >= 0;
    }
    if (stuck) {
        ++out.stuck_cells;
        return false;
    }
    bool cand = true;
    double score = 0;   // how far, in cells, linearly, the farthest component's zero lies beyond the cell
    for (int c = 0; c < dim; ++c) {
        cand = cand && lo[c] <= ftol && hi[c] >= -ftol;
        const double nearest = lo[c] > 0 ? lo[c] : hi[c] < 0 ? -hi[c] : 0;
        score = std::max(score, nearest / std::max(hi[c] - lo[c], 1e-300));
    }
    if (!cand) {
        if (score < 0.5) near_zero.push_back({score, {i, j, k}});
        return false;
    }
    ++out.candidates;
    return true;
}

// Newton from a candidate cell's centre; a new zero is classified and kept as a point or a line.
void FixedPointSearch::search_cell(int i, int j, int k) {
    Vec3 qc = g.at(i, j, k) + 0.5 * Vec3(g.dx(), g.dy(), g.dth());
    VecX z = f.z_of(qc);
    if (in_cell(qc, kInside)) return;   // a zero already found lies in (or next to) this cell
    f.warm.setZero();
    try {
        if (!from_near_zero && !resolved(i, j, k, f.F(z))) ++out.unresolved_cells;
        if (!newton(f, z, ftol, opt.max_newton, cell, h, kCut)) return;
    } catch (const FieldUndefined&) {
        return;
    }
    if (!inside(z) || known(z, 0.5 * cell)) return;
    if (f.F(z).isZero(0) || in_region(f.q_of(z))) return;   // landed in a region where the part does not move

    // Classify, with the eigenvalues' error from the Jacobian at twice the step.
    MatX Jm, J2;
    try {
        Jm = f.J(z, h);
        J2 = f.J(z, 2 * h);
    } catch (const FieldUndefined&) {
        return;
    }
    const Eigen::VectorXcd ev = Eigen::EigenSolver<MatX>(Jm).eigenvalues();
    const double err = eigen_error(ev, Eigen::EigenSolver<MatX>(J2).eigenvalues());
    Eigen::Vector3cd ev3 = Eigen::Vector3cd::Zero();
    ev3.head(dim) = ev;
    Eigen::JacobiSVD<MatX> svd(Jm, Eigen::ComputeFullV);
    const VecX s = svd.singularValues();
    const Vec3 q = f.q_of(z);

    bool is_line = false;
    if (s[dim - 1] < opt.null_ratio * s[0]) is_line = follow_line(z, Jm, ev, ev3, err, svd.matrixV().col(dim - 1), q);
    if (!is_line) {
        FixedPoint fp;
        fp.q = q;
        fp.q[2] = dim == 3 ? wrap_angle(q[2]) : 0;
        fp.eigenvalues = ev3;
        fp.eigen_error = err;
        fp.stability = classify_eigenvalues(ev, err);
        fp.residual = f.F(z).norm();
        out.points.push_back(fp);
    }
    if (from_near_zero) ++out.coarse_zeros;
}

// Do the cell's corners resolve the field inside it: is the field at its centre within the corners'
// spread of their mean (the trilinear interpolant there), in every component?
bool FixedPointSearch::resolved(int i, int j, int k, const VecX& centre) const {
    const int corners = dim == 3 ? 8 : 4;
    MatX v(dim, corners);
    for (int c = 0; c < corners; ++c) {
        const int at = corner(i, j, k, c);
        v.col(c) = f.z_of(field.points[at].twist);   // (v_x, v_y, rho omega)
    }
    for (int c = 0; c < dim; ++c) {
        const double spread = v.row(c).maxCoeff() - v.row(c).minCoeff();
        if (std::abs(centre[c] - v.row(c).mean()) > std::max(spread, ftol)) return false;
    }
    return true;
}

// Does every component change sign among the cell's corners and the field at its centre qc?
bool FixedPointSearch::refined_candidate(int i, int j, int k, const Vec3& qc) {
    VecX fc;
    try {
        f.warm.setZero();
        fc = f.F(f.z_of(qc));
    } catch (const FieldUndefined&) {
        return false;
    }
    for (int c = 0; c < dim; ++c) {
        double lo = fc[c], hi = fc[c];
        for (int n = 0; n < (dim == 3 ? 8 : 4); ++n) {
            const int at = corner(i, j, k, n);
            const double v = f.z_of(field.points[at].twist)[c];
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        }
        if (lo > ftol || hi < -ftol) return false;
    }
    return true;
}

// Does the grid cell holding q have a corner in a stuck region?
bool FixedPointSearch::in_region(const Vec3& q) const {
    const int i = std::clamp(static_cast<int>(std::floor((q[0] - g.x0) / g.dx())), 0, g.nx - 2);
    const int j = std::clamp(static_cast<int>(std::floor((q[1] - g.y0) / g.dy())), 0, g.ny - 2);
    const int k = dim == 3 ? static_cast<int>(std::floor(wrap_angle(q[2] - g.th0) / g.dth() + g.nth)) % g.nth : 0;
    for (int c = 0; c < (dim == 3 ? 8 : 4); ++c)
        if (region[corner(i, j, k, c)] >= 0) return true;
    return false;
}

// Follows the null direction v of the zero z (at q; Jm its Jacobian, ev its eigenvalues) both ways;
// kept as a line if it goes on for at least two points.
bool FixedPointSearch::follow_line(const VecX& z, const MatX& Jm, const Eigen::VectorXcd& ev, const Eigen::Vector3cd& ev3,
                                   double err, const VecX& v, const Vec3& q) {
    FixedLine line;
    std::vector<Vec3> fwd, bwd;
    for (int sgn : {1, -1}) {
        VecX zc = z, dir = sgn * v;
        double travelled = 0;
        for (int step = 0; step < 400; ++step) {
            VecX zn = zc + 0.5 * cell * dir;
            try {
                if (!newton(f, zn, ftol, 8, 0.5 * cell, h, opt.null_ratio, &dir, &Jm)) break;
            } catch (const FieldUndefined&) {
                break;
            }
            if (!inside(zn)) break;
            travelled += dist(zn, zc);
            dir = (zn - zc).normalized();
            zc = zn;
            (sgn > 0 ? fwd : bwd).push_back(f.q_of(zc));
            if (dim == 3 && travelled > 2 * kPi * f.rho + (g.x1 - g.x0) + (g.y1 - g.y0)) break;
        }
    }
    if (fwd.size() + bwd.size() < 2) return false;
    for (auto it = bwd.rbegin(); it != bwd.rend(); ++it) line.points.push_back(*it);
    line.points.push_back(q);
    for (const auto& p : fwd) line.points.push_back(p);
    for (auto& p : line.points) p[2] = wrap_angle(p[2]);
    line.direction = f.q_of(v);
    if (dim == 3) line.direction[2] = v[2] / f.rho;
    line.eigenvalues = ev3;
    int skip = 0;
    ev.cwiseAbs().minCoeff(&skip);
    line.stability = classify_eigenvalues(ev, err, skip);
    line.eigen_error = err;
    for (std::size_t m = 1; m < line.points.size(); ++m) line.length += dist(f.z_of(line.points[m]), f.z_of(line.points[m - 1]));
    out.lines.push_back(line);
    return true;
}

}   // namespace

FixedPoints find_fixed_points(const Scene& sc, const Field& field, const FixedPointOptions& opt) {
    const StopScope scope(opt.stop);
    FixedPointSearch run(sc, field, opt);
    const GridSpec& g = run.g;
    const int dim = run.dim;
    const int nk = dim == 3 ? g.nth : 1;
    run.f.budget = opt.max_rhs_evaluations;
    std::size_t next_near = 0;
    try {
        for (int i = 0; i + 1 < g.nx; ++i)
            for (int j = 0; j + 1 < g.ny; ++j)
                for (int k = 0; k < nk; ++k) {
                    if (dim == 3 && g.nth < 2) break;
                    if (run.candidate(i, j, k)) run.search_cell(i, j, k);
                }
        // Then the cells the corners' signs cannot decide, nearest to a sign change first, unless a zero
        // found lies next to them; at most kMaxNearZero.
        run.from_near_zero = true;
        std::stable_sort(run.near_zero.begin(), run.near_zero.end(),
                         [](const auto& a, const auto& b) { return a.first < b.first; });
        for (; next_near < run.near_zero.size(); ++next_near) {
            const auto& c = run.near_zero[next_near].second;
            if (run.in_cell(g.at(c[0], c[1], c[2]) + 0.5 * Vec3(g.dx(), g.dy(), g.dth()), 1.0)) continue;
            // Refined once: the field at the centre with the corners; searched when every component
            // changes sign among those nine (or five) values.
            const Vec3 qc = g.at(c[0], c[1], c[2]) + 0.5 * Vec3(g.dx(), g.dy(), g.dth());
            if (!run.refined_candidate(c[0], c[1], c[2], qc)) continue;
            if (run.out.near_zero_cells == kMaxNearZero) {
                ++run.out.near_zero_unsearched;
                continue;
            }
            ++run.out.near_zero_cells;
            run.search_cell(c[0], c[1], c[2]);
        }
    } catch (const BudgetSpent&) {
        if (run.from_near_zero) {
            run.out.near_zero_unsearched += static_cast<int>(run.near_zero.size() - next_near);
        } else {
            // The budget is spent: the cell in progress and every later one are counted as not searched.
            const int total = (g.nx - 1) * (g.ny - 1) * (dim == 3 && g.nth >= 2 ? nk : dim == 3 ? 0 : 1);
            run.out.unsearched_cells = total - run.out.cells + 1;
            run.out.cells = total;
        }
    }
    if (run.out.coarse_zeros > 0 || run.out.near_zero_unsearched > 0 || run.out.unresolved_cells > 0)
        run.out.suggested_grid = 2 * (std::max(g.nx, g.ny) - 1) + 1;
    run.out.evaluations = run.f.evals;
    run.out.rhs_evaluations = run.f.rhs_evals;
    find_rotating_attractors(sc, field, opt, run.cycle, run.out);
    return run.out;
}

// Real parts within 3 x error of zero are zero as far as the Jacobian can tell; all of them so, with
// a complex pair beyond it, make a centre.
Stability classify_eigenvalues(const Eigen::VectorXcd& ev, double error, int skip) {
    const double thr = 3 * error;
    bool neg = true, pos = true, undecided = true, turning = false;
    for (int i = 0; i < ev.size(); ++i) {
        if (i == skip) continue;
        neg = neg && ev[i].real() < 0;
        pos = pos && ev[i].real() > 0;
        undecided = undecided && std::abs(ev[i].real()) <= thr;
        turning = turning || std::abs(ev[i].imag()) > thr;
    }
    if (undecided && turning) return Stability::Centre;
    return neg ? Stability::Stable : pos ? Stability::Unstable : Stability::Saddle;
}

std::string fixed_points_sentence(const FixedPoints& fp) {
    auto count = [](std::size_t n, const char* one, const char* many) { return std::to_string(n) + " " + (n == 1 ? one : many); };
    std::string s;
    if (fp.points.empty() && fp.lines.empty())
        s = "no fixed point found";
    else if (fp.lines.empty())
        s = count(fp.points.size(), "fixed point", "fixed points") + " found";
    else if (fp.points.empty())
        s = count(fp.lines.size(), "line of fixed points", "lines of fixed points") + " found";
    else
        s = count(fp.points.size(), "fixed point", "fixed points") + " and " +
            count(fp.lines.size(), "line of fixed points", "lines of fixed points") + " found";
    if (fp.undefined_cells > 0)
        s += " in the defined part (" + std::to_string(fp.undefined_cells) + " of " + std::to_string(fp.cells) +
             " cells undefined: a corner has no cycle)";
    if (fp.unsearched_cells > 0)
        s += " (the search stopped at its work budget, FixedPointOptions::max_rhs_evaluations: " +
             std::to_string(fp.unsearched_cells) + " of " + std::to_string(fp.cells) + " cells not searched)";
    for (const StuckRegion& r : fp.stuck_regions) {
        s += "; a region where the part sticks (" + stuck_region_words(r, fp.point_part) + ")";
    }
    if (!fp.stuck_regions.empty())
        s += " (every configuration in it is fixed: a region rather than points; " + std::to_string(fp.stuck_cells) + " of " +
             std::to_string(fp.cells) + " cells touch it and were not refined)";
    for (const RotatingAttractor& r : fp.rotating) s += "; " + rotating_attractor_words(r);
    if (fp.suggested_grid > 0) {
        s += "; the grid may be too coarse: ";
        if (fp.coarse_zeros > 0)
            s += count(fp.coarse_zeros, "zero was", "zeros were") + " found only in cells without a sign change at their corners";
        std::string sep = fp.coarse_zeros > 0 ? ", " : "";
        if (fp.near_zero_unsearched > 0) {
            s += sep + count(fp.near_zero_unsearched, "cell", "cells") + " with a near-zero field were not searched";
            sep = ", ";
        }
        if (fp.unresolved_cells > 0)
            s += sep + "at " + count(fp.unresolved_cells, "cell", "cells") +
                 " the field at the centre is not what the corners say";
        s += "; try --grid " + std::to_string(fp.suggested_grid);
    }
    return s;
}

}   // namespace plate
