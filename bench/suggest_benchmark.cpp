// Benchmark: how much what the suggested motion tells depends on where the tracks start (issue 52,
// point 4). Not a test. For each candidate motion of suggest's families (and the extra shapes below),
// the information of TRACKS planned tracks of DURATION s is weighed (weigh_motion) over SETS seeded
// start sets, x, y in +-BOX, theta any; printed per candidate: the predicted sd of every parameter
// for each set, and the worst and median over the sets of the largest static sd.
//   bench_suggest [SETS [BOX [THREADS [TRACKS [DURATION [SCENE [PARAMS]]]]]]]
#include "plate/peaks.hpp"
#include "plate/scene_io.hpp"
#include "plate/suggest.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

using namespace plate;

namespace {

// x with its second harmonic at a third, scaled to horizontal peak A, plus an optional y second harmonic
// and a yaw of `yaw` A / reach at phase `yaw_phase` and harmonic `yaw_n`.
MotionCandidate shape(const Scene& s, const std::string& label, double A, bool y2, double yaw, double yaw_phase, int yaw_n,
                      double reach) {
    MotionCandidate c;
    c.label = label;
    c.motion.T = s.plate.T;
    c.motion.harmonics.push_back(Harmonic{Axis::x, 1, 1, 0});
    c.motion.harmonics.push_back(Harmonic{Axis::x, 2, 1.0 / 3, 0});
    if (y2) c.motion.harmonics.push_back(Harmonic{Axis::y, 2, 1.0 / 3, kPi / 2});
    const double scale = A / horizontal_peak(c.motion);
    for (Harmonic& h : c.motion.harmonics) h.amp *= scale;
    if (yaw > 0) c.motion.harmonics.push_back(Harmonic{Axis::rz, yaw_n, yaw * A / reach, yaw_phase});
    return c;
}

}   // namespace

int main(int argc, char** argv) {
    const int sets = argc > 1 ? std::stoi(argv[1]) : 4;
    const double box = argc > 2 ? std::stod(argv[2]) : 0.05;
    const int threads = argc > 3 ? std::stoi(argv[3]) : 2;
    const int tracks = argc > 4 ? std::stoi(argv[4]) : 5;
    const double duration = argc > 5 ? std::stod(argv[5]) : 10;
    const std::string file = argc > 6 ? argv[6] : PLATE_SOURCE_DIR "/scenes/fig4.json";
    const std::string plist = argc > 7 ? argv[7] : "mu_k1,mu_k2,mu_k3,mu_s1,mu_s2,mu_s3";
    Scene nominal = load_scene(file);
    nominal.part.mu_static = Vec3(1.2 * nominal.part.mu);
    SuggestOptions o;
    std::stringstream in(plist);
    for (std::string w; std::getline(in, w, ',');) o.fit.params.push_back(w);
    o.fit.threads = threads;
    o.tracks = tracks;
    o.duration = duration;
    o.start_box = box;
    o.start_sets = 1;   // one set per weighing: the columns below are the sets one by one
    Camera cam;
    cam.per_period = 1;
    cam.phase = 0.25;
    cam.noise_xy_mm = 0.1;
    cam.noise_theta_mrad = 5;
    double reach = 0;
    for (const Vec3& c : nominal.part.c) reach = std::max(reach, std::hypot(c.x(), c.y()));
    const double a_s = nominal.part.mu_static->mean() * nominal.g;
    std::vector<MotionCandidate> cands;
    for (double level : {1.1, 1.25, 1.4})
        for (double yaw : {0.25, 0.5, 1.0})
            for (double ph : {0.0, kPi / 2}) {
                char label[96];
                std::snprintf(label, sizeof label, "x+2x+rz(%.2f, %.2f) @ %.2f", yaw, ph, level);
                cands.push_back(shape(nominal, label, level * a_s, false, yaw, ph, 1, reach));
            }
    for (double level : {1.1, 1.4}) {
        char label[96];
        std::snprintf(label, sizeof label, "x+2x+2y+rz(0.50, 1.57) @ %.2f", level);
        cands.push_back(shape(nominal, label, level * a_s, true, 0.5, kPi / 2, 1, reach));
        std::snprintf(label, sizeof label, "x+2x+2rz(0.50, 1.57) @ %.2f", level);
        cands.push_back(shape(nominal, label, level * a_s, false, 0.5, kPi / 2, 2, reach));
    }
    std::printf("%d start sets of %d tracks of %.0f s, starts in +-%.3f m, %d threads\n", sets, tracks, duration, box, threads);
    for (MotionCandidate& c0 : cands) {
        std::vector<double> worst;
        double secs = 0;
        std::printf("%-32s", c0.label.c_str());
        for (int k = 0; k < sets; ++k) {
            MotionCandidate c = c0;
            o.seed = 1 + k;
            weigh_motion(nominal, cam, o, c);
            secs += c.seconds;
            if (!c.within_limits || !c.simulated) {
                std::printf(" [%s]", c.within_limits ? "not simulated" : "over limits");
                worst.push_back(INFINITY);
                break;
            }
            double w = 0;
            for (const FittedParameter& p : c.predicted)
                if (p.name.rfind("mu_s", 0) == 0) w = std::isfinite(p.sd) ? std::max(w, p.sd) : INFINITY;
            worst.push_back(w);
            std::printf(" %.4f(stick %.2f)", w, c.stick_fraction);
        }
        std::vector<double> sorted = worst;
        std::sort(sorted.begin(), sorted.end());
        std::printf("  | worst %.4f median %.4f  %.1f s\n", sorted.back(), sorted[sorted.size() / 2], secs);
        std::fflush(stdout);
    }
}
