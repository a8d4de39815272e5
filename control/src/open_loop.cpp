// Open loop for comparison (control.hpp): one motion kept all run, the same loop and truth as the
// closed-loop policies; and the issue's test plate, starts and camera (spread_truth, square_start, issue_camera).
#include "plate/control.hpp"
#include "plate/random_scene.hpp"
#include "plate/scene_io.hpp"

namespace plate {

Truth spread_truth(double friction_scale, double spread, std::uint64_t draw) {
    Truth truth;
    truth.friction_scale = friction_scale;
    UncertaintySpec spec;
    spec.seed = 53;
    spec.amplitude.spread = spread;
    spec.phase.spread = spread;
    truth.uncertainty = spec;
    truth.draw = draw;
    return truth;
}

Vec3 square_start(std::uint64_t i, bool with_theta) {
    Rng rng(1000 + i);
    const double y = rng.uniform(-0.05, 0.05);   // (y first: the order bench_control's starts were measured in)
    const double x = rng.uniform(-0.05, 0.05);
    return Vec3(x, y, with_theta ? rng.uniform(-kPi, kPi) : 0.0);
}

Camera issue_camera(double T, std::uint64_t seed, bool rigid) {
    Camera cam;
    cam.per_period = 1;
    cam.noise_xy_mm = 0.1;
    cam.noise_theta_mrad = rigid ? 5 : 0;
    cam.latency = T;
    cam.seed = seed;
    cam.frame = CameraFrame::world;
    return cam;
}

ControlModel open_loop_model(const Scene& nominal, const std::string& path) {
    ControlModel m;
    m.nominal = nominal;
    m.library.source = path;
    m.library.names = {"open_loop"};
    m.library.motions = {load_scene(path).plate};
    MotionField f;
    f.uniform = true;
    f.twist = {Vec3::Zero()};
    m.fields = {f};
    return m;
}

namespace {

class Always : public Policy {
public:
    std::string name() const override { return "open_loop"; }
    void reset(const ControlModel&, const Goal&) override {}
    Decision decide(const Observation&, long) override { return {0, std::nullopt}; }
};

}   // namespace

std::unique_ptr<Policy> make_open_loop_policy() { return std::make_unique<Always>(); }

}   // namespace plate
