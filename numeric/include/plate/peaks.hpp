// PEAKS of a plate motion. What an actuator saturates on: per axis a, the peak over the period of
// |u_a(t)|, the axis' harmonics summed (x, y, z in m/s^2; rx, ry, rz in rad/s^2; entries of one (axis,
// n) add as phasors, a negative amp is a half-period phase). Not the sum of the amplitudes: a third
// harmonic a sixth of the first flattens its crest (sin t + sin(3 t) / 6 peaks at sqrt(3) / 2), in the
// wrong phase it sharpens it (sin t - sin(3 t) / 3 = (4 / 3) sin^3 t). Exact to roundoff: the extrema
// are the zeros of the derivative, a trigonometric polynomial's, found as a companion matrix's
// eigenvalues and polished by Newton steps (peaks.cpp; tests/design/test_design_peaks.cpp: within
// 1e-12 of closed forms). The one home of the peaks: design's limits and identification's suggested
// motions both judge a motion by them.
#pragma once

#include "plate/model.hpp"

#include <complex>
#include <vector>

namespace plate {

Vec6 axis_peaks(const PlateMotion& u);

// The largest |f| of the real trigonometric polynomial f(theta) = F_0 + 2 Re sum_{k >= 1} F_k e^{i k theta}
// (F[0] real), to roundoff (peaks.cpp says how).
double trig_peak(const std::vector<std::complex<double>>& F);
// max over t of |(u_x(t), u_y(t))|: the largest peak of x (or y) over every turn of the motion about z.
double horizontal_peak(const PlateMotion& u);
// max_t |(f_1(t), ..., f_m(t))| for real trigonometric polynomials given as trig_peak's F_k.
double norm_peak(const std::vector<std::vector<std::complex<double>>>& f);

// What a plate's stops and its actuators' speed bound: the plate's corners at (+-half_size.x,
// +-half_size.y) in the plate frame [m], and over the period and the four corners the peak length of
// a corner's displacement from its mean position [m] and of its velocity [m/s]. To first order in the
// plate's rotation, which is milliradians (d = p + phi x r with phi the zero-mean integral of omega, as
// PlateMotion::displacement; v = p' + omega x r). Exact to roundoff as the peaks above.
struct CornerPeaks {
    double displacement = 0;   // [m]
    double velocity = 0;       // [m/s]
};
CornerPeaks corner_peaks(const PlateMotion& u, const Vec2& half_size);

}   // namespace plate
