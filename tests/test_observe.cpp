// Camera observations (observe.hpp): a part riding the plate seen in the world frame against the plate
// motion's closed form, the stroboscopic schedule, latency, the noise's and the drops' statistics, and
// the track file: written and read back to the bit, each bad input named by file and line.
#include "plate/observe.hpp"
#include "plate/scene_io.hpp"

#include "cli_run.hpp"
#include "shipped_scenes.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <sstream>

using namespace plate;

namespace {

using plate_tests::scene;

Camera camera(double rate, CameraFrame frame) {
    Camera c;
    c.rate = rate;
    c.frame = frame;
    return c;
}

// The zero-mean double integral of a sin(n w t + phase): -a / (n w)^2 sin(n w t + phase), summed over
// the harmonics of one axis -- the plate's displacement (or small rotation about that axis) in closed form.
double closed_form(const PlateMotion& u, Axis axis, double t) {
    double x = 0;
    for (const Harmonic& h : u.harmonics)
        if (h.axis == axis) {
            const double k = h.n * 2 * kPi / u.T;
            x -= h.amp / (k * k) * std::sin(k * t + h.phase);
        }
    return x;
}

// A part at rest at q0 on `plate` under full dynamics, filmed in the world frame at 400 frames/s with
// `latency`; REQUIREs that it stayed stuck (its plate-frame q unchanged at every frame).
Track stuck_track(Scene& sc, const PlateMotion& plate, const Vec3& q0, double latency) {
    sc.plate = plate;
    sc.part.mu.setConstant(0.8);
    Camera cam = camera(400, CameraFrame::world);
    cam.latency = latency;
    Trajectory exact;
    const Track tr = observe(sc, cam, Dynamics::Full, q0, Vec3::Zero(), 6 * plate.T, {}, &exact);
    REQUIRE(exact.stop.reason == StopReason::None);
    REQUIRE(tr.t.size() == exact.samples.size());
    for (const Sample& s : exact.samples) REQUIRE((s.q - q0).cwiseAbs().maxCoeff() == 0);
    return tr;
}

}   // namespace

TEST_CASE("a part stuck on a translating plate moves in the world frame exactly with the plate", "[observe][world]") {
    PlateMotion u;
    u.T = 0.05;
    u.harmonics = {{Axis::x, 1, 2, 0.4}, {Axis::y, 2, 1.5, 0.7}, {Axis::z, 1, 1, 0.3}, {Axis::x, 3, 0.5, 2.0}};
    for (const char* name : {"fig4", "fig1_point"}) {
        for (double latency : {0.0, 0.0031}) {
            Scene sc = scene(name);
            const Vec3 q0(0.02, -0.01, sc.part.point ? 0.0 : 0.7);
            const Track tr = stuck_track(sc, u, q0, latency);
            REQUIRE(tr.t.size() > 100);
            double worst = 0;
            for (std::size_t k = 0; k < tr.t.size(); ++k) {
                const double ts = tr.t[k] - latency;   // the state a frame stamped t shows
                worst = std::max({worst, std::abs(tr.q[k].x() - (q0.x() + closed_form(u, Axis::x, ts))),
                                  std::abs(tr.q[k].y() - (q0.y() + closed_form(u, Axis::y, ts))),
                                  std::abs(tr.q[k].z() - (sc.part.point ? 0.0 : q0.z()))});
            }
            INFO(name << " latency " << latency << ": largest difference " << worst << " (m, rad)");
            // No rotation: R1 = I exactly, and the closed form is the library's sum term by term
            // (measured 0; bound 1e-16, against displacements of 1.3e-4 m).
            CHECK(worst < 1e-16);
        }
    }
}

