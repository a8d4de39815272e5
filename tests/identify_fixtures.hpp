// What the identification tests share: the shipped scenes, a stroboscopic camera and a track filmed
// at parameters the nominal scene does not declare.
#pragma once

#include "plate/identify.hpp"
#include "plate/observe.hpp"
#include "plate/scene_io.hpp"
#include "shipped_scenes.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace plate::test {

using plate_tests::scene;

// One frame a period at phase 0.25, the noise given.
inline Camera strobe(double xy_mm, double theta_mrad, std::uint64_t seed) {
    Camera c;
    c.per_period = 1;
    c.phase = 0.25;
    c.noise_xy_mm = xy_mm;
    c.noise_theta_mrad = theta_mrad;
    c.seed = seed;
    return c;
}

// What a camera films of the part with the named parameters at `truth`, started at rest at q0: the
// track's scene_id is the set-up's (plate motion, gravity), so it matches the nominal scene's.
inline Track filmed(const Scene& nominal, const std::vector<std::string>& names, const std::vector<double>& truth,
                    const Camera& cam, const Vec3& q0, double duration, Trajectory* exact = nullptr) {
    const Scene truth_scene = apply_parameters(nominal, names, truth);
    Track tr = observe(truth_scene, cam, Dynamics::Full, q0, Vec3::Zero(), duration, {}, exact);
    tr.source = "track.csv";
    return tr;
}

// The tests' fit: two starts, one thread.
inline IdentifyOptions options(const std::vector<std::string>& params) {
    IdentifyOptions o;
    o.params = params;
    o.starts = 2;
    o.threads = 1;
    return o;
}

}   // namespace plate::test
