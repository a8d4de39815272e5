// A track's prediction and its scaled residuals.
#include "internal.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace plate::identify_detail {

bool predict(const Scene& scene, const Track& track, Dynamics level, const Vec3& q0, const IntegrationOptions& opt,
             std::vector<Vec3>& q) {
    Camera clean = track.camera;   // the camera without its noise and drops: what it would see
    clean.noise_xy_mm = clean.noise_theta_mrad = clean.drop = 0;
    std::vector<double> times;
    times.reserve(track.t.size());
    for (double t : track.t) times.push_back(t - clean.latency);
    const Trajectory exact = simulate_at(scene, level, q0, Vec3::Zero(), times, opt);
    const Track seen = film(scene, clean, track.t, exact);
    if (seen.t.size() != track.t.size()) return false;
    q = seen.q;
    return true;
}

int first_used_frame(const Track& track, double T, double settle_periods) {
    int k = 0;
    while (k < static_cast<int>(track.t.size()) && track.t[k] - track.camera.latency < settle_periods * T) ++k;
    return k;
}

std::vector<Track> segments(const std::vector<Track>& tracks, double T, double seconds, std::vector<double>& shifts) {
    shifts.clear();
    const long P = std::max(1L, std::lround(seconds / T));   // whole periods a piece
    const double span = static_cast<double>(P) * T;
    std::vector<Track> out;
    for (const Track& tr : tracks) {
        if (tr.t.empty()) continue;
        // K pieces of P periods, the last one taking the remainder too (it is never shorter than P periods).
        const long K = std::max(1L, static_cast<long>(std::floor((tr.t.back() - tr.camera.latency) / span)));
        std::size_t i = 0;
        for (long k = 0; k < K; ++k) {
            Track piece = tr;
            piece.t.clear();
            piece.q.clear();
            piece.lines.clear();
            // A frame stays in this piece while its state time re-timed for the next one, computed as the
            // prediction will compute it there ((stamp - shift) - latency), is below 0: on a boundary it
            // starts the next piece, never at a state time rounded below 0.
            const double shift = static_cast<double>(k) * span, next = static_cast<double>(k + 1) * span;
            for (; i < tr.t.size() && (k == K - 1 || (tr.t[i] - next) - tr.camera.latency < 0); ++i) {
                piece.t.push_back(tr.t[i] - shift);
                piece.q.push_back(tr.q[i]);
                if (i < tr.lines.size()) piece.lines.push_back(tr.lines[i]);
            }
            if (piece.t.empty()) continue;
            if (k > 0) {
                char from[48];
                std::snprintf(from, sizeof from, " (from %g s)", shift);
                piece.source += from;
            }
            out.push_back(std::move(piece));
            shifts.push_back(shift);
        }
    }
    return out;
}

}   // namespace plate::identify_detail
