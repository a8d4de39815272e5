// plate.twist: a limit cycle of the reduced U-dynamics and its asymptotic twist (plate.Cycle).
#include "bindings.hpp"
#include "interrupt.hpp"

#include <algorithm>

namespace plate::python {

namespace {

struct PyCycle {
    Scene scene;
    Vec3 at;
    LimitCycleSummary lc;
};

// Pickled state: the scene, the configuration and every field of the summary (path and transients
// included), numbers as Python floats (doubles: back to the bit).
py::tuple cycle_state(const PyCycle& c) {
    const LimitCycleSummary& l = c.lc;
    py::list events, path, transient;
    for (const ModeEvent& e : l.mode_events) events.append(event_state(e));
    for (const Sample& s : l.path) path.append(sample_state(s));
    for (const StopEvent& e : l.transient_stops) transient.append(stop_state(e));
    std::vector<double> mono(l.monodromy.data(), l.monodromy.data() + 9);
    return py::make_tuple(
        c.scene, std::vector<double>{c.at[0], c.at[1], c.at[2]},
        py::make_tuple(l.converged, l.periods, l.residual, l.error_estimate, l.contraction, l.twist[0], l.twist[1], l.twist[2],
                       l.qd_start[0], l.qd_start[1], l.qd_start[2], l.has_monodromy, mono, l.min_normal_force, l.step_hint),
        py::make_tuple(l.stick_fraction[0], l.stick_fraction[1], l.stick_fraction[2]), mode_state(l.start_mode), events,
        stop_state(l.stop), stats_state(l.stats), l.restarts, transient, path, l.note);
}
PyCycle cycle_of(const py::tuple& t) {
    require(t.size() == 12, "plate.Cycle: not a pickled cycle");
    PyCycle c{t[0].cast<Scene>(), Vec3::Zero(), {}};
    const auto at = t[1].cast<std::vector<double>>();
    require(at.size() == 3, "plate.Cycle: a pickled configuration has 3 numbers");
    c.at = Vec3(at[0], at[1], at[2]);
    LimitCycleSummary& l = c.lc;
    const auto v = t[2].cast<py::tuple>();
    l.converged = v[0].cast<bool>();
    l.periods = v[1].cast<int>();
    l.residual = v[2].cast<double>();
    l.error_estimate = v[3].cast<double>();
    l.contraction = v[4].cast<double>();
    l.twist = Vec3(v[5].cast<double>(), v[6].cast<double>(), v[7].cast<double>());
    l.qd_start = Vec3(v[8].cast<double>(), v[9].cast<double>(), v[10].cast<double>());
    l.has_monodromy = v[11].cast<bool>();
    const auto mono = v[12].cast<std::vector<double>>();
    require(mono.size() == 9, "plate.Cycle: a pickled monodromy has 9 numbers");
    std::copy(mono.begin(), mono.end(), l.monodromy.data());
    l.min_normal_force = v[13].cast<double>();
    l.step_hint = v[14].cast<double>();
    const auto sf = t[3].cast<py::tuple>();
    for (std::size_t i = 0; i < 3; ++i) l.stick_fraction[i] = sf[i].cast<double>();
    l.start_mode = mode_of(t[4]);
    for (const py::handle& h : t[5].cast<py::list>()) l.mode_events.push_back(event_of(h));
    l.stop = stop_of(t[6]);
    l.stats = stats_of(t[7]);
    l.restarts = t[8].cast<int>();
    for (const py::handle& h : t[9].cast<py::list>()) l.transient_stops.push_back(stop_of(h));
    for (const py::handle& h : t[10].cast<py::list>()) l.path.push_back(sample_of(h));
    l.note = t[11].cast<std::string>();
    return c;
}

}   // namespace

void bind_twist(py::module_& m) {
    py::class_<PyCycle>(m, "Cycle", "A limit cycle of the reduced U-dynamics and its asymptotic twist (36).")
        .def(py::pickle(&cycle_state, &cycle_of))
        .def_property_readonly("at", [](const PyCycle& c) { return c.at; })
        .def_property_readonly(
            "twist", [](const PyCycle& c) { return c.lc.twist; },
            "(s_x', s_y', theta') averaged over the cycle [m/s, rad/s]; NaN if undefined")
        .def_property_readonly("converged", [](const PyCycle& c) { return c.lc.converged; })
        .def_property_readonly("periods", [](const PyCycle& c) { return c.lc.periods; })
        .def_property_readonly("residual", [](const PyCycle& c) { return c.lc.residual; })
        .def_property_readonly("error_estimate", [](const PyCycle& c) { return c.lc.error_estimate; })
        .def_property_readonly("contraction", [](const PyCycle& c) { return c.lc.contraction; })
        .def_property_readonly("min_normal_force", [](const PyCycle& c) { return c.lc.min_normal_force; })
        .def_property_readonly(
            "stick_fraction",
            [](const PyCycle& c) {
                return std::vector<double>(c.lc.stick_fraction.begin(), c.lc.stick_fraction.begin() + c.scene.part.contacts());
            },
            "fraction of the cycle's period each contact had zero slip")
        .def_property_readonly("stuck_all_period", [](const PyCycle& c) { return c.lc.stuck_all_period(); })
        .def_property_readonly(
            "mode_sequence",
            [](const PyCycle& c) {
                std::vector<std::pair<double, std::string>> s;
                if (c.lc.converged) {
                    s.emplace_back(0.0, mode_name(c.lc.start_mode));
                    for (const ModeEvent& e : c.lc.mode_events) s.emplace_back(e.t, mode_name(e.to));
                }
                return s;
            },
            "(t from the period's start, mode entered) over the cycle's last period")
        .def_property_readonly(
            "monodromy",
            [](const PyCycle& c) -> std::optional<Mat3> {
                if (!c.lc.has_monodromy) return std::nullopt;
                return c.lc.monodromy;
            },
            "dP/dx in the scaled twist (shooting solver), or None")
        .def_property_readonly("rhs_evaluations", [](const PyCycle& c) { return c.lc.stats.rhs_evals; })
        .def_property_readonly("stop", [](const PyCycle& c) { return to_py(c.lc.stop); })
        .def_property_readonly(
            "summary", [](const PyCycle& c) { return json_to_python(to_json(c.scene, c.at, c.lc)); },
            "the command line's JSON (`plate twist`) as a dict")
        .def("report", [](const PyCycle& c) { return c.lc.report(); })
        .def("__repr__", [](const PyCycle& c) {
            return "<plate.Cycle converged=" + std::string(c.lc.converged ? "True" : "False") +
                   " periods=" + std::to_string(c.lc.periods) + ">";
        });
    m.def(
        "twist",
        [](const Scene& sc, const std::vector<double>& at, std::optional<std::vector<double>> twist, double tol, double rtol,
           int max_periods, const std::string& solver, long max_rhs, std::optional<std::vector<double>> start) {
            PyCycle c{sc, config(sc, at, "at"), {}};
            const std::vector<double> qd = renamed<std::vector<double>>(twist, start, "twist", "start", {});
            const Vec3 qd0 = twist || start ? config(sc, qd, "twist") : Vec3::Zero();
            const LimitCycleOptions o = cycle_options(tol, rtol, max_periods, solver, max_rhs);
            c.lc = interruptible(py::none(), [&](Watch&) { return limit_cycle(sc, c.at, o, qd0); });
            return c;
        },
        py::arg("scene"), py::arg("at"), py::kw_only(), py::arg("twist") = py::none(), py::arg("tol") = 1e-7,
        py::arg("rtol") = 1e-8, py::arg("max_periods") = 400, py::arg("solver") = "shooting", py::arg("max_rhs") = 20'000'000L,
        py::arg("start") = py::none(),
        "The asymptotic twist (36) at configuration `at` = (s_x, s_y, theta) (point part: (s_x, s_y)): the\n"
        "limit cycle of the reduced U-dynamics from the part's twist `twist` relative to the plate (default:\n"
        "at rest on the plate). `start` is twist's old spelling (deprecated: a start is a configuration in\n"
        "plate.simulate and plate.observe).");
}

}   // namespace plate::python
