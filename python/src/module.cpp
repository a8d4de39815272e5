// The Python module `plate` (its compiled half, plate._plate; python/plate/__init__.py is the rest).
//
// What the command line computes, callable from a notebook: scenes from files or dicts, asymptotic
// twists (limit cycles), fields as numpy arrays over their grid, fixed points, trajectories with the
// contact mode of every sample. Options are keyword arguments with the library's defaults; results
// are objects whose arrays are numpy arrays, and whose `summary` is the command line's JSON as a dict.
// The GIL is released while the library works (fields and long simulations take seconds), so other
// Python threads run meanwhile. Errors are Python exceptions with the command line's messages:
// plate.InputError (a ValueError) for a bad scene, ValueError for a bad option, RuntimeError else.
#include "plate/design.hpp"
#include "plate/field.hpp"
#include "plate/output.hpp"
#include "plate/scene_io.hpp"

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace py = pybind11;
using namespace plate;

namespace {

// --- conversions ---------------------------------------------------------------------------------

py::object json_to_python(const nlohmann::json& j) {
    return py::module_::import("json").attr("loads")(j.dump());
}

// A configuration or twist: 3 numbers for a rigid part, 2 for a point part (theta meaningless).
Vec3 config(const Scene& sc, const std::vector<double>& v, const char* name) {
    const std::size_t need = sc.part.point ? 2 : 3;
    if (v.size() != need)
        throw py::value_error(std::string(name) + ": expected " + std::to_string(need) + " numbers (" +
                              (sc.part.point ? "point part: SX SY" : "SX SY THETA") + "), got " +
                              std::to_string(v.size()));
    Vec3 q = Vec3::Zero();
    for (std::size_t i = 0; i < need; ++i) {
        if (!std::isfinite(v[i])) throw py::value_error(std::string(name) + ": expected finite numbers");
        q[i] = v[i];
    }
    return q;
}

void require(bool ok, const std::string& message) {
    if (!ok) throw py::value_error(message);
}

py::array_t<double> array(const std::vector<double>& data, std::vector<py::ssize_t> shape) {
    py::array_t<double> a(shape);
    std::copy(data.begin(), data.end(), a.mutable_data());
    return a;
}

LimitCycleOptions cycle_options(double tol, double rtol, int max_periods, const std::string& solver, long max_rhs) {
    LimitCycleOptions o;
    require(tol > 0, "tol: expected a number > 0");
    require(rtol > 0 && rtol < 1e-2, "rtol: expected a number in (0, 1e-2)");
    require(max_periods >= 2, "max_periods: expected at least 2");
    require(max_rhs >= 1000, "max_rhs: expected at least 1000");
    o.tol = tol;
    o.integration.rtol = rtol;
    o.max_periods = max_periods;
    o.max_rhs_evaluations = max_rhs;
    try {
        o.solver = parse_cycle_solver(solver);
    } catch (const std::invalid_argument& e) {
        throw py::value_error(std::string("solver: ") + e.what());
    }
    return o;
}

// --- results -------------------------------------------------------------------------------------

struct PyStop {
    std::string reason;     // "none", "contact_lost", ... (stop_name)
    int contact = 0;        // 1-based, 0 if none
    double t = 0;
    std::string message;    // StopEvent::describe()
};
PyStop to_py(const StopEvent& e) {
    return {stop_name(e.reason), e.contact + 1, e.t, e.reason == StopReason::None ? "" : e.describe()};
}

struct PyCycle {
    Scene scene;
    Vec3 at;
    LimitCycleSummary lc;
};

struct PyField {
    Scene scene;
    Field f;
};

struct PyTrajectory {
    Scene scene;
    Trajectory tr;
    std::string dynamics;
};

struct PyFixedPoints {
    Scene scene;
    FixedPoints fp;
};

// The field's arrays over its grid: shape (nx, ny, ntheta, 3) (point parts: ntheta = 1).
py::array_t<double> field_array(const Field& f, int what) {
    const GridSpec& g = f.grid;
    std::vector<double> d;
    d.reserve(f.points.size() * 3);
    for (const FieldPoint& p : f.points)
        for (int c = 0; c < 3; ++c) d.push_back(what == 0 ? p.q[c] : what == 1 ? p.twist[c] : p.stick_fraction[c]);
    return array(d, {g.nx, g.ny, g.nth, 3});
}

py::array_t<double> samples_array(const Trajectory& tr, int what) {
    std::vector<double> d;
    for (const Sample& s : tr.samples) {
        const Vec3& v = what == 0 ? s.q : what == 1 ? s.qd : s.n;
        d.insert(d.end(), {v[0], v[1], v[2]});
    }
    return array(d, {static_cast<py::ssize_t>(tr.samples.size()), 3});
}

}  // namespace

