// A plate motion from a measured cycle (issue 51): one period of the plate's sampled 6-axis
// acceleration in a CSV, turned into the harmonics of u(t) by a discrete Fourier transform.
//
//   t [s],x [m/s^2],y [m/s^2],z [m/s^2],rx [rad/s^2],ry [rad/s^2],rz [rad/s^2]
//   0,20,0,0,0,0,0
//   0.0005,19.96,0.63,0,3.1,0,0
//   ...
//
// The header is exactly this (spaces around a field ignored; lines starting with '#' and blank
// lines skipped); one row per sample, t uniformly spaced by dt, M rows covering one period
// T = M dt from the first t (the sample at t0 + T, the first one again, is not in the file).
// Phases are those of u(t) = sum amp sin(n 2 pi t / T + phase) with the file's t.
#pragma once

#include "plate/model.hpp"

#include <string>
#include <vector>

namespace plate {

struct MeasuredCycle {
    PlateMotion plate;                   // harmonics n = 1..max_n of each axis, axis order x y z rx ry rz
    Vec6 mean;                           // the data's mean per axis, removed (a periodic plate's acceleration has none)
    Vec6 rms;                            // the RMS per axis about that mean
    Vec6 residual_rms;                   // the RMS per axis of what harmonics 1..max_n leave out
    int samples = 0;                     // M
    std::vector<std::string> warnings;   // a mean that is not small against the RMS; a large residual
};

// A mean above this fraction of its axis's RMS is reported (an accelerometer offset, gravity left
// in z, a record that is not one period); so is a residual RMS above it.
inline constexpr double kMeasuredMeanWarn = 0.01;
// Harmonics below this fraction of the largest sample of their axis are rounding and dropped.
inline constexpr double kMeasuredDropRelative = 1e-12;

// max_n: the highest harmonic kept, at most (M - 1) / 2 (below the Nyquist frequency). Bad input
// (the header, a cell, the spacing of t, too few rows) throws InputError naming the file, the line
// and the column.
MeasuredCycle read_measured_cycle(const std::string& path, int max_n);
MeasuredCycle parse_measured_cycle(const std::string& text, const std::string& source, int max_n);

// The scene with its plate motion replaced by the measured one; validated (validate_scene).
Scene with_measured_plate(const Scene& scene, const MeasuredCycle& cycle);

}   // namespace plate