TEST_CASE("a part stuck on a turning plate is seen turned with it: R_z(psi) s + p and heading theta + psi", "[observe][world]") {
    // Rotations about z only commute: R1(t) = R_z(psi(t)) with psi the closed-form double integral, which
    // PlateOrientation's Runge-Kutta steps must reproduce; likewise about x alone, where the height
    // s_z of the centre of mass enters: r = p + R_x(a) (s_x, s_y, s_z), heading atan2(cos a sin theta, cos theta).
    PlateMotion spin, tilt;
    spin.T = tilt.T = 0.05;
    spin.harmonics = {{Axis::rz, 1, 20, 0.3}, {Axis::rz, 2, 10, 1.1}, {Axis::x, 1, 2, 0}};
    tilt.harmonics = {{Axis::rx, 1, 60, 0.9}, {Axis::y, 1, 1, 0}};
    const Vec3 q0(0.02, -0.01, 0.7);
    double worst_spin = 0, worst_tilt = 0, turned = 0;
    {
        Scene sc = scene("fig4");
        const Track tr = stuck_track(sc, spin, q0, 0);
        for (std::size_t k = 0; k < tr.t.size(); ++k) {
            const double psi = closed_form(spin, Axis::rz, tr.t[k]), c = std::cos(psi), s = std::sin(psi);
            const Vec3 want(closed_form(spin, Axis::x, tr.t[k]) + c * q0.x() - s * q0.y(), s * q0.x() + c * q0.y(), q0.z() + psi);
            worst_spin = std::max(worst_spin, (tr.q[k] - want).cwiseAbs().maxCoeff());
            turned = std::max(turned, std::abs(psi));
        }
    }
    {
        Scene sc = scene("fig4");
        const double sz = sc.part.s_z();
        const Track tr = stuck_track(sc, tilt, q0, 0);
        for (std::size_t k = 0; k < tr.t.size(); ++k) {
            const double a = closed_form(tilt, Axis::rx, tr.t[k]), c = std::cos(a), s = std::sin(a);
            const Vec3 want(q0.x(), closed_form(tilt, Axis::y, tr.t[k]) + c * q0.y() - s * sz,
                            std::atan2(c * std::sin(q0.z()), std::cos(q0.z())));
            worst_tilt = std::max(worst_tilt, (tr.q[k] - want).cwiseAbs().maxCoeff());
        }
    }
    INFO("largest differences: turning " << worst_spin << ", tilting " << worst_tilt << " (m, rad); turned up to " << turned);
    // RK4 at T/256 against the closed forms: measured 7.8e-13 and 1.7e-15 (m, rad); bounds 3e-12 and 5e-15.
    // The plate turns by up to 1.35e-3 rad, moving the part 3e-5 m: a world frame without R1 is off by that.
    CHECK(worst_spin < 3e-12);
    CHECK(worst_tilt < 5e-15);
    CHECK(turned > 1e-3);
}

TEST_CASE("stroboscopic frames at phase phi are stamped (k + phi) T, and a latency L shows the state at t - L",
          "[observe][schedule]") {
    Camera c;
    c.per_period = 1;
    c.phase = 0.25;
    const double T = 0.05;
    const auto stamps = frame_stamps(c, T, 10 * T);
    REQUIRE(stamps.size() == 10u);   // (9.25 T is the last within 10 T)
    for (std::size_t k = 0; k < stamps.size(); ++k) CHECK(stamps[k] == (static_cast<double>(k) + 0.25) * T);
    // Four per period: (k / 4 + phi) T; with a latency of one period the first frame showing a state
    // at t >= 0 is the one stamped T, k = 3.
    c.per_period = 4;
    c.latency = T;
    const auto four = frame_stamps(c, T, 2.1 * T);
    REQUIRE(four.size() == 9u);   // (k = 3 to 11: state times 0 to 2 T)
    for (std::size_t k = 0; k < four.size(); ++k) CHECK(four[k] == (static_cast<double>(k + 3) / 4 + 0.25) * T);

    // Any schedule and latency: every stamp from k = 0 on whose state time lies in [0, duration], none other.
    for (const double phase : {0.0, 0.5, 0.9})
        for (const int m : {1, 4, 8})
            for (const double L : {0.0, 0.3 * T, 1.7 * T}) {
                c.per_period = m;
                c.phase = phase;
                c.latency = L;
                std::vector<double> want;
                for (int k = 0; k < 100; ++k) {
                    const double t = (static_cast<double>(k) / m + phase) * T;
                    if (t - L >= 0 && t - L <= 3 * T) want.push_back(t);
                }
                INFO("phase " << phase << ", " << m << " per period, latency " << L);
                CHECK(frame_stamps(c, T, 3 * T) == want);
            }

    // The observed states: frames with latency L = 3 frames equal those without, three frames on.
    const Scene sc = scene("fig4");
    Camera cam = camera(200, CameraFrame::plate);
    const Vec3 q0(0.03, -0.02, 1.0);
    const Track direct = observe(sc, cam, Dynamics::Full, q0, Vec3::Zero(), 0.5);
    cam.latency = 3 / cam.rate;
    const Track late = observe(sc, cam, Dynamics::Full, q0, Vec3::Zero(), 0.5);
    REQUIRE(direct.t.size() == 101u);
    REQUIRE(late.t.size() == 101u);
    double dt = 0, dq = 0, moved = 0;
    for (std::size_t k = 0; k < late.t.size(); ++k) {
        dt = std::max(dt, std::abs(late.t[k] - (direct.t[k] + cam.latency)));
        dq = std::max(dq, (late.q[k] - direct.q[k]).cwiseAbs().maxCoeff());
        moved = std::max(moved, (direct.q[k] - q0).head<2>().norm());
    }
    INFO("stamps " << dt << " s, configurations " << dq << " (m, rad) apart; the part moved " << moved << " m");
    // The state times k / rate - L and (k - 3) / rate differ by rounding (measured 5.6e-17 s between
    // the stamps, 5.3e-15 (m, rad) between the configurations); bounds 2e-16 s and 2e-14.
    CHECK(dt < 2e-16);
    CHECK(dq < 2e-14);
    CHECK(moved > 1e-3);   // (frames one off would differ by the motion)
}

