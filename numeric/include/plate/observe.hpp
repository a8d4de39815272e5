// Camera observations of a part (issue 52, point 2): what a camera filming the plate from above
// records of a simulation -- frames on a schedule, pixel noise, latency, dropped frames, in the plate's
// frame or the world's -- and the track file that holds them. The one home of cameras and tracks: the
// simulate command writes tracks through write_track_csv, and whatever reads them (identification)
// reads them through read_track_csv and check_track_scene.
//
// The camera file (JSON; unknown or missing fields are errors):
//
//   { "rate_hz": 200,                                  // frames at t = k / rate_hz, k = 0, 1, ...
//     -- or --
//     "stroboscopic": {"phase": 0.25, "per_period": 1},  // frames at t = (k / per_period + phase) T
//     "noise": {"xy_mm": 0.1, "theta_mrad": 5},        // optional: Gaussian pixel noise, sd per coordinate
//     "latency_s": 0.002,                              // optional (0): a frame stamped t shows the state at t - latency_s
//     "drop": 0.01,                                    // optional (0): probability a frame is lost, independently
//     "seed": 1,                                       // optional (0): the noise's and the drops' seed
//     "frame": "plate" }                               // "plate" | "world": whose coordinates the frames give
//
// Exactly one of rate_hz and stroboscopic. phase is a fraction of the plate period T in [0, 1);
// per_period (optional, 1) is a whole number of frames per period. Stamps run from the camera's t = 0,
// the start of the simulation (the plate at phase 0 of its motion).
//
// The track file (CSV), written by write_track_csv:
//
//   # plate track 1
//   # scene: "fig4"
//   # scene_id: fa0586ad9c2e6259
//   # camera: {"drop":0.0,"frame":"plate","latency_s":0.0,"noise":{...},"seed":1,"stroboscopic":{...}}
//   # frame: plate
//   # part: rigid
//   t [s],s_x [m],s_y [m],theta [rad]
//   0.012500000000000001,0.028551897259516866,-0.020566585395640418,1.0093570203833446
//   ...
//
// The first line names the format and its version; "# key: value" lines follow in this order (the
// scene's name as a JSON string, its scene_id, the camera in its file form, its frame, the part); then
// the column line and one row per recorded frame, t strictly increasing. A point part has no heading:
// its part line says "point" and its columns are t [s],s_x [m],s_y [m]. t is the camera's stamp; the
// state shown is at t - latency_s (the camera line says it).
#pragma once

#include "plate/dynamics.hpp"
#include "plate/model.hpp"
#include "plate/simulate.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

namespace plate {

enum class CameraFrame { plate, world };
const char* frame_name(CameraFrame f);   // "plate", "world"

// A camera, validated once here (validate(): the reader and every caller that builds one in code).
struct Camera {
    std::string source;   // file it was read from (for messages)
    double rate = 0;      // frames per second; 0: stroboscopic
    int per_period = 0;   // stroboscopic: frames per plate period (0 when rate > 0)
    double phase = 0;     // stroboscopic: the first frame's time as a fraction of T, in [0, 1)
    // Standard deviations of the Gaussian noise on s_x and on s_y (each) [mm], and on theta [mrad]: in
    // the file's units, so that a camera written and read back is the same to the bit.
    double noise_xy_mm = 0;
    double noise_theta_mrad = 0;
    double latency = 0;       // [s]: a frame stamped t shows the state at t - latency
    double drop = 0;          // probability that a frame is lost, in [0, 1)
    std::uint64_t seed = 0;   // of the noise and the drops (Rng, random_scene.hpp)
    CameraFrame frame = CameraFrame::plate;

