// A track's prediction and its scaled residuals.
#include "internal.hpp"

#include <cmath>

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

}   // namespace plate::identify_detail
