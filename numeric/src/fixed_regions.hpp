// Internal to find_fixed_points: the grid configurations where the part does not move, grouped into
// connected regions (FixedPoints::stuck_regions), and the return map of rotating attractors.
#pragma once

#include "plate/field.hpp"

#include <string>
#include <vector>

namespace plate {

// Stuck all period: every contact held the whole cycle, so the twist is exactly zero.
bool stuck_all_period(const FieldPoint& p, bool point_part);
// The part does not move there: stuck all period, or sticking part of the period with a twist that is
// zero within ftol [m/s, angular times rho] (it slides back and forth and stays).
bool at_rest(const FieldPoint& p, bool point_part, double rho, double ftol);
// Connected sets (grid neighbours along each axis, theta wrapping) of configurations at rest; member,
// if given, receives each grid point's region (-1: none).
std::vector<StuckRegion> stuck_regions(const Field& f, double rho, double ftol, std::vector<int>* member = nullptr);
// "x in [a, b] m, y in [c, d] m, theta in [e, f] rad, n grid points[, reaching the grid's edge]".
std::string stuck_region_words(const StuckRegion& r, bool point_part);
// The error of a difference Jacobian's eigenvalues ev from the same Jacobian's at twice the step, ev2:
// the largest distance from each eigenvalue to the nearest of the other's.
double eigen_error(const Eigen::VectorXcd& ev, const Eigen::VectorXcd& ev2);
// A number in 3 significant digits, for sentences.
std::string short_num(double x);

// Rotating attractors of the field from the grid's columns where omega keeps one sign (appended to
// fp.rotating; work added to fp's counters); `ftol` as in FixedPointOptions, scaled by v_ref.
void find_rotating_attractors(const Scene& sc, const Field& field, const FixedPointOptions& opt, const LimitCycleOptions& cycle,
                              FixedPoints& fp);

}   // namespace plate
