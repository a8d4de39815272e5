// A track's prediction and its scaled residuals.
#include "internal.hpp"

#include "plate/tasks.hpp"

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

std::vector<Eigen::VectorXd> stacked_residuals(const std::vector<TrackCost*>& costs,
                                               const std::vector<std::vector<double>>& points,
                                               const std::vector<std::vector<std::vector<double>>>& starts, int threads,
                                               long& simulations) {
    const int nt = static_cast<int>(costs.size()), np = static_cast<int>(points.size());
    std::vector<int> offset(static_cast<std::size_t>(nt) + 1, 0);
    for (int t = 0; t < nt; ++t) offset[t + 1] = offset[t] + costs[t]->num_residuals();
    std::vector<Eigen::VectorXd> out(static_cast<std::size_t>(np), Eigen::VectorXd(offset[nt]));
    std::vector<char> ok(static_cast<std::size_t>(np) * static_cast<std::size_t>(nt), 0);
    thread_tasks(std::max(1, std::min(threads, np * nt)))(
        np * nt,
        [&](int i) {
            const std::size_t p = static_cast<std::size_t>(i / nt), t = static_cast<std::size_t>(i % nt);
            const std::vector<double>& q0 = starts.size() == 1 ? starts[0][t] : starts[p][t];
            ok[static_cast<std::size_t>(i)] = costs[t]->residuals(points[p].data(), q0.data(), out[p].data() + offset[t]);
            return std::string();
        },
        [](int, const std::string&) {});
    simulations += static_cast<long>(np) * nt;
    for (int p = 0; p < np; ++p)
        for (int t = 0; t < nt; ++t)
            if (!ok[static_cast<std::size_t>(p) * nt + t]) out[static_cast<std::size_t>(p)].resize(0);
    return out;
}

}   // namespace plate::identify_detail