PYBIND11_MODULE(_plate, m) {
    m.doc() = "Sliding manipulation on a vibrating 6-DoF plate (Vose, Umbanhowar & Lynch): the compiled core";
    m.attr("__version__") = PLATE_VERSION;
    // Bad scene files and dicts: the message names the source and the field, as the command line's.
    static py::exception<InputError> input_error(m, "InputError", PyExc_ValueError);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const InputError& e) {
            input_error(e.what());
        }
    });

    py::class_<Scene>(m, "Scene", "A part and a periodic plate motion (a scene file's contents).")
        .def_readonly("name", &Scene::name)
        .def_readonly("source", &Scene::source)
        .def_readonly("gravity", &Scene::g)
        .def_property_readonly("point_part", [](const Scene& s) { return s.part.point; })
        .def_property_readonly("thin", [](const Scene& s) { return !s.part.point && s.part.thin(); })
        .def_property_readonly("mass", [](const Scene& s) { return s.part.m; })
        .def_property_readonly("rho", [](const Scene& s) { return s.part.rho(); },
                               "radius of gyration sqrt(J_zz/m) [m] (1 for a point part)")
        .def_property_readonly("period", [](const Scene& s) { return s.plate.T; })
        .def_property_readonly("v_ref", &Scene::v_ref, "the slip-speed scale tolerances are relative to [m/s]")
        .def_property_readonly("warnings", &scene_warnings,
                               "admissible but outside the intended regime (the command line prints them)")
        .def("to_json", [](const Scene& s) { return scene_to_json(s).dump(); }, "the scene in the file form")
        .def("__repr__", [](const Scene& s) {
            return "<plate.Scene '" + s.name + "' " + (s.part.point ? "point part" : s.part.thin() ? "thin part" : "thick part") +
                   ", T = " + std::to_string(s.plate.T) + " s, " + std::to_string(s.plate.harmonics.size()) + " harmonics>";
        });
    m.def("load_scene", &load_scene, py::arg("path"), "Reads a scene file (raises plate.InputError).");
    m.def("parse_scene", &parse_scene, py::arg("text"), py::arg("source"),
          "Reads a scene from JSON text; `source` names it in messages (raises plate.InputError).");

    py::class_<PyStop>(m, "Stop", "Why a run stopped: reason 'none' if it did not.")
        .def_readonly("reason", &PyStop::reason)
        .def_readonly("contact", &PyStop::contact, "1-based; 0 if no contact is concerned")
        .def_readonly("t", &PyStop::t, "[s]")
        .def_readonly("message", &PyStop::message)
        .def("__bool__", [](const PyStop& s) { return s.reason != "none"; })
        .def("__repr__", [](const PyStop& s) { return "<plate.Stop " + s.reason + (s.message.empty() ? "" : ": " + s.message) + ">"; });

    // --- twist ---------------------------------------------------------------------------------
    py::class_<PyCycle>(m, "Cycle", "A limit cycle of the reduced U-dynamics and its asymptotic twist (36).")
        .def_property_readonly("at", [](const PyCycle& c) { return c.at; })
        .def_property_readonly("twist", [](const PyCycle& c) { return c.lc.twist; },
                               "(s_x', s_y', theta') averaged over the cycle [m/s, rad/s]; NaN if undefined")
        .def_property_readonly("converged", [](const PyCycle& c) { return c.lc.converged; })
        .def_property_readonly("periods", [](const PyCycle& c) { return c.lc.periods; })
        .def_property_readonly("residual", [](const PyCycle& c) { return c.lc.residual; })
        .def_property_readonly("error_estimate", [](const PyCycle& c) { return c.lc.error_estimate; })
        .def_property_readonly("contraction", [](const PyCycle& c) { return c.lc.contraction; })
        .def_property_readonly("min_normal_force", [](const PyCycle& c) { return c.lc.min_normal_force; })
        .def_property_readonly("stick_fraction", [](const PyCycle& c) {
            return std::vector<double>(c.lc.stick_fraction.begin(), c.lc.stick_fraction.begin() + c.scene.part.contacts());
        }, "fraction of the cycle's period each contact had zero slip")
        .def_property_readonly("stuck_all_period", [](const PyCycle& c) { return c.lc.stuck_all_period(); })
        .def_property_readonly("mode_sequence", [](const PyCycle& c) {
            std::vector<std::pair<double, std::string>> s;
            if (c.lc.converged) {
                s.emplace_back(0.0, mode_name(c.lc.start_mode));
                for (const ModeEvent& e : c.lc.mode_events) s.emplace_back(e.t, mode_name(e.to));
            }
            return s;
        }, "(t from the period's start, mode entered) over the cycle's last period")
        .def_property_readonly("monodromy", [](const PyCycle& c) -> std::optional<Mat3> {
            if (!c.lc.has_monodromy) return std::nullopt;
            return c.lc.monodromy;
        }, "dP/dx in the scaled twist (shooting solver), or None")
        .def_property_readonly("rhs_evaluations", [](const PyCycle& c) { return c.lc.stats.rhs_evals; })
        .def_property_readonly("stop", [](const PyCycle& c) { return to_py(c.lc.stop); })
        .def_property_readonly("summary", [](const PyCycle& c) { return json_to_python(to_json(c.scene, c.at, c.lc)); },
                               "the command line's JSON (`plate twist`) as a dict")
        .def("report", [](const PyCycle& c) { return c.lc.report(); })
        .def("__repr__", [](const PyCycle& c) {
            return "<plate.Cycle converged=" + std::string(c.lc.converged ? "True" : "False") + " periods=" +
                   std::to_string(c.lc.periods) + ">";
        });
    m.def("twist",
          [](const Scene& sc, const std::vector<double>& at, std::optional<std::vector<double>> start, double tol,
             double rtol, int max_periods, const std::string& solver, long max_rhs) {
              PyCycle c{sc, config(sc, at, "at"), {}};
              const Vec3 qd0 = start ? config(sc, *start, "start") : Vec3::Zero();
              const LimitCycleOptions o = cycle_options(tol, rtol, max_periods, solver, max_rhs);
              py::gil_scoped_release free;
              c.lc = limit_cycle(sc, c.at, o, qd0);
              return c;
          },
          py::arg("scene"), py::arg("at"), py::kw_only(), py::arg("start") = py::none(), py::arg("tol") = 1e-7,
          py::arg("rtol") = 1e-8, py::arg("max_periods") = 400, py::arg("solver") = "shooting",
          py::arg("max_rhs") = 20'000'000L,
          "The asymptotic twist (36) at configuration `at` = (s_x, s_y, theta) (point part: (s_x, s_y)): the\n"
          "limit cycle of the reduced U-dynamics from the twist `start` (default: at rest on the plate).");

    // --- field ---------------------------------------------------------------------------------
    py::class_<PyField>(m, "Field", "The asymptotic twist field on a grid (point parts: velocity field, ntheta = 1).")
        .def_property_readonly("x", [](const PyField& f) {
            std::vector<double> v;
            for (int i = 0; i < f.f.grid.nx; ++i) v.push_back(f.f.grid.at(i, 0, 0)[0]);
            return array(v, {f.f.grid.nx});
        })
        .def_property_readonly("y", [](const PyField& f) {
            std::vector<double> v;
            for (int j = 0; j < f.f.grid.ny; ++j) v.push_back(f.f.grid.at(0, j, 0)[1]);
            return array(v, {f.f.grid.ny});
        })
        .def_property_readonly("theta", [](const PyField& f) {
            std::vector<double> v;
            for (int k = 0; k < f.f.grid.nth; ++k) v.push_back(f.f.grid.at(0, 0, k)[2]);
            return array(v, {f.f.grid.nth});
        })
        .def_property_readonly("q", [](const PyField& f) { return field_array(f.f, 0); },
                               "configurations, shape (nx, ny, ntheta, 3)")
        .def_property_readonly("twist", [](const PyField& f) { return field_array(f.f, 1); },
                               "asymptotic twists, shape (nx, ny, ntheta, 3); NaN where undefined")
        .def_property_readonly("stick_fraction", [](const PyField& f) { return field_array(f.f, 2); },
                               "per contact, shape (nx, ny, ntheta, 3)")
        .def_property_readonly("converged", [](const PyField& f) {
            py::array_t<bool> a({f.f.grid.nx, f.f.grid.ny, f.f.grid.nth});
            for (std::size_t i = 0; i < f.f.points.size(); ++i) a.mutable_data()[i] = f.f.points[i].converged;
            return a;
        })
        .def_property_readonly("stops", [](const PyField& f) {
            std::vector<std::string> s;
            for (const FieldPoint& p : f.f.points) s.push_back(stop_name(p.stop));
            return s;
        }, "why each configuration has no twist ('none' where it has), grid order")
        .def_property_readonly("seconds", [](const PyField& f) { return f.f.seconds; })
        .def_property_readonly("rhs_evaluations", [](const PyField& f) { return f.f.rhs_evals; })
        .def_property_readonly("threads", [](const PyField& f) { return f.f.threads; })
        .def_property_readonly("summary", [](const PyField& f) { return json_to_python(to_json(f.scene, f.f)); },
                               "the command line's JSON (`plate field`) as a dict");
    m.def("field",
          [](const Scene& sc, int grid, std::optional<int> nx, std::optional<int> ny, std::optional<int> ntheta,
             std::pair<double, double> x, std::pair<double, double> y, double theta0, int threads, double tol,
             double rtol, int max_periods, const std::string& solver, long max_rhs, long max_work) {
              GridSpec g;
              g.nx = nx.value_or(grid);
              g.ny = ny.value_or(grid);
              g.nth = sc.part.point ? 1 : ntheta.value_or(grid);
              require(g.nx >= 1 && g.ny >= 1 && g.nth >= 1 && g.nx <= 201 && g.ny <= 201 && g.nth <= 720,
                      "grid: expected 1..201 points along x and y and 1..720 along theta");
              require(std::isfinite(x.first) && std::isfinite(x.second) && x.second >= x.first,
                      "x: expected (MIN, MAX) with MIN <= MAX");
              require(std::isfinite(y.first) && std::isfinite(y.second) && y.second >= y.first,
                      "y: expected (MIN, MAX) with MIN <= MAX");
              require(threads >= 0, "threads: expected >= 0 (0: all cores)");
              require(max_work >= 0, "max_work: expected >= 0 (0: no budget)");
              std::tie(g.x0, g.x1) = x;
              std::tie(g.y0, g.y1) = y;
              g.th0 = theta0;
              FieldOptions o;
              o.cycle = cycle_options(tol, rtol, max_periods, solver, max_rhs);
              o.threads = threads;
              o.max_rhs_evaluations = max_work;
              PyField f{sc, {}};
              {
                  py::gil_scoped_release free;
                  f.f = compute_field(sc, g, o);
              }
              if (f.f.budget_spent)
                  throw std::runtime_error("the work budget of max_work = " + std::to_string(max_work) +
                                           " right-hand sides was spent before the field was complete");
              return f;
          },
          py::arg("scene"), py::kw_only(), py::arg("grid") = 7, py::arg("nx") = py::none(), py::arg("ny") = py::none(),
          py::arg("ntheta") = py::none(), py::arg("x") = std::make_pair(-0.05, 0.05),
          py::arg("y") = std::make_pair(-0.05, 0.05), py::arg("theta0") = 0.0, py::arg("threads") = 0,
          py::arg("tol") = 1e-7, py::arg("rtol") = 1e-8, py::arg("max_periods") = 400, py::arg("solver") = "shooting",
          py::arg("max_rhs") = 20'000'000L, py::arg("max_work") = 0L,
          "The asymptotic twist field on a regular grid over (s_x, s_y, theta), theta covering a full turn;\n"
          "configurations in parallel on `threads` cores (0: all). max_work: a budget in right-hand sides\n"
          "for the whole field (0: none); a field that spends it raises RuntimeError.");

    // --- fixed points --------------------------------------------------------------------------
    py::class_<FixedPoint>(m, "FixedPoint")
        .def_readonly("q", &FixedPoint::q, "(s_x, s_y, theta), theta in (-pi, pi]")
        .def_readonly("eigenvalues", &FixedPoint::eigenvalues, "of the field's Jacobian (point part: the first 2)")
        .def_property_readonly("stability", [](const FixedPoint& p) { return stability_name(p.stability); })
        .def_readonly("residual", &FixedPoint::residual)
        .def("__repr__", [](const FixedPoint& p) {
            return "<plate.FixedPoint " + std::string(stability_name(p.stability)) + " at (" + std::to_string(p.q[0]) +
                   ", " + std::to_string(p.q[1]) + ", " + std::to_string(p.q[2]) + ")>";
        });
    py::class_<FixedLine>(m, "FixedLine")
        .def_property_readonly("points", [](const FixedLine& l) { return l.points; })
        .def_readonly("direction", &FixedLine::direction)
        .def_property_readonly("stability", [](const FixedLine& l) { return stability_name(l.stability); })
        .def_readonly("eigenvalues", &FixedLine::eigenvalues)
        .def_readonly("length", &FixedLine::length);
    py::class_<PyFixedPoints>(m, "FixedPoints")
        .def_property_readonly("points", [](const PyFixedPoints& f) { return f.fp.points; })
        .def_property_readonly("lines", [](const PyFixedPoints& f) { return f.fp.lines; })
        .def_property_readonly("sentence", [](const PyFixedPoints& f) { return fixed_points_sentence(f.fp); })
        .def_property_readonly("undefined_cells", [](const PyFixedPoints& f) { return f.fp.undefined_cells; })
        .def_property_readonly("stuck_cells", [](const PyFixedPoints& f) { return f.fp.stuck_cells; })
        .def_property_readonly("summary", [](const PyFixedPoints& f) { return json_to_python(to_json(f.scene, f.fp)); },
                               "the command line's JSON (`plate fixed-points`) as a dict");
    m.def("fixed_points",
          [](const PyField& f, double ftol, long max_rhs) {
              FixedPointOptions o;
              require(ftol > 0, "ftol: expected a number > 0");
              require(max_rhs >= 0, "max_rhs: expected >= 0 (0: no budget)");
              o.ftol = ftol;
              o.max_rhs_evaluations = max_rhs;
              PyFixedPoints r{f.scene, {}};
              py::gil_scoped_release free;
              r.fp = find_fixed_points(f.scene, f.f, o);
              return r;
          },
          py::arg("field"), py::kw_only(), py::arg("ftol") = 1e-6, py::arg("max_rhs") = 20'000'000L,
          "Zeros of a field (from plate.field): candidate cells refined by Gauss-Newton, classified by the\n"
          "Jacobian's eigenvalues; curves of zeros as lines.");

    // --- design --------------------------------------------------------------------------------
    py::class_<DesignSummary>(m, "Design", "A designed plate motion and its verification (plate.design).")
        .def_readonly("verified", &DesignSummary::verified)
        .def_readonly("unique", &DesignSummary::unique)
        .def_readonly("failure", &DesignSummary::failure)
        .def_readonly("scene", &DesignSummary::scene)
        .def_readonly("rate", &DesignSummary::rate, "convergence rate at the target, -max Re(eigenvalues) [1/s]")
        .def_readonly("eigenvalues", &DesignSummary::eigenvalues)
        .def_readonly("fixed_point", &DesignSummary::fixed_point)
        .def_readonly("starts", &DesignSummary::starts)
        .def_readonly("evaluations", &DesignSummary::evaluations)
        .def_readonly("cycles", &DesignSummary::cycles)
        .def_readonly("worst_end_distance", &DesignSummary::worst_end_distance,
                      "of the full-dynamics runs from random starts [m]")
        .def_readonly("min_vertical_margin", &DesignSummary::min_vertical_margin)
        .def_readonly("seconds", &DesignSummary::seconds)
        .def_readonly("notes", &DesignSummary::notes)
        .def_readonly("transport_mean", &DesignSummary::transport_mean)
        .def_readonly("transport_spread", &DesignSummary::transport_spread)
        .def_property_readonly("ring", [](const DesignSummary& s) {
            std::vector<std::tuple<double, Vec3>> r;
            for (std::size_t k = 0; k < s.ring_theta.size(); ++k) r.emplace_back(s.ring_theta[k], s.ring_twist[k]);
            return r;
        }, "orient by transport: (theta, twist) at the centre on the verification's ring of orientations")
        .def_readonly("basin_share", &DesignSummary::basin_share,
                      "rigid parts: the share of the verification runs that end at the target")
        .def_readonly("basin_share_bound", &DesignSummary::basin_share_bound,
                      "the largest share the design's symmetry allows (a half-turn pair: below 1)")
        .def_property_readonly("competitors", [](const DesignSummary& s) {
            std::vector<std::tuple<Vec3, double>> r;
            for (const auto& c : s.competitors) r.emplace_back(c.point.q, c.basin_share);
            return r;
        }, "rigid parts: the other stable fixed points on the grid, (q, share of the runs ending there)")
        .def_property_readonly("runs", [](const DesignSummary& s) {
            std::vector<std::tuple<double, double, double, double>> r;
            for (const DesignStartRun& x : s.runs) r.emplace_back(x.x, x.y, x.seconds, x.end_distance);
            return r;
        }, "(x, y, seconds, end distance) of each verification run")
        .def_property_readonly("held", [](const DesignSummary& s) {
            return std::make_tuple(s.held.seconds, s.held.end, s.held.end_distance);
        }, "sinks and fixed points: (seconds, end, distance) of the part released at rest at the target")
        .def_readonly("coning", &DesignSummary::coning, "the design's coning rate [rad/s] (plate.coning_rate)")
        .def_property_readonly("pulls", [](const DesignSummary& s) {
            std::vector<std::tuple<double, Vec2, Eigen::Vector2cd>> r;
            for (const auto& p : s.pulls) r.emplace_back(p.theta, p.zero, p.eigenvalues);
            return r;
        }, "a rigid part's sink: (theta, where the position's field vanishes, its eigenvalues) per orientation");
    m.def("design",
          [](const Scene& part, std::optional<std::pair<double, double>> sink,
             std::optional<std::pair<double, double>> transport, std::optional<std::tuple<double, double, double>> fixed_point,
             std::optional<double> orient, std::optional<std::tuple<double, double, double>> line_sink,
             double lin_limit, double ang_limit, double period,
             std::uint64_t seed, int starts, int local_evaluations, int verify_starts, int threads, double hold,
             double max_coning, std::vector<std::string> axes, int max_harmonic) {
              require(sink.has_value() + transport.has_value() + fixed_point.has_value() + orient.has_value() +
                                  line_sink.has_value() == 1,
                      "design: give one target, sink=(x, y), transport=(vx, vy), fixed_point=(x, y, theta), orient=theta "
                      "or line_sink=(x, y, phi)");
              DesignTarget t;
              if (sink) t.at = Vec2(sink->first, sink->second);
              if (transport) {
                  t.kind = DesignTargetKind::Transport;
                  t.velocity = Vec2(transport->first, transport->second);
              }
              if (fixed_point) {
                  t.kind = DesignTargetKind::FixedPoint;
                  t.at = Vec2(std::get<0>(*fixed_point), std::get<1>(*fixed_point));
                  t.theta = std::get<2>(*fixed_point);
              }
              if (orient) {
                  t.kind = DesignTargetKind::Orient;
                  t.theta = *orient;
              }
              if (line_sink) {
                  t.kind = DesignTargetKind::LineSink;
                  t.at = Vec2(std::get<0>(*line_sink), std::get<1>(*line_sink));
                  t.theta = std::get<2>(*line_sink);
              }
              DesignOptions o;
              require(lin_limit >= 0 && ang_limit >= 0, "limits: expected amplitudes >= 0");
              require(starts >= 0 && local_evaluations >= 1 && verify_starts >= 1,
                      "starts: expected >= 0 (0: the target's default); local_evaluations, verify_starts: expected >= 1");
              o.lin_limit = lin_limit;
              o.ang_limit = ang_limit;
              o.period = period;
              o.seed = seed;
              o.starts = starts;
              o.local_evaluations = local_evaluations;
              o.verify_starts = verify_starts;
              o.threads = threads;
              require(hold >= 0, "hold: expected seconds >= 0 (0: not checked)");
              o.hold = hold;
              o.max_coning = max_coning;
              for (const std::string& name : axes) {
                  int k = 0;
                  while (k < 6 && name != axis_name(static_cast<Axis>(k))) ++k;
                  require(k < 6, "axes: expected names among x, y, z, rx, ry, rz, got '" + name + "'");
                  o.axes.push_back(static_cast<Axis>(k));
              }
              require(max_harmonic >= 0, "max_harmonic: expected >= 0 (0: the target's own)");
              o.max_harmonic = max_harmonic;
              py::gil_scoped_release free;
              try {
                  return design(part, t, o);
              } catch (const std::invalid_argument& e) {
                  py::gil_scoped_acquire hold;
                  throw py::value_error(e.what());
              }
          },
          py::arg("part"), py::kw_only(), py::arg("sink") = py::none(), py::arg("transport") = py::none(),
          py::arg("fixed_point") = py::none(), py::arg("orient") = py::none(), py::arg("line_sink") = py::none(),
          py::arg("lin_limit") = 20.0, py::arg("ang_limit") = 150.0,
          py::arg("period") = 0.0, py::arg("seed") = 1, py::arg("starts") = 0, py::arg("local_evaluations") = 400,
          py::arg("verify_starts") = 20, py::arg("threads") = 0, py::arg("hold") = 120.0, py::arg("max_coning") = -1.0,
          py::arg("axes") = std::vector<std::string>{}, py::arg("max_harmonic") = 0,
          "Designs a plate motion within the amplitude limits and without flight, and verifies it (grid and\n"
          "full dynamics; sinks and fixed points also by a part released at the target staying within 5 mm\n"
          "for `hold` seconds, which limits a sink's coning unless max_coning >= 0 sets it [rad/s]).\n"
          "sink=(x, y) for a rigid part: its position ends at\n"
          "(x, y) whatever its orientation (`pulls`). Point parts: sink=(x, y) the unique stable fixed point of its field,\n"
          "line_sink=(x, y, phi) every start ends on the line through (x, y) along phi, or\n"
          "transport=(vx, vy) a uniform velocity over the plate (also a rigid part with one friction coefficient). Rigid parts: orient=theta for a part whose\n"
          "contacts' friction differs (a plate that only translates turns it like a weathervane; `ring` gives\n"
          "theta' over a turn); fixed_point=(x, y, theta), and orient for one friction coefficient: the summary\n"
          "gives the basin share and the competing fixed points (where no unique fixed point is found, a half-turn\n"
          "pair: theta and theta + pi both stable, unique False; see the README). axes=['x', ...] and\n"
          "max_harmonic=n narrow each target's motion family (the others stay zero; an empty family is a ValueError).");
    m.def(
        "orientation_harmonics",
        [](const Scene& sc, std::array<double, 2> at, int n, double tol, double rtol) {
            require(n >= 4, "n: expected at least 4 orientations");
            const OrientationHarmonics h =
                orientation_harmonics(sc, Vec2(at[0], at[1]), cycle_options(tol, rtol, 400, "shooting", 20'000'000), n);
            py::dict d;
            d["defined"] = h.defined;
            d["mean"] = h.mean;
            d["amplitude"] = h.amplitude;
            d["first"] = h.first();
            d["rest"] = h.rest();
            d["one_stable"] = h.one_stable();
            return d;
        },
        py::arg("scene"), py::arg("at") = std::array<double, 2>{0, 0}, py::arg("n") = 12, py::arg("tol") = 1e-7,
        py::arg("rtol") = 1e-8,
        "theta' at position `at` on n orientations as M + sum_k B_k sin(k theta + phi_k): {defined, mean (M),\n"
        "amplitude (B_0 = |M|, B_1 .. B_n/2), first (B_1), rest (|M| + B_2 + ...), one_stable (B_1^2 > rest^2 +\n"
        "(sum_k>=2 k B_k)^2: exactly one stable orientation)} [rad/s]; what one orientation needs (design.hpp).");
    m.def("coning_rate", [](const Scene& sc) { return coning_rate(sc.plate); }, py::arg("scene"),
          "The plate's steady yaw drift from rx and ry out of phase [rad/s], which the asymptotic field does\n"
          "not see and the full dynamics does: sum_n Im(A_rx,n conj A_ry,n) / (2 (n w)^3).");

    // --- simulate ------------------------------------------------------------------------------
    py::class_<PyTrajectory>(m, "Trajectory", "Samples of a simulation, with the contact mode on each step.")
        .def_property_readonly("t", [](const PyTrajectory& p) {
            std::vector<double> t;
            for (const Sample& s : p.tr.samples) t.push_back(s.t);
            return array(t, {static_cast<py::ssize_t>(t.size())});
        })
        .def_property_readonly("q", [](const PyTrajectory& p) { return samples_array(p.tr, 0); }, "(n, 3): s_x, s_y, theta")
        .def_property_readonly("qd", [](const PyTrajectory& p) { return samples_array(p.tr, 1); },
                               "(n, 3): the part's twist relative to the plate")
        .def_property_readonly("normal_forces", [](const PyTrajectory& p) { return samples_array(p.tr, 2); }, "(n, 3) [N]")
        .def_property_readonly("mode", [](const PyTrajectory& p) {
            std::vector<std::string> m;
            for (const Sample& s : p.tr.samples) m.push_back(mode_name(s.mode));
            return m;
        }, "the contact mode on the step that ended at each sample: slide, pivot1-3, stuck")
        .def_property_readonly("events", [](const PyTrajectory& p) {
            std::vector<std::tuple<double, std::string, std::string>> e;
            for (const ModeEvent& ev : p.tr.events) e.emplace_back(ev.t, mode_name(ev.from), mode_name(ev.to));
            return e;
        }, "every change of contact mode: (t, from, to)")
        .def_property_readonly("held_time", [](const PyTrajectory& p) {
            return std::vector<double>(p.tr.held_time.begin(), p.tr.held_time.begin() + p.scene.part.contacts());
        }, "time each contact had zero slip [s]")
        .def_property_readonly("stop", [](const PyTrajectory& p) { return to_py(p.tr.stop); })
        .def_property_readonly("steps", [](const PyTrajectory& p) { return p.tr.stats.steps; })
        .def_property_readonly("dynamics", [](const PyTrajectory& p) { return p.dynamics; });
    m.def("simulate",
          [](const Scene& sc, const std::vector<double>& start, double time, const std::string& dynamics,
             std::optional<std::vector<double>> twist, std::optional<double> sample, double rtol, long max_steps,
             double tol) {
              require(dynamics == "full" || dynamics == "u" || dynamics == "field",
                      "dynamics: expected 'full', 'u' or 'field', got '" + dynamics + "'");
              const Vec3 q0 = config(sc, start, "start");
              const Vec3 qd0 = twist ? config(sc, *twist, "twist") : Vec3::Zero();
              const double dt = sample.value_or(sc.plate.T / 4);
              require(std::isfinite(time) && time > 0, "time: expected a number > 0");
              require(std::isfinite(dt) && dt > 0, "sample: expected a number > 0");
              require(std::ceil(time / dt) + 1 <= 1e7, "time / sample: more than 10^7 rows; sample less often");
              require(rtol > 0 && rtol < 1e-2, "rtol: expected a number in (0, 1e-2)");
              require(max_steps >= 1, "max_steps: expected >= 1");
              require(dynamics != "field" || qd0.isZero(), "twist: has no meaning for dynamics='field'");
              PyTrajectory p{sc, {}, dynamics};
              py::gil_scoped_release free;
              if (dynamics == "field") {
                  LimitCycleOptions lo;
                  lo.tol = tol;
                  p.tr = field_curve(sc, q0, time, dt, lo);
              } else {
                  IntegrationOptions io;
                  io.rtol = rtol;
                  io.max_steps = max_steps;
                  p.tr = simulate(sc, dynamics == "full" ? Dynamics::Full : Dynamics::U, q0, qd0, time, dt, io);
              }
              return p;
          },
          py::arg("scene"), py::arg("start"), py::arg("time"), py::kw_only(), py::arg("dynamics") = "full",
          py::arg("twist") = py::none(), py::arg("sample") = py::none(), py::arg("rtol") = 1e-9,
          py::arg("max_steps") = 20'000'000L, py::arg("tol") = 1e-7,
          "A trajectory from configuration `start` with the part's twist `twist` relative to the plate (default:\n"
          "at rest) for `time` seconds, sampled every `sample` (default T/4): 'full' dynamics (31), 'u'\n"
          "U-dynamics (32) or the 'field' integral curve. Stick-slip is simulated through. A run that leaves\n"
          "the model (a normal force reaches zero) ends there: trajectory.stop says when and which contact.");
}
