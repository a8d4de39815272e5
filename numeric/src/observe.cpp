// Cameras, their frames and what they record of a simulation (observe.hpp); the track file's
// reader and writer: track_io.cpp.
#include "plate/observe.hpp"

#include "plate/field.hpp"
#include "plate/output.hpp"
#include "plate/random_scene.hpp"
#include "plate/scene_io.hpp"

#include "input_reader.hpp"

#include <Eigen/Geometry>

#include <cmath>
#include <stdexcept>

namespace plate {

using detail::Reader;
using nlohmann::json;

const char* frame_name(CameraFrame f) { return f == CameraFrame::world ? "world" : "plate"; }

void Camera::validate() const {
    Reader r{source.empty() ? std::string("(camera)") : source};
    auto range = [&](double x, double lo, double hi, bool hi_open, const char* field, const std::string& what) {
        if (!(std::isfinite(x) && x >= lo && (hi_open ? x < hi : x <= hi))) r.fail(field, what + ", got " + Reader::fmt(x));
    };
    if ((rate > 0) == (per_period > 0))
        r.fail("rate_hz", "expected exactly one schedule: rate_hz (frames per second) or stroboscopic (frames per period)");
    if (rate > 0) {
        range(rate, 0, kMaxFrameRate, false, "rate_hz", "expected a frame rate from 0 to " + Reader::fmt(kMaxFrameRate) + " /s");
    } else {
        if (per_period > kMaxFramesPerPeriod)
            r.fail("stroboscopic.per_period", "expected a whole number from 1 to " + std::to_string(kMaxFramesPerPeriod) +
                                                  ", got " + std::to_string(per_period));
        range(phase, 0, 1, true, "stroboscopic.phase", "expected a fraction of the plate period in [0, 1)");
    }
    range(noise_xy_mm, 0, kMaxNoise * 1e3, false, "noise.xy_mm", "expected a standard deviation from 0 to 1000 mm");
    range(noise_theta_mrad, 0, kMaxNoise * 1e3, false, "noise.theta_mrad", "expected a standard deviation from 0 to 1000 mrad");
    range(latency, 0, kMaxLatency, false, "latency_s", "expected a latency from 0 to " + Reader::fmt(kMaxLatency) + " s");
    range(drop, 0, 1, true, "drop", "expected a probability in [0, 1)");
}

Camera parse_camera(const std::string& text, const std::string& source) {
    Reader r{source};
    const json doc = r.parse(text);
    r.only_keys(doc, "", {"rate_hz", "stroboscopic", "noise", "latency_s", "drop", "seed", "frame"}, {"frame"});
    Camera c;
    c.source = source;
    if (doc.contains("rate_hz") == doc.contains("stroboscopic"))
        r.fail("rate_hz", "expected exactly one of rate_hz (frames per second) and stroboscopic ({\"phase\": F})");
    if (doc.contains("rate_hz")) c.rate = r.positive(doc["rate_hz"], "rate_hz");
    if (doc.contains("stroboscopic")) {
        const json& s = doc["stroboscopic"];
        r.only_keys(s, "stroboscopic", {"phase", "per_period"}, {"phase"});
        c.phase = r.number(s["phase"], "stroboscopic.phase");
        c.per_period = 1;
        if (s.contains("per_period")) {
            const json& m = s["per_period"];
            if (!m.is_number_integer() || m.get<long>() < 1 || m.get<long>() > kMaxFramesPerPeriod)
                r.fail("stroboscopic.per_period",
                       "expected a whole number from 1 to " + std::to_string(kMaxFramesPerPeriod) + " (frames per period)");
            c.per_period = m.get<int>();
        }
    }
    if (doc.contains("noise")) {
        const json& n = doc["noise"];
        r.only_keys(n, "noise", {"xy_mm", "theta_mrad"}, {});
        if (n.contains("xy_mm")) c.noise_xy_mm = r.number(n["xy_mm"], "noise.xy_mm");
        if (n.contains("theta_mrad")) c.noise_theta_mrad = r.number(n["theta_mrad"], "noise.theta_mrad");
    }
    if (doc.contains("latency_s")) c.latency = r.number(doc["latency_s"], "latency_s");
    if (doc.contains("drop")) c.drop = r.number(doc["drop"], "drop");
    if (doc.contains("seed")) c.seed = r.seed(doc["seed"], "seed");
    const json& f = doc["frame"];
    if (f == "plate")
        c.frame = CameraFrame::plate;
    else if (f == "world")
        c.frame = CameraFrame::world;
    else
        r.fail("frame", "expected \"plate\" (coordinates on the plate) or \"world\" (the plate's own motion included)");
    c.validate();
    return c;
}

Camera load_camera(const std::string& path) { return parse_camera(detail::read_input_file(path, "camera file"), path); }

json camera_to_json(const Camera& c) {
    json j;
    if (c.stroboscopic())
        j["stroboscopic"] = {{"phase", c.phase}, {"per_period", c.per_period}};
    else
        j["rate_hz"] = c.rate;
    j["noise"] = {{"xy_mm", c.noise_xy_mm}, {"theta_mrad", c.noise_theta_mrad}};
    j["latency_s"] = c.latency;
    j["drop"] = c.drop;
    j["seed"] = c.seed;
    j["frame"] = frame_name(c.frame);
    return j;
}

std::string scene_id(const Scene& scene) {
    const nlohmann::json all = scene_to_json(scene);
    const nlohmann::json setup = {{"gravity", all["gravity"]}, {"plate", all["plate"]}, {"point_part", scene.part.point}};
    return fnv1a_hex(setup.dump());
}

std::vector<double> frame_stamps(const Camera& c, double T, double duration) {
    c.validate();
    if (!(duration > 0 && std::isfinite(duration))) throw std::invalid_argument("frame_stamps: duration must be > 0");
    if (c.stroboscopic() && !(T > 0)) throw std::invalid_argument("frame_stamps: the plate period must be > 0");
    // Stamp k: k / rate, or (k / per_period + phase) T ((k + phase) T for one frame per period).
    auto stamp = [&](long k) {
        return c.stroboscopic() ? (static_cast<double>(k) / c.per_period + c.phase) * T : static_cast<double>(k) / c.rate;
    };
    const double per_second = c.stroboscopic() ? c.per_period / T : c.rate;
    if (duration * per_second > 1e9) throw std::invalid_argument("frame_stamps: more than 10^9 frames");
    std::vector<double> out;
    // (from a frame or two before the first whose state time is >= 0: stamp k is k / per_second + offset)
    const double offset = c.stroboscopic() ? c.phase * T : 0;
    for (long k = std::max(0L, static_cast<long>((c.latency - offset) * per_second) - 2);; ++k) {
        const double t = stamp(k);
        if (t - c.latency > duration) break;
        if (t - c.latency >= 0) out.push_back(t);
    }
    return out;
}

Vec3 world_pose(const Scene& scene, double t, const Vec3& q, const Mat3& R1) {
    Vec3 p, phi;
    scene.plate.displacement(t, p, phi);
    const Vec3 r = p + R1 * Vec3(q.x(), q.y(), scene.part.s_z());
    if (scene.part.point) return Vec3(r.x(), r.y(), 0);
    const Mat3 Rp = R1 * Eigen::AngleAxisd(q.z(), Vec3::UnitZ()).toRotationMatrix();
    return Vec3(r.x(), r.y(), q.z() + wrap_angle(std::atan2(Rp(1, 0), Rp(0, 0)) - q.z()));
}

namespace {

// q' = (1/2) (0, omega1) q: R1' = omega1^ R1 with omega1 in the world frame.
Eigen::Quaterniond rate(const PlateMotion& u, double t, const Eigen::Quaterniond& q) {
    Vec3 pd, w;
    u.velocity(t, pd, w);
    const Eigen::Quaterniond d = Eigen::Quaterniond(0, w.x(), w.y(), w.z()) * q;
    return Eigen::Quaterniond(0.5 * d.coeffs());
}

Eigen::Quaterniond rk4_step(const PlateMotion& u, double t, const Eigen::Quaterniond& q, double h) {
    auto add = [](const Eigen::Quaterniond& a, double s, const Eigen::Quaterniond& b) {
        return Eigen::Quaterniond(a.coeffs() + s * b.coeffs());
    };
    const Eigen::Quaterniond k1 = rate(u, t, q), k2 = rate(u, t + h / 2, add(q, h / 2, k1)),
                             k3 = rate(u, t + h / 2, add(q, h / 2, k2)), k4 = rate(u, t + h, add(q, h, k3));
    Eigen::Quaterniond out(q.coeffs() + h / 6 * (k1.coeffs() + 2 * k2.coeffs() + 2 * k3.coeffs() + k4.coeffs()));
    out.normalize();
    return out;
}

}   // namespace

PlateOrientation::PlateOrientation(const PlateMotion& plate) : plate_(plate) {
    Vec3 p, phi;
    plate.displacement(0, p, phi);
    q_ = phi.norm() > 0 ? Eigen::Quaterniond(Eigen::AngleAxisd(phi.norm(), phi.normalized())) : Eigen::Quaterniond::Identity();
}

Mat3 PlateOrientation::at(double t) {
    if (t < t_) throw std::invalid_argument("PlateOrientation::at: times must be asked in increasing order");
    // Whole steps on the grid n h (so that R1(t) does not depend on the times asked before), then a
    // partial step to t that is not kept.
    const double h = plate_.T / kOrientationStepsPerPeriod;
    for (;;) {
        const double next = (std::round(t_ / h) + 1) * h;
        if (next > t) break;
        q_ = rk4_step(plate_, t_, q_, next - t_);
        t_ = next;
    }
    return (t > t_ ? rk4_step(plate_, t_, q_, t - t_) : q_).toRotationMatrix();
}

Track film(const Scene& scene, const Camera& camera, const std::vector<double>& stamps, const Trajectory& exact) {
    camera.validate();
    Track tr;
    tr.scene_name = scene.name;
    tr.scene_id = scene_id(scene);
    tr.camera = camera;
    tr.point = scene.part.point;
    Rng rng(camera.seed);
    PlateOrientation R1(scene.plate);
    const double sd_xy = camera.noise_xy_mm * 1e-3, sd_theta = camera.noise_theta_mrad * 1e-3;
    for (std::size_t k = 0; k < stamps.size() && k < exact.samples.size(); ++k) {
        const Sample& s = exact.samples[k];
        if (s.t != stamps[k] - camera.latency) break;   // (the sample at a stop, which is no frame)
        // Every frame draws its drop and its noise, kept or not.
        const bool dropped = rng.uniform() < camera.drop;
        const Vec3 e(standard_normal(rng) * sd_xy, standard_normal(rng) * sd_xy, standard_normal(rng) * sd_theta);
        if (dropped) continue;
        Vec3 q = camera.frame == CameraFrame::world ? world_pose(scene, s.t, s.q, R1.at(s.t)) : s.q;
        q += e;
        if (scene.part.point) q.z() = 0;
        tr.t.push_back(stamps[k]);
        tr.q.push_back(q);
    }
    return tr;
}

Track observe(const Scene& scene, const Camera& camera, Dynamics level, const Vec3& q0, const Vec3& qd0, double duration,
              const IntegrationOptions& opt, Trajectory* exact) {
    const std::vector<double> stamps = frame_stamps(camera, scene.plate.T, duration);
    if (stamps.empty()) throw std::invalid_argument("observe: no frame of the camera falls within the duration");
    return observe_at(scene, camera, level, q0, qd0, stamps, opt, exact);
}

Track observe_at(const Scene& scene, const Camera& camera, Dynamics level, const Vec3& q0, const Vec3& qd0,
                 const std::vector<double>& stamps, const IntegrationOptions& opt, Trajectory* exact) {
    camera.validate();
    std::vector<double> times;
    for (double t : stamps) times.push_back(t - camera.latency);
    Trajectory tr = simulate_at(scene, level, q0, qd0, times, opt);
    Track out = film(scene, camera, stamps, tr);
    if (exact) *exact = std::move(tr);
    return out;
}

}   // namespace plate