TEST_CASE("a run that loses contact ends the track at the last frame before the stop", "[observe][schedule]") {
    // The plate's heave at 15 m/s^2 > g: the normal force reaches zero within the first period.
    Scene sc = scene("fig1_point");
    sc.plate.harmonics.push_back({Axis::z, 1, 15, 0});
    Camera cam = camera(1000, CameraFrame::plate);
    Trajectory exact;
    const Track tr = observe(sc, cam, Dynamics::Full, Vec3(0.01, 0, 0), Vec3::Zero(), 0.2, {}, &exact);
    REQUIRE(exact.stop.reason == StopReason::ContactLost);
    const double stop = exact.stop.t;
    INFO("contact lost at " << stop << " s; " << tr.t.size() << " frames");
    REQUIRE(stop < sc.plate.T);
    // Every stamp k / 1000 before the stop is a frame, none at or after it (the stop's own sample is no frame).
    CHECK(tr.t.size() == static_cast<std::size_t>(std::floor(stop * 1000)) + 1);
    CHECK(tr.t.back() < stop);
    CHECK(exact.samples.back().t == stop);
}

namespace {

// n frames of a part at rest at q (plate frame): the exact trajectory a camera films (film()).
Track film_at_rest(const Scene& sc, const Camera& cam, const Vec3& q, int n) {
    const auto stamps = frame_stamps(cam, sc.plate.T, (n - 1) / cam.rate);
    Trajectory exact;
    for (double t : stamps) exact.samples.push_back(Sample{t - cam.latency, q, Vec3::Zero(), Vec3::Zero(), {}});
    return film(sc, cam, stamps, exact);
}

}   // namespace

TEST_CASE("pixel noise has the camera's standard deviation, zero mean and independent coordinates", "[observe][noise]") {
    const Scene sc = scene("fig4");
    Camera cam = camera(1000, CameraFrame::plate);
    cam.noise_xy_mm = 0.1;
    cam.noise_theta_mrad = 5;
    cam.seed = 7;
    const Vec3 q(0.01, -0.02, 0.5);
    const int N = 40000;
    const Track tr = film_at_rest(sc, cam, q, N);
    REQUIRE(tr.t.size() == static_cast<std::size_t>(N));
    const Vec3 sd(1e-4, 1e-4, 5e-3);
    Vec3 mean = Vec3::Zero(), var = Vec3::Zero();
    double cross = 0;
    for (const Vec3& o : tr.q) mean += (o - q) / N;
    for (const Vec3& o : tr.q) {
        const Vec3 e = o - q - mean;
        var += e.cwiseAbs2() / (N - 1);
        cross += e.x() * e.y() / (N - 1);
    }
    for (int i = 0; i < 3; ++i) {
        const double s = std::sqrt(var[i]);
        INFO("coordinate " << i << ": mean " << mean[i] << ", sd " << s << " against " << sd[i]);
        // Within 4 standard errors: of the mean sd / sqrt(N), of the sample sd sd / sqrt(2 (N - 1)) (0.35 %).
        CHECK(std::abs(mean[i]) < 4 * sd[i] / std::sqrt(N));
        CHECK(std::abs(s / sd[i] - 1) < 4 / std::sqrt(2.0 * (N - 1)));
    }
    // The correlation of x and y: standard error 1 / sqrt(N).
    CHECK(std::abs(cross / std::sqrt(var.x() * var.y())) < 4 / std::sqrt(N));
    // A point part has no heading: its theta stays 0, noise or not.
    const Track pt = film_at_rest(scene("fig1_point"), cam, Vec3(0.01, -0.02, 0), 100);
    for (const Vec3& o : pt.q) CHECK(o.z() == 0);
}