    bool stroboscopic() const { return rate == 0; }
    // InputError naming source and the file's field unless the camera is admissible: exactly one
    // schedule, a positive rate up to kMaxFrameRate, per_period from 1 to kMaxFramesPerPeriod, phase
    // in [0, 1), noise from 0 to kMaxNoise (a metre or a radian) and latency from 0 to kMaxLatency,
    // drop in [0, 1).
    void validate() const;
};
inline constexpr double kMaxFrameRate = 1e6;   // frames/s
inline constexpr int kMaxFramesPerPeriod = 1000;
inline constexpr double kMaxNoise = 1.0;     // m or rad: a camera that sees nothing
inline constexpr double kMaxLatency = 1e3;   // s

Camera load_camera(const std::string& path);                               // throws InputError
Camera parse_camera(const std::string& text, const std::string& source);   // throws InputError
// The camera in the file form (parse_camera(camera_to_json(c).dump(), ..) gives c back).
nlohmann::json camera_to_json(const Camera& camera);

// A stable fingerprint of the set-up a camera films: FNV-1a 64 of the scene file's gravity and plate
// motion and whether the part is a point (keys sorted, numbers that read back to the same doubles), as
// 16 lowercase hex digits. Not the part's mass, inertia, contacts or friction, nor the scene's name:
// those are what a real part leaves unknown and identification estimates, so a track filmed on the
// real plate matches any guess of them. The same set-up gives the same id on every run and platform;
// any change of the plate motion or gravity changes it.
std::string scene_id(const Scene& scene);

// The frames a track holds: camera stamps t and the observed (s_x, s_y, theta) -- theta 0 for a
// point part, which has none.
struct Track {
    std::string source;       // the file it was read from ("" if made in code)
    std::string scene_name;   // the scene the frames were taken under
    std::string scene_id;     // and its scene_id()
    Camera camera;
    bool point = false;      // a point part: no theta column
    std::vector<double> t;   // camera stamps [s], strictly increasing
    std::vector<Vec3> q;     // (s_x [m], s_y [m], theta [rad]) in camera.frame
    // Read from a file: the file's line of each frame and of the scene_id line (for messages of
    // later checks, e.g. a frame an identification cannot use); empty and 0 for a track made in code.
    std::vector<int> lines;
    int scene_id_line = 0;
};

// Fewer frames are no track: a velocity needs two positions and an acceleration (a friction's
// deceleration, a twist's change) three.
inline constexpr int kMinTrackFrames = 3;

// The camera's stamps (before drops) whose state times t - latency lie in [0, duration], in order;
// stroboscopic ones need the plate period T. std::invalid_argument for duration <= 0 or more than
// 10^9 frames; InputError for a camera that validate() refuses.
std::vector<double> frame_stamps(const Camera& camera, double T, double duration);

// The part's pose in the world frame at time t from its plate-frame configuration q: the plate's
// displacement p(t) plus R1(t) (s_x, s_y, s_z), and the heading of R1(t) R_z(theta) about the world's
// z, taken within pi of theta (continuous wherever theta is). R1: PlateOrientation.
Vec3 world_pose(const Scene& scene, double t, const Vec3& q, const Mat3& R1);

// The plate's orientation R1(t) (R1' = omega1^ R1, omega1 from PlateMotion::velocity, R1(0) the
// rotation by the zero-mean rotation vector at 0 -- as the full dynamics start it), integrated forward
// in fixed steps of T / kOrientationStepsPerPeriod (fourth-order Runge-Kutta on the quaternion): the
// rotations do not commute, so R1(t) drifts from the rotation by the zero-mean rotation vector
// (coning). Times must be asked in increasing order.
inline constexpr int kOrientationStepsPerPeriod = 256;
class PlateOrientation {
public:
    explicit PlateOrientation(const PlateMotion& plate);
    Mat3 at(double t);

private:
    const PlateMotion& plate_;
    double t_ = 0;
    Eigen::Quaterniond q_;
};

// What the camera records of `exact`, whose samples k are the states at stamps[k] - latency (from
// simulate_at; a run that stopped has fewer, and a last one at its stop, which is no frame): each
// frame mapped to camera.frame, kept with probability 1 - drop, given Gaussian noise. The random
// draws of frame k are the same whatever drop is (each frame draws its drop and its noise).
Track film(const Scene& scene, const Camera& camera, const std::vector<double>& stamps, const Trajectory& exact);

// A camera filming a simulation from (q0, qd0) at t = 0 for `duration` seconds: simulate_at the
// state times of frame_stamps, then film. `exact` (if given) receives the trajectory at those times,
// with its stop (a run that stops ends the track there).
Track observe(const Scene& scene, const Camera& camera, Dynamics level, const Vec3& q0, const Vec3& qd0, double duration,
              const IntegrationOptions& opt = {}, Trajectory* exact = nullptr);

// observe() at the given stamps (increasing, each at or after camera.latency; std::invalid_argument
// else): e.g. a model's prediction of a recorded track -- its t, a camera without noise and drops.
Track observe_at(const Scene& scene, const Camera& camera, Dynamics level, const Vec3& q0, const Vec3& qd0,
                 const std::vector<double>& stamps, const IntegrationOptions& opt = {}, Trajectory* exact = nullptr);

// The track file (above): numbers with 17 significant digits, which read back to the same doubles.
void write_track_csv(std::ostream& out, const Track& track);
// InputError naming the file and the line (and the column of a bad cell) and what was expected: a
// missing or unknown format line, a missing or misordered header line, a camera that parse_camera
// refuses, a column line that does not match the part, a row with the wrong number of cells, a cell
// that is no finite number, a time not after the one before, fewer than kMinTrackFrames frames.
Track read_track_csv(const std::string& path);
Track parse_track_csv(const std::string& text, const std::string& source);
// InputError "TRACK:LINE: tracks from another scene: ..." unless the track's scene_id is the scene's.
void check_track_scene(const Track& track, const Scene& scene);

}   // namespace plate
