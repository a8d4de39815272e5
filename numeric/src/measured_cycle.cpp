#include "plate/measured_cycle.hpp"

#include "plate/scene_io.hpp"

#include "input_reader.hpp"

#include <cmath>
#include <cstdlib>
#include <sstream>

namespace plate {
namespace {

const char* const kColumns[7] = {"t [s]", "x [m/s^2]", "y [m/s^2]", "z [m/s^2]", "rx [rad/s^2]", "ry [rad/s^2]", "rz [rad/s^2]"};

using detail::Reader;
using detail::split_csv;
using detail::trim;

struct Rows {
    std::vector<double> t;
    std::vector<Vec6> a;
    std::vector<int> line;   // the file's line of each row
};

Rows read_rows(const std::string& text, const std::string& source) {
    auto fail = [&](int line, int column, const std::string& what) {
        throw InputError(source + ":" + std::to_string(line) + (column > 0 ? ":" + std::to_string(column) : "") + ": " + what);
    };
    std::string header;
    for (std::size_t k = 0; k < 7; ++k) header += (k ? "," : "") + std::string(kColumns[k]);
    Rows rows;
    std::stringstream in(text);
    std::string raw;
    bool have_header = false;
    for (int line = 1; std::getline(in, raw); ++line) {
        const std::string l = trim(raw);
        if (l.empty() || l[0] == '#') continue;
        const auto cells = split_csv(l);
        if (!have_header) {
            for (std::size_t k = 0; k < 7; ++k)
                if (k >= cells.size() || cells[k] != kColumns[k])
                    fail(line, static_cast<int>(k) + 1,
                         "header: expected column " + std::to_string(k + 1) + " to be \"" + kColumns[k] + "\" (the header is \"" +
                             header + "\": acceleration in SI units, world frame)");
            if (cells.size() != 7) fail(line, 8, "header: expected 7 columns, got " + std::to_string(cells.size()));
            have_header = true;
            continue;
        }
        if (cells.size() != 7) fail(line, 0, "expected 7 columns (t, x, y, z, rx, ry, rz), got " + std::to_string(cells.size()));
        double v[7];
        for (int k = 0; k < 7; ++k) {
            if (!detail::finite_number(cells[k], v[k]))
                fail(line, k + 1, std::string(kColumns[k]) + ": expected a finite number, got \"" + cells[k] + "\"");
        }
        rows.t.push_back(v[0]);
        Vec6 a;
        for (int k = 0; k < 6; ++k) a[k] = v[k + 1];
        rows.a.push_back(a);
        rows.line.push_back(line);
    }
    if (!have_header) fail(1, 0, "empty: expected the header \"" + header + "\" and one row per sample");
    return rows;
}

}   // namespace

MeasuredCycle parse_measured_cycle(const std::string& text, const std::string& source, int max_n) {
    const Rows rows = read_rows(text, source);
    const int M = static_cast<int>(rows.t.size());
    auto fail = [&](int line, const std::string& what) {
        throw InputError(source + (line > 0 ? ":" + std::to_string(line) + ":1" : std::string()) + ": " + what);
    };
    if (max_n < 1 || max_n > 1000)
        fail(0, "harmonics: expected a whole number from 1 to 1000 (a scene's range), got " + std::to_string(max_n));
    if (M < 2 * max_n + 1)
        fail(0, std::to_string(M) + " samples resolve harmonics up to n = " + std::to_string((M - 1) / 2) +
                    " only (below the Nyquist frequency), " + std::to_string(max_n) + " asked for");
    // Uniform spacing: each t within 1e-6 dt of t0 + k dt (the rounding of a printed time stamp).
    const double t0 = rows.t.front(), dt = (rows.t.back() - t0) / (M - 1);
    if (!(dt > 0)) fail(rows.line[1], "t [s]: expected increasing times");
    for (int k = 0; k < M; ++k)
        if (std::abs(rows.t[k] - (t0 + k * dt)) > 1e-6 * dt)
            fail(rows.line[k], "t [s]: expected uniformly spaced samples, t0 + k dt with dt = " + Reader::fmt(dt) + " s; got " +
                                   Reader::fmt(rows.t[k]) + " s at sample " + std::to_string(k));

    MeasuredCycle out;
    out.samples = M;
    PlateMotion& plate = out.plate;
    plate.T = M * dt;
    Vec6 mean = Vec6::Zero(), peak = Vec6::Zero();
    for (const auto& a : rows.a) {
        mean += a / M;
        peak = peak.cwiseMax(a.cwiseAbs());
    }
    out.mean = mean;
    Vec6 ms = Vec6::Zero();
    for (const auto& a : rows.a) ms += (a - mean).cwiseAbs2() / M;
    out.rms = ms.cwiseSqrt();
    // a(t) = sum_n amp_n sin(n w t + phase_n) = sum_n S_n sin(n w t) + C_n cos(n w t) with
    // S_n = amp cos(phase), C_n = amp sin(phase); on M uniform samples of one period the sums
    // (2/M) sum_k a_k sin(n w t_k) and (2/M) sum_k a_k cos(n w t_k) give S_n and C_n exactly for
    // n < M/2 (the DFT's orthogonality). The mean drops out of them for n >= 1.
    Vec6 kept_power = Vec6::Zero();
    const double w = plate.omega();
    for (int a = 0; a < 6; ++a)
        for (int n = 1; n <= max_n; ++n) {
            double S = 0, C = 0;
            for (int k = 0; k < M; ++k) {
                const double x = rows.a[k][a] - mean[a], ph = n * w * (t0 + k * dt);
                S += x * std::sin(ph);
                C += x * std::cos(ph);
            }
            S *= 2.0 / M;
            C *= 2.0 / M;
            const double amp = std::hypot(S, C);
            if (amp <= kMeasuredDropRelative * peak[a]) continue;
            plate.harmonics.push_back(Harmonic{static_cast<Axis>(a), n, amp, std::atan2(C, S)});
            kept_power[a] += amp * amp / 2;
        }
    for (int a = 0; a < 6; ++a) {
        out.residual_rms[a] = std::sqrt(std::max(0.0, ms[a] - kept_power[a]));
        const std::string axis = axis_name(static_cast<Axis>(a));
        if (std::abs(mean[a]) > kMeasuredMeanWarn * out.rms[a])
            out.warnings.push_back(source + ": " + axis + ": the mean " + Reader::fmt(mean[a]) + " is " +
                                   (out.rms[a] > 0
                                        ? Reader::fmt(std::abs(mean[a]) / out.rms[a]) + " of the RMS " + Reader::fmt(out.rms[a])
                                        : std::string("nonzero on a constant signal")) +
                                   " and was removed: a periodic plate's acceleration has zero mean (an "
                                   "accelerometer offset, gravity left in z, a record that is not one period?)");
        if (out.residual_rms[a] > kMeasuredMeanWarn * out.rms[a] && out.residual_rms[a] > kMeasuredDropRelative * peak[a])
            out.warnings.push_back(source + ": " + axis + ": harmonics 1 to " + std::to_string(max_n) + " leave an RMS of " +
                                   Reader::fmt(out.residual_rms[a]) + " of " + Reader::fmt(out.rms[a]) + " out");
    }
    return out;
}

MeasuredCycle read_measured_cycle(const std::string& path, int max_n) {
    return parse_measured_cycle(detail::read_input_file(path, "measured cycle"), path, max_n);
}

Scene with_measured_plate(const Scene& scene, const MeasuredCycle& cycle) {
    Scene s = scene;
    s.plate = cycle.plate;
    validate_scene(s);
    return s;
}

}   // namespace plate
