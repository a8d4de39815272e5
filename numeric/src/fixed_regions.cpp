// Regions of a field where the part does not move (stuck regions), found on the grid as connected
// sets of configurations; they are reported with their extent instead of being refined as zeros.
#include "fixed_regions.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace plate {

std::string short_num(double x) {
    char b[32];
    std::snprintf(b, sizeof b, "%.3g", std::abs(x) < 1e-12 ? 0.0 : x);
    return b;
}

bool stuck_all_period(const FieldPoint& p, bool point_part) {
    if (!p.converged || !p.twist.isZero(0)) return false;
    for (int i = 0; i < (point_part ? 1 : 3); ++i)
        if (p.stick_fraction[i] < 1 - 1e-12) return false;
    return true;
}

bool at_rest(const FieldPoint& p, bool point_part, double rho, double ftol) {
    if (!p.converged) return false;
    if (stuck_all_period(p, point_part)) return true;
    const double sticks = *std::max_element(p.stick_fraction.begin(), p.stick_fraction.begin() + (point_part ? 1 : 3));
    const Vec3 v(p.twist[0], p.twist[1], rho * p.twist[2]);
    return sticks > 0 && v.lpNorm<Eigen::Infinity>() <= ftol;
}

namespace {

// The theta interval [lo, hi] (hi >= lo, possibly beyond pi) covering the occupied layers of a
// region: the complement of the largest run of unoccupied layers, theta wrapping.
void theta_extent(const GridSpec& g, const std::vector<bool>& layer, StuckRegion& r) {
    int occupied = 0;
    for (bool b : layer) occupied += b;
    if (occupied == g.nth) {
        r.all_theta = true;
        r.lo[2] = wrap_angle(g.th0);
        r.hi[2] = r.lo[2] + (g.nth - 1) * g.dth();
        return;
    }
    int best_start = 0, best_len = 0;   // the longest circular run of empty layers
    for (int s = 0; s < g.nth; ++s) {
        if (layer[s] || !layer[(s + g.nth - 1) % g.nth]) continue;   // a run starts after an occupied layer
        int len = 0;
        while (len < g.nth && !layer[(s + len) % g.nth]) ++len;
        if (len > best_len) best_len = len, best_start = s;
    }
    const int first = (best_start + best_len) % g.nth;   // the first occupied layer after the gap
    r.lo[2] = wrap_angle(g.th0 + first * g.dth());
    r.hi[2] = r.lo[2] + (g.nth - best_len - 1) * g.dth();
}

}   // namespace

std::vector<StuckRegion> stuck_regions(const Field& f, double rho, double ftol, std::vector<int>* member) {
    const GridSpec& g = f.grid;
    const int nk = f.point_part ? 1 : g.nth;
    std::vector<int> id(f.points.size(), -1);
    std::vector<StuckRegion> out;
    std::vector<int> stack;
    for (int start = 0; start < g.size(); ++start) {
        if (id[start] >= 0 || !at_rest(f.points[start], f.point_part, rho, ftol)) continue;
        StuckRegion r;
        r.lo = Vec3::Constant(1e300);
        r.hi = Vec3::Constant(-1e300);
        std::vector<bool> layer(nk, false);
        const int label = static_cast<int>(out.size());
        id[start] = label;
        stack.assign(1, start);
        while (!stack.empty()) {
            const int n = stack.back();
            stack.pop_back();
            const int k = n % g.nth, j = (n / g.nth) % g.ny, i = n / (g.nth * g.ny);
            ++r.grid_points;
            layer[f.point_part ? 0 : k] = true;
            const Vec3 q = g.at(i, j, k);
            r.lo.head<2>() = r.lo.head<2>().cwiseMin(q.head<2>());
            r.hi.head<2>() = r.hi.head<2>().cwiseMax(q.head<2>());
            r.touches_edge = r.touches_edge || i == 0 || j == 0 || i == g.nx - 1 || j == g.ny - 1;
            const int nb[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k}, {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
            for (const auto& c : nb) {
                if (c[0] < 0 || c[0] >= g.nx || c[1] < 0 || c[1] >= g.ny) continue;
                if (nk == 1 && c[2] != k) continue;
                const int m = g.index(c[0], c[1], (c[2] + g.nth) % g.nth);
                if (id[m] >= 0 || !at_rest(f.points[m], f.point_part, rho, ftol)) continue;
                id[m] = label;
                stack.push_back(m);
            }
        }
        if (f.point_part) {
            r.lo[2] = r.hi[2] = 0;
        } else {
            theta_extent(g, layer, r);
        }
        out.push_back(r);
    }
    if (member) *member = std::move(id);
    return out;
}

std::string stuck_region_words(const StuckRegion& r, bool point_part) {
    auto range = [](double a, double b) { return "[" + short_num(a) + ", " + short_num(b) + "]"; };
    std::string s = "x in " + range(r.lo[0], r.hi[0]) + " m, y in " + range(r.lo[1], r.hi[1]) + " m";
    if (!point_part) s += r.all_theta ? ", every theta" : ", theta in " + range(r.lo[2], r.hi[2]) + " rad";
    s += ", " + std::to_string(r.grid_points) + (r.grid_points == 1 ? " grid point" : " grid points");
    if (r.touches_edge) s += ", reaching the grid's edge";
    return s;
}

}   // namespace plate