TEST_CASE("frames drop independently with the camera's probability, and dropping changes no other frame", "[observe][drop]") {
    const Scene sc = scene("fig4");
    Camera cam = camera(1000, CameraFrame::plate);
    cam.noise_xy_mm = 0.1;
    cam.seed = 3;
    const int N = 40000;
    const Vec3 q(0.01, -0.02, 0.5);
    const Track all = film_at_rest(sc, cam, q, N);
    cam.drop = 0.2;
    const Track kept = film_at_rest(sc, cam, q, N);
    const double p = cam.drop, n_kept = static_cast<double>(kept.t.size());
    // Binomial: N (1 - p) kept, standard deviation sqrt(N p (1 - p)) = 80; within 4 of them.
    INFO("kept " << n_kept << " of " << N);
    CHECK(std::abs(n_kept - N * (1 - p)) < 4 * std::sqrt(N * p * (1 - p)));
    // Independence: a drop right after a drop happens with probability p^2 per pair, N p^2 = 1600 of
    // N - 1 pairs (standard deviation under 40); a camera dropping in bursts or evenly spaced fails it.
    std::size_t j = 0;
    int pairs = 0;
    bool last_dropped = false;
    for (std::size_t k = 0; k < all.t.size(); ++k) {
        const bool dropped = j >= kept.t.size() || kept.t[j] != all.t[k];
        if (!dropped) {
            // The frames kept are the same frames, noise and all.
            CHECK(kept.q[j] == all.q[k]);
            ++j;
        }
        pairs += dropped && last_dropped;
        last_dropped = dropped;
    }
    CHECK(j == kept.t.size());
    CHECK(std::abs(pairs - N * p * p) < 4 * std::sqrt(N * p * p * (1 - p * p)));
}

TEST_CASE("a model's prediction at a track's stamps differs from the track by the camera's noise alone", "[observe][noise]") {
    // What an identification compares: observe_at the recorded stamps with a camera without noise and
    // drops, against the frames that camera takes on its whole schedule.
    const Scene sc = scene("fig4");
    Camera cam = camera(500, CameraFrame::world);
    cam.noise_xy_mm = 0.1;
    cam.drop = 0.3;
    cam.latency = 0.0013;
    const Vec3 q0(0.03, -0.02, 1.0);
    const Track track = observe(sc, cam, Dynamics::Full, q0, Vec3::Zero(), 1.0);
    Camera clean = cam;
    clean.noise_xy_mm = 0;
    clean.drop = 0;
    const Track pred = observe_at(sc, clean, Dynamics::Full, q0, Vec3::Zero(), track.t);
    const Track full = observe(sc, clean, Dynamics::Full, q0, Vec3::Zero(), 1.0);
    REQUIRE(pred.t == track.t);
    REQUIRE(full.t.size() == 500u);   // (stamps 2 ms to 1 s: the first, 0, shows a state before the start)
    double apart = 0, ss = 0;
    std::size_t j = 0;
    for (std::size_t k = 0; k < pred.t.size(); ++k) {
        while (full.t[j] < pred.t[k]) ++j;
        REQUIRE(full.t[j] == pred.t[k]);
        apart = std::max(apart, (full.q[j] - pred.q[k]).cwiseAbs().maxCoeff());
        ss += (track.q[k] - pred.q[k]).head<2>().squaredNorm();
    }
    const double n = 2.0 * pred.t.size(), sd = std::sqrt(ss / n);
    INFO(pred.t.size() << " frames; prediction and whole schedule " << apart << " apart; residual sd " << sd);
    // The engine steps to other times when frames are missing: measured 5.9e-11 (m, rad) apart (rtol 1e-9); bound 2e-10. The
    // residuals' sd: 0.1 mm within 4 standard errors (1 / sqrt(2 n) of it).
    CHECK(apart < 2e-10);
    CHECK(std::abs(sd / 1e-4 - 1) < 4 / std::sqrt(2 * n));
}

