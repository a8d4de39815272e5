// The truth the loop runs against (TRUTH.json, true_scene) and the part's state carried over a period
// boundary (carry_state).
#include "plate/control.hpp"

#include "plate/measured_cycle.hpp"
#include "plate/scene_io.hpp"

#include "input_reader.hpp"
#include "so3.hpp"

#include <cmath>
#include <filesystem>
#include <stdexcept>

namespace plate {

using detail::Reader;
using nlohmann::json;

namespace {

bool same_motion(const PlateMotion& a, const PlateMotion& b) {
    if (a.T != b.T || a.harmonics.size() != b.harmonics.size()) return false;
    for (std::size_t i = 0; i < a.harmonics.size(); ++i) {
        const Harmonic &x = a.harmonics[i], &y = b.harmonics[i];
        if (x.axis != y.axis || x.n != y.n || x.amp != y.amp || x.phase != y.phase) return false;
    }
    return true;
}

}   // namespace

void Truth::validate() const {
    const Reader r{source};
    if (!(friction_scale > 0 && friction_scale <= kMaxFrictionScale))
        r.fail("friction_scale",
               "expected a number in (0, " + Reader::fmt(kMaxFrictionScale) + "], got " + Reader::fmt(friction_scale));
    if (uncertainty) validate_uncertainty(*uncertainty);
}

Truth parse_truth(const std::string& text, const std::string& source, const std::string& dir) {
    const Reader r{source};
    const json doc = r.parse(text);
    r.only_keys(doc, "", {"friction_scale", "uncertainty", "tracking", "draw", "measured"}, {});
    Truth t;
    t.source = source;
    if (doc.contains("friction_scale")) t.friction_scale = r.number(doc["friction_scale"], "friction_scale");
    if (doc.contains("uncertainty")) {
        if (!doc["uncertainty"].is_object()) r.fail("uncertainty", "expected an uncertainty spec (an object)");
        t.uncertainty = parse_uncertainty(doc["uncertainty"].dump(), source + ": uncertainty");
    }
    if (doc.contains("tracking")) {
        const json& k = doc["tracking"];
        if (k == "per_period")
            t.tracking = Tracking::per_period;
        else if (k == "per_run")
            t.tracking = Tracking::per_run;
        else
            r.fail("tracking", "expected \"per_period\" or \"per_run\"");
    }
    if (doc.contains("draw")) t.draw = r.seed(doc["draw"], "draw");
    if (doc.contains("measured")) {
        const json& M = doc["measured"];
        if (!M.is_array()) r.fail("measured", "expected an array of {commanded, cycle, harmonics}");
        for (std::size_t k = 0; k < M.size(); ++k) {
            const std::string f = "measured[" + std::to_string(k) + "]";
            r.only_keys(M[k], f, {"commanded", "cycle", "harmonics"}, {"commanded", "cycle", "harmonics"});
            for (const char* key : {"commanded", "cycle"})
                if (!M[k][key].is_string() || M[k][key].get<std::string>().empty())
                    r.fail(f + "." + key, "expected a file's path");
            const json& h = M[k]["harmonics"];
            if (!h.is_number_integer() || h.get<long long>() < 1 || h.get<long long>() > 1000)
                r.fail(f + ".harmonics", "expected a whole number from 1 to 1000");
            MeasuredMotion m;
            m.commanded_source = (std::filesystem::path(dir) / M[k]["commanded"].get<std::string>()).string();
            m.cycle_source = (std::filesystem::path(dir) / M[k]["cycle"].get<std::string>()).string();
            try {
                m.commanded = load_scene(m.commanded_source).plate;
            } catch (const InputError& e) {
                r.fail(f + ".commanded", e.what());
            }
            try {
                m.measured = read_measured_cycle(m.cycle_source, static_cast<int>(h.get<long long>())).plate;
            } catch (const InputError& e) {
                r.fail(f + ".cycle", e.what());
            }
            if (!(std::abs(m.measured.T - m.commanded.T) <= 1e-9 * m.commanded.T))
                r.fail(f + ".cycle", m.cycle_source + ": period " + Reader::fmt(m.measured.T) + " s, not the commanded " +
                                         Reader::fmt(m.commanded.T) + " s");
            m.measured.T = m.commanded.T;
            for (const MeasuredMotion& o : t.measured)
                if (same_motion(o.commanded, m.commanded))
                    r.fail(f + ".commanded", m.commanded_source + ": the same motion as " + o.commanded_source);
            t.measured.push_back(std::move(m));
        }
    }
    t.validate();
    return t;
}

Truth load_truth(const std::string& path) {
    return parse_truth(detail::read_input_file(path, "truth file"), path, std::filesystem::path(path).parent_path().string());
}

namespace {

// The spec's draw index of (run draw, slot, period): a splitmix64 mix, so that the run's part, each
// motion's tracking errors and each period's are independent streams of the spec's seed.
std::uint64_t draw_index(std::uint64_t run, std::uint64_t slot, std::uint64_t period) {
    std::uint64_t z = run * 0x9E3779B97F4A7C15ull ^ (slot + 1) * 0xBF58476D1CE4E5B9ull ^ (period + 1) * 0x94D049BB133111EBull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

}   // namespace

Scene true_scene(const Truth& truth, const Scene& commanded_scene, int motion, long period) {
    Scene commanded = commanded_scene;
    for (const MeasuredMotion& m : truth.measured)
        if (same_motion(m.commanded, commanded.plate)) {
            commanded.plate = m.measured;
            break;
        }
    Scene s = commanded;
    if (truth.uncertainty) {
        const UncertaintySpec& spec = *truth.uncertainty;
        // The part and the period: one draw per run, of the scene on a still plate (the same for every motion).
        Scene still = commanded;
        still.plate.harmonics.clear();
        const Scene run = draw(still, spec, draw_index(truth.draw, 0, 0));
        // The plate's tracking errors: this period's draw (per_period, and motions of a policy's own), or
        // the motion's draw for the whole run.
        const bool per_period = truth.tracking == Tracking::per_period || motion < 0;
        const std::uint64_t slot = motion < 0 ? 1 : static_cast<std::uint64_t>(motion) + 2;
        const Scene plate = draw(commanded, spec, draw_index(truth.draw, slot, per_period ? period + 1 : 0));
        s.part = run.part;
        s.plate.harmonics = plate.plate.harmonics;
        s.plate.T = run.plate.T;
    }
    s.part.mu *= truth.friction_scale;
    if (s.part.mu_static) *s.part.mu_static *= truth.friction_scale;
    s.name = commanded_scene.name + "~truth";
    return s;
}


namespace {

// The heading about the world's z of R1 R_z(theta), taken within pi of theta.
double heading(const Mat3& R1, double theta) {
    const Mat3 R = R1 * rot_z(theta);
    return theta + wrap_angle(std::atan2(R(1, 0), R(0, 0)) - theta);
}

// The plate at phase 0: its position, velocity, angular velocity and orientation (the rotation by its
// zero-mean rotation vector, as the full dynamics start it).
struct PlateAtZero {
    Vec3 p, v, w;
    Mat3 R;
    explicit PlateAtZero(const PlateMotion& u) {
        Vec3 phi;
        u.displacement(0, p, phi);
        u.velocity(0, v, w);
        R = detail::exp_so3(phi);
    }
};

}   // namespace

void carry_state(const Part& part, const PlateMotion& from, const PlateMotion& to, Vec3& q, Vec3& qd) {
    if (same_motion(from, to)) return;
    const PlateAtZero a(from), b(to);
    const double sz = part.s_z();
    // The part's world position and velocity on the old plate.
    const Vec3 s_a(q.x(), q.y(), sz);
    const Vec3 r = a.p + a.R * s_a;
    const Vec3 v = a.v + a.w.cross(a.R * s_a) + a.R * Vec3(qd.x(), qd.y(), 0);
    const double yaw_rate = a.w.z() + a.R(2, 2) * qd.z();
    // The same on the new plate: in-plane components kept, the normal ones the plate's.
    const Vec3 s_rel = b.R.transpose() * (r - b.p);
    const Vec3 s_b(s_rel.x(), s_rel.y(), sz);
    const Vec3 v_rel = b.R.transpose() * (v - b.v - b.w.cross(b.R * s_b));
    double theta = q.z();
    if (!part.point) {
        const double h = heading(a.R, q.z());
        for (int i = 0; i < 3; ++i) theta += h - heading(b.R, theta);   // heading(b.R, .) has slope ~1
    }
    q = Vec3(s_b.x(), s_b.y(), part.point ? 0.0 : theta);
    qd = Vec3(v_rel.x(), v_rel.y(), part.point ? 0.0 : (yaw_rate - b.w.z()) / b.R(2, 2));
}

}   // namespace plate
