// plate.observe: what a camera records of a simulation (plate.Track), the camera (plate.Camera) and
// the track file (plate.read_track_csv, plate.write_track_csv): numeric/include/plate/observe.hpp.
#include "bindings.hpp"
#include "interrupt.hpp"

#include <pybind11/stl/filesystem.h>

#include <filesystem>

#include "plate/observe.hpp"

#include <cmath>
#include <functional>

namespace plate::python {

Camera camera_of(const py::object& c) {
    if (py::isinstance<Camera>(c)) return c.cast<Camera>();
    if (const auto path = path_of(c)) return load_camera(*path);
    require(py::isinstance<py::dict>(c), "camera: expected a plate.Camera, a camera file's path or a dict in its form");
    return parse_camera(py::module_::import("json").attr("dumps")(c).cast<std::string>(), "<dict>");
}

namespace {

// plate.observe and plate.observe_at: the options checked, `run` (the library's observe or observe_at)
// called without the GIL, the track returned with the run's stop as track.stop.
using Run = std::function<Track(Dynamics, const Vec3&, const Vec3&, const IntegrationOptions&, Trajectory*)>;
py::object run_observe(const Scene& sc, const std::vector<double>& start, const std::optional<std::vector<double>>& twist,
                       const std::string& dynamics, double rtol, long max_steps, const Run& run) {
    require(dynamics == "full" || dynamics == "u", "dynamics: expected 'full' or 'u', got '" + dynamics + "'");
    const Vec3 q0 = config(sc, start, "start");
    const Vec3 qd0 = twist ? config(sc, *twist, "twist") : Vec3::Zero();
    require(rtol > 0 && rtol < 1e-2, "rtol: expected a number in (0, 1e-2)");
    require(max_steps >= 1, "max_steps: expected >= 1");
    IntegrationOptions io;
    io.rtol = rtol;
    io.max_steps = max_steps;
    Trajectory exact;
    Track tr = interruptible(py::none(),
                             [&](Watch&) { return run(dynamics == "full" ? Dynamics::Full : Dynamics::U, q0, qd0, io, &exact); });
    py::object out = py::cast(std::move(tr));
    out.attr("stop") = py::cast(to_py(exact.stop));
    return out;
}

}   // namespace

void bind_observe(py::module_& m) {
    py::class_<Camera>(m, "Camera", "A camera filming the plate (numeric/include/plate/observe.hpp: the file's form).")
        .def("__repr__",
             [](const Camera& c) {
                 return "<plate.Camera " +
                        (c.stroboscopic() ? std::to_string(c.per_period) + " frame(s) per period from phase " + num(c.phase)
                                          : num(c.rate) + " frames/s") +
                        ", noise " + num(c.noise_xy_mm) + " mm / " + num(c.noise_theta_mrad) + " mrad, latency " +
                        num(c.latency) + " s, drop " + num(c.drop) + ", " + frame_name(c.frame) + " frame>";
             })
        .def(py::pickle([](const Camera& c) { return py::make_tuple(camera_to_json(c).dump(), c.source); },
                        [](const py::tuple& t) {
                            require(t.size() == 2, "plate.Camera: a pickled camera is (file text, source)");
                            Camera c = parse_camera(t[0].cast<std::string>(), t[1].cast<std::string>());
                            c.source = t[1].cast<std::string>();
                            return c;
                        }))
        .def_readonly("source", &Camera::source)
        .def_readonly("rate", &Camera::rate, "frames per second; 0: stroboscopic")
        .def_readonly("per_period", &Camera::per_period, "stroboscopic: frames per plate period (0 if rate > 0)")
        .def_readonly("phase", &Camera::phase, "stroboscopic: the first frame's time as a fraction of T")
        .def_readonly("noise_xy_mm", &Camera::noise_xy_mm, "standard deviation of the noise on s_x and on s_y [mm]")
        .def_readonly("noise_theta_mrad", &Camera::noise_theta_mrad, "standard deviation of the noise on theta [mrad]")
        .def_readonly("latency", &Camera::latency, "[s]: a frame stamped t shows the state at t - latency")
        .def_readonly("drop", &Camera::drop, "probability that a frame is lost")
        .def_readonly("seed", &Camera::seed)
        .def_property_readonly("frame", [](const Camera& c) { return std::string(frame_name(c.frame)); })
        .def_property_readonly("stroboscopic", &Camera::stroboscopic)
        .def(
            "to_json", [](const Camera& c) { return camera_to_json(c).dump(); }, "the camera in the file form");
    m.def(
        "load_camera", [](const std::filesystem::path& p) { return load_camera(p.string()); }, py::arg("path"),
        "Reads a camera file, its path a str or os.PathLike (raises plate.InputError).");
    m.def("parse_camera", &parse_camera, py::arg("text"), py::arg("source"),
          "Reads a camera from JSON text; `source` names it in messages (raises plate.InputError).");
    m.def("scene_id", &scene_id, py::arg("scene"), "The scene's fingerprint (16 hex digits), as a track's header names it.");
    m.def(
        "frame_stamps",
        [](const Scene& sc, const py::object& camera, double time) {
            const std::vector<double> t = frame_stamps(camera_of(camera), sc.plate.T, time);
            return array(t, {static_cast<py::ssize_t>(t.size())});
        },
        py::arg("scene"), py::arg("camera"), py::arg("time"),
        "The camera's stamps (before drops) whose states, at t - latency, lie within [0, time].");

    // (dynamic attributes: observe's tracks carry the run's stop)
    py::class_<Track>(m, "Track", py::dynamic_attr(),
                      "The frames a camera recorded: stamps t and (s_x, s_y, theta) in the camera's frame.")
        .def_readonly("source", &Track::source, "the file it was read from ('' if made here)")
        .def_readonly("scene_name", &Track::scene_name)
        .def_readonly("scene_id", &Track::scene_id)
        .def_readonly("camera", &Track::camera)
        .def_readonly("point", &Track::point, "a point part: theta is 0")
        .def_property_readonly("frame", [](const Track& t) { return std::string(frame_name(t.camera.frame)); })
        .def_property_readonly(
            "t", [](const Track& t) { return array(t.t, {static_cast<py::ssize_t>(t.t.size())}); }, "(n,): camera stamps [s]")
        .def_property_readonly(
            "q",
            [](const Track& t) {
                std::vector<double> d;
                for (const Vec3& q : t.q) d.insert(d.end(), {q[0], q[1], q[2]});
                return array(d, {static_cast<py::ssize_t>(t.q.size()), 3});
            },
            "(n, 3): s_x [m], s_y [m], theta [rad]")
        .def_readonly("lines", &Track::lines, "read from a file: each frame's line")
        .def("__len__", [](const Track& t) { return t.t.size(); })
        // Pickled as its fields, the camera in its file form, with the attributes a run gave it (stop).
        .def(py::pickle(
            [](const py::object& self) {
                const Track& t = self.cast<const Track&>();
                py::list q;
                for (const Vec3& v : t.q) q.append(py::make_tuple(v[0], v[1], v[2]));
                return py::make_tuple(t.source, t.scene_name, t.scene_id, camera_to_json(t.camera).dump(), t.point, t.t, q,
                                      t.lines, t.scene_id_line, self.attr("__dict__"));
            },
            [](const py::tuple& s) {
                require(s.size() == 10, "plate.Track: not a pickled track");
                Track t;
                t.source = s[0].cast<std::string>();
                t.scene_name = s[1].cast<std::string>();
                t.scene_id = s[2].cast<std::string>();
                t.camera = parse_camera(s[3].cast<std::string>(), "<pickled track>");
                t.point = s[4].cast<bool>();
                t.t = s[5].cast<std::vector<double>>();
                for (const py::handle& h : s[6].cast<py::list>()) {
                    const auto v = h.cast<py::tuple>();
                    t.q.emplace_back(v[0].cast<double>(), v[1].cast<double>(), v[2].cast<double>());
                }
                t.lines = s[7].cast<std::vector<int>>();
                t.scene_id_line = s[8].cast<int>();
                return std::make_pair(t, s[9].cast<py::dict>());
            }))
        .def("__repr__", [](const Track& t) {
            return "<plate.Track of '" + t.scene_name + "': " + std::to_string(t.t.size()) + " frames, " +
                   frame_name(t.camera.frame) + " frame>";
        });
    m.def(
        "observe",
        [](const Scene& sc, const py::object& camera, const std::vector<double>& start, double time, const std::string& dynamics,
           std::optional<std::vector<double>> twist, double rtol, long max_steps) {
            const Camera cam = camera_of(camera);
            require(std::isfinite(time) && time > 0, "time: expected a number > 0");
            const double per_second = cam.stroboscopic() ? cam.per_period / sc.plate.T : cam.rate;
            require(time * per_second <= 1e7, "time: the camera would take more than 10^7 frames");
            return run_observe(sc, start, twist, dynamics, rtol, max_steps,
                               [&](Dynamics level, const Vec3& q0, const Vec3& qd0, const IntegrationOptions& io,
                                   Trajectory* ex) { return observe(sc, cam, level, q0, qd0, time, io, ex); });
        },
        py::arg("scene"), py::arg("camera"), py::arg("start"), py::arg("time"), py::kw_only(), py::arg("dynamics") = "full",
        py::arg("twist") = py::none(), py::arg("rtol") = 1e-9, py::arg("max_steps") = 20'000'000L,
        "What `camera` (a plate.Camera, a camera file's path or a dict in its form) records of a simulation from\n"
        "`start` (twist `twist` relative to the plate, default at rest) for `time` seconds: ('full' or 'u' dynamics).\n"
        "A run that stops (a normal force reaches zero) ends the track there: track.stop says when and why.");
    m.def(
        "observe_at",
        [](const Scene& sc, const py::object& camera, const std::vector<double>& start, const std::vector<double>& stamps,
           const std::string& dynamics, std::optional<std::vector<double>> twist, double rtol, long max_steps) {
            const Camera cam = camera_of(camera);
            require(!stamps.empty() && stamps.size() <= 10'000'000u, "stamps: expected 1 to 10^7 stamps");
            return run_observe(sc, start, twist, dynamics, rtol, max_steps,
                               [&](Dynamics level, const Vec3& q0, const Vec3& qd0, const IntegrationOptions& io,
                                   Trajectory* ex) { return observe_at(sc, cam, level, q0, qd0, stamps, io, ex); });
        },
        py::arg("scene"), py::arg("camera"), py::arg("start"), py::arg("stamps"), py::kw_only(), py::arg("dynamics") = "full",
        py::arg("twist") = py::none(), py::arg("rtol") = 1e-9, py::arg("max_steps") = 20'000'000L,
        "plate.observe at the given camera stamps (increasing, none before the camera's latency): e.g. a model's\n"
        "prediction of a recorded track -- track.t, a camera without noise and drops.");
    m.def(
        "read_track_csv", [](const std::filesystem::path& p) { return read_track_csv(p.string()); }, py::arg("path"),
        "Reads a track file, its path a str or os.PathLike (raises plate.InputError naming the file and the line: a bad header, "
        "cell or time, too few frames).");
    m.def(
        "write_track_csv",
        [](const Track& t, const std::filesystem::path& path) {
            write_file_atomic(path.string(), [&](std::ostream& o) { write_track_csv(o, t); });
        },
        py::arg("track"), py::arg("path"), "Writes a track file (the form read_track_csv reads).");
    m.def("check_track_scene", &check_track_scene, py::arg("track"), py::arg("scene"),
          "Raises plate.InputError ('tracks from another scene', naming the file and line) unless the track was taken "
          "under `scene`.");
}

}   // namespace plate::python