TEST_CASE("a track written and read back is the same to the bit", "[observe][track]") {
    for (const char* name : {"fig4", "fig1_point"}) {
        Scene sc = scene(name);
        sc.name = "with \"quotes\", a comma and\na newline";
        Camera cam;
        cam.per_period = 3;
        cam.phase = 0.1;
        cam.noise_xy_mm = 0.1;
        cam.noise_theta_mrad = 5;
        cam.latency = 0.0017;
        cam.drop = 0.1;
        cam.seed = 12345678901234567ull;
        cam.frame = CameraFrame::world;
        const Vec3 q0(0.03, -0.02, sc.part.point ? 0.0 : 1.0);
        const Track tr = observe(sc, cam, Dynamics::Full, q0, Vec3::Zero(), 0.4);
        REQUIRE(tr.t.size() > 15);
        std::ostringstream out;
        write_track_csv(out, tr);
        const Track back = parse_track_csv(out.str(), "round.csv");
        INFO(out.str().substr(0, 400));
        CHECK(back.scene_name == tr.scene_name);
        CHECK(back.scene_id == scene_id(sc));
        CHECK(back.point == sc.part.point);
        CHECK(camera_to_json(back.camera) == camera_to_json(cam));
        CHECK(back.camera.noise_xy_mm == cam.noise_xy_mm);
        CHECK(back.camera.latency == cam.latency);
        REQUIRE(back.t.size() == tr.t.size());
        for (std::size_t k = 0; k < tr.t.size(); ++k) {
            CHECK(back.t[k] == tr.t[k]);
            CHECK(back.q[k] == tr.q[k]);
        }
        CHECK(back.lines.front() == 8);   // (7 header lines)
        CHECK_NOTHROW(check_track_scene(back, sc));
    }
}

TEST_CASE("a scene's id is its set-up's: the plate motion and gravity, not the part's unknowns", "[observe][track]") {
    const Scene a = scene("fig4");
    const Scene again = parse_scene(scene_to_json(a).dump(2), "elsewhere.json");
    CHECK(scene_id(a) == scene_id(again));
    CHECK(scene_id(a).size() == 16u);
    // What identification estimates (friction, the centre of mass) and what it takes as given leave it.
    Scene guess = a;
    guess.part.m *= 1.1;
    guess.part.mu *= 1.2;
    guess.part.mu_static = Vec3::Constant(0.5);
    for (auto& c : guess.part.c) c.x() += 1e-3;
    guess.name = "fig4 with a guessed friction";
    CHECK(scene_id(guess) == scene_id(a));
    // Another plate motion, gravity or kind of part: another set-up.
    Scene phase = a;
    phase.plate.harmonics[0].phase += 1e-12;
    Scene period = a;
    period.plate.T *= 1 + 1e-15;
    Scene gravity = a;
    gravity.g = 9.80665;
    CHECK(scene_id(phase) != scene_id(a));
    CHECK(scene_id(period) != scene_id(a));
    CHECK(scene_id(gravity) != scene_id(a));
    CHECK(scene_id(scene("fig1_point")) != scene_id(scene("fig1")));
}

