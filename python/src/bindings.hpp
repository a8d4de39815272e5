// The Python module's compiled half, plate._plate, in pieces by topic (python/src/): module.cpp's
// PYBIND11_MODULE calls the bind_* functions below in order, each defined in the file named beside it;
// the conversions and result holders more than one of them uses are declared here.
#pragma once

#include "plate/design.hpp"
#include "plate/field.hpp"
#include "plate/observe.hpp"
#include "plate/output.hpp"
#include "plate/scene_io.hpp"

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace plate::python {

namespace py = pybind11;

// --- the module's classes and functions, registered in this order --------------------------------

void bind_progress(py::module_& m);       // progress.cpp: Progress
void bind_scene(py::module_& m);          // scene.cpp:    Scene, load_scene, parse_scene, Stop
void bind_twist(py::module_& m);          // twist.cpp:    Cycle, twist
void bind_field(py::module_& m);          // field.cpp:    Field, field
void bind_fixed_points(py::module_& m);   // field.cpp:    FixedPoint, FixedLine, FixedPoints, fixed_points
void bind_design(py::module_& m);         // design.cpp:   Design, design, orientation_harmonics, coning_rate
void bind_simulate(py::module_& m);       // simulate.cpp: Trajectory, simulate
void bind_robustness(py::module_& m);     // robustness.cpp: Robustness, robustness, uncertain_parameters
void bind_observe(py::module_& m);        // observe.cpp:  Camera, Track, observe, read_track_csv, ...
void bind_identify(py::module_& m);       // identify.cpp: Identification, identify
void bind_control(py::module_& m);        // control.cpp:  ControlRun, control, ControlEnv
void bind_commands(py::module_& m);       // commands.cpp: random_scene, sweep

// --- conversions (conversions.cpp) ---------------------------------------------------------------

py::object json_to_python(const nlohmann::json& j);

// A configuration or twist: 3 numbers for a rigid part, 2 for a point part (theta meaningless).
Vec3 config(const Scene& sc, const std::vector<double>& v, const char* name);

// The library's run records as pickled state (tuples of Python numbers and str: doubles to the bit),
// and back; what the results' py::pickle are made of.
py::tuple mode_state(const Mode& m);
Mode mode_of(const py::handle& state);
py::tuple event_state(const ModeEvent& e);
ModeEvent event_of(const py::handle& state);
py::tuple stop_state(const StopEvent& e);
StopEvent stop_of(const py::handle& state);
py::tuple stats_state(const Stats& s);
Stats stats_of(const py::handle& state);
py::tuple sample_state(const Sample& s);
Sample sample_of(const py::handle& state);

// A file's path from a str or an os.PathLike (pathlib.Path): the path, else nothing.
std::optional<std::string> path_of(const py::handle& o);

// ValueError(message) unless ok.
void require(bool ok, const std::string& message);

// x with `digits` significant digits, for reprs.
std::string num(double x, int digits = 4);

// One vocabulary (issue 54): the value of keyword `now`, or of its old spelling `old` (kept for one
// release: using it warns with a DeprecationWarning); both given is a ValueError; neither, `fallback`.
template <class T>
T renamed(const std::optional<T>& now, const std::optional<T>& old, const char* now_name, const char* old_name,
          const T& fallback) {
    if (!old) return now ? *now : fallback;
    require(!now,
            std::string(now_name) + " and " + old_name + " are the same argument (" + old_name + " its old spelling): give one");
    const std::string msg =
        std::string(old_name) + "= is deprecated: use " + now_name + "= (the old spelling goes in the next release)";
    if (PyErr_WarnEx(PyExc_DeprecationWarning, msg.c_str(), 1) != 0) throw py::error_already_set();
    return *old;
}

// A camera from a plate.Camera, a camera file's path (str) or a dict in the file's form (checked as a
// file is: plate.InputError). observe.cpp.
Camera camera_of(const py::object& c);

// A numpy array of the given shape holding data (row-major).
py::array_t<double> array(const std::vector<double>& data, std::vector<py::ssize_t> shape);

// The limit-cycle options of the keywords tol, rtol, max_periods, solver, max_rhs (ValueError if out of range).
LimitCycleOptions cycle_options(double tol, double rtol, int max_periods, const std::string& solver, long max_rhs);

// --- results more than one topic holds ------------------------------------------------------------

struct PyStop {
    std::string reason;   // "none", "contact_lost", ... (stop_name)
    int contact = 0;      // 1-based, 0 if none
    double t = 0;
    std::string message;   // StopEvent::describe()
};
PyStop to_py(const StopEvent& e);

// plate.field's result; plate.fixed_points takes it.
struct PyField {
    Scene scene;
    Field f;
};

// --- the design target (design.cpp) ----------------------------------------------------------------

// plate.design's target keywords -- exactly one of sink=(x, y), transport=(vx, vy), fixed_point=(x, y,
// theta), orient=theta, line_sink=(x, y, phi), target='KIND NUMBERS' -- as a DesignTarget through the
// library's parse_design_target (ValueError with its message if not exactly one, or refused). The one
// place the module reads a target.
DesignTarget design_target_from_kwargs(const std::optional<std::pair<double, double>>& sink,
                                       const std::optional<std::pair<double, double>>& transport,
                                       const std::optional<std::tuple<double, double, double>>& fixed_point,
                                       const std::optional<double>& orient,
                                       const std::optional<std::tuple<double, double, double>>& line_sink,
                                       const std::optional<std::string>& target, bool point_part);

}   // namespace plate::python