namespace {

// A valid track of fig4 as text (5 frames), for the bad-input cases to break.
std::string good_track() {
    Track tr;
    const Scene sc = scene("fig4");
    tr.scene_name = sc.name;
    tr.scene_id = scene_id(sc);
    tr.camera = camera(100, CameraFrame::plate);
    for (int k = 0; k < 5; ++k) {
        tr.t.push_back(k / 100.0);
        tr.q.emplace_back(0.01 * k, -0.02, 0.5);
    }
    std::ostringstream out;
    write_track_csv(out, tr);
    return out.str();
}

// The message of the InputError read_track_csv throws on `text` (written to a file), "" if none.
std::string track_error(const std::string& text) {
    const fs::path p = tmpdir() / "bad_track.csv";
    std::ofstream(p) << text;
    try {
        read_track_csv(p.string());
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

std::string replace(std::string s, const std::string& from, const std::string& to) {
    const auto at = s.find(from);
    REQUIRE(at != std::string::npos);
    return s.replace(at, from.size(), to);
}

}   // namespace

TEST_CASE("a bad track is refused with its file, its line and what was expected", "[observe][track]") {
    const std::string good = good_track(), file = (tmpdir() / "bad_track.csv").string();
    REQUIRE(track_error(good).empty());
    // Rows are lines 8-12 (frame k at line 8 + k): "0.01,0.01,..." is frame 1's.
    const std::string row1 = "0.01,0.01,-0.02,0.5";
    REQUIRE(good.find(row1) != std::string::npos);
    const struct {
        std::string text, where, what;
    } cases[] = {
        {replace(good, row1, "0.01,nan,-0.02,0.5"), ":9:2: ", "s_x [m]: expected a finite number"},
        {replace(good, row1, "0.01,0.01,-0.02,inf"), ":9:4: ", "theta [rad]: expected a finite number"},
        {replace(good, row1, "0.01,0.01,-0.02"), ":9: ", "expected 4 columns"},
        {replace(good, row1, "0.01,0.01,-0.02,0.5,1"), ":9: ", "expected 4 columns"},
        {replace(good, row1, "0,0.01,-0.02,0.5"), ":9:1: ", "expected a time after the previous frame's"},
        {good.substr(0, good.find(row1)), ":8: ", "1 frames: a track needs at least 3"},
        {good.substr(good.find('\n') + 1), ":1: ", "expected the format line \"# plate track 1\""},
        {replace(good, "# plate track 1", "# plate track 2"), ":1: ", "unknown track format version \"2\""},
        {replace(good, "# scene_id: ", "# scene id: "), ":3: ", "expected the header line \"# scene_id: ...\""},
        {good.substr(0, good.find("# frame")), ":5: ", "the file ends before the header is complete"},
        {replace(good, "\"rate_hz\":100.0", "\"rate_hz\":-1"), ":4: camera: rate_hz: ", "expected a positive number"},
        {replace(good, "# part: rigid", "# part: point"), ":7: ", "expected the column line \"t [s],s_x [m],s_y [m]\""},
        {replace(good, "# frame: plate", "# frame: world"), ":5: ", "frame: expected \"plate\", the camera's frame"},
    };
    for (const auto& c : cases) {
        const std::string msg = track_error(c.text);
        INFO("message: " << msg);
        CHECK(msg.find(file + c.where) == 0);
        CHECK(msg.find(c.what) != std::string::npos);
    }
    // Tracks taken under another scene: the scene_id's line (3) named.
    const fs::path p = tmpdir() / "fig4_track.csv";
    std::ofstream(p) << good;
    Scene other = scene("fig4");
    other.plate.harmonics[0].amp *= 1.01;   // another plate motion
    try {
        check_track_scene(read_track_csv(p.string()), other);
        FAIL("no error");
    } catch (const InputError& e) {
        const std::string msg = e.what();
        INFO(msg);
        CHECK(msg.find(p.string() + ":3: tracks from another scene") == 0);
    }
}

TEST_CASE("plate simulate --observe writes the camera's track, and a bad camera file exits 2 naming file and field",
          "[observe][cli]") {
    const fs::path cam = tmpdir() / "camera.json", track = tmpdir() / "track.csv";
    std::ofstream(cam) << R"({"stroboscopic": {"phase": 0.25}, "noise": {"xy_mm": 0.1, "theta_mrad": 5},
                             "latency_s": 0, "drop": 0.0, "seed": 1, "frame": "world"})";
    const Run r = run("simulate " + kScenes + "fig4.json --dynamics full --start 0.03 -0.02 1 --time 1 --observe " +
                      cam.string() + " --out " + track.string());
    INFO(r.err);
    REQUIRE(r.code == 0);
    const Track tr = read_track_csv(track.string());
    CHECK_NOTHROW(check_track_scene(tr, scene("fig4")));
    CHECK(tr.camera.frame == CameraFrame::world);
    REQUIRE(tr.t.size() == 20u);   // one frame per period of 0.05 s over 1 s, at (k + 1/4) T
    CHECK(tr.t[3] == 3.25 * 0.05);

    std::ofstream(cam) << R"({"rate_hz": 100, "noise": {"xy_mm": -0.1}, "frame": "plate"})";
    const Run bad = run("simulate " + kScenes + "fig4.json --dynamics full --start 0.03 -0.02 1 --time 1 --observe " +
                        cam.string() + " --out " + track.string());
    CHECK(bad.code == 2);
    CHECK(bad.err.find(cam.string() + ": noise.xy_mm: expected a standard deviation from 0 to 1000 mm") != std::string::npos);
    const Run sample = run("simulate " + kScenes +
                           "fig4.json --dynamics full --start 0.03 -0.02 1 --time 1 --sample 0.01 --observe " + cam.string());
    CHECK(sample.code == 2);
    CHECK(sample.err.find("--sample") != std::string::npos);
}
