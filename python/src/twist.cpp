// plate.twist: a limit cycle of the reduced U-dynamics and its asymptotic twist (plate.Cycle).
#include "bindings.hpp"
#include "interrupt.hpp"

namespace plate::python {

namespace {

struct PyCycle {
    Scene scene;
    Vec3 at;
    LimitCycleSummary lc;
};

}   // namespace

void bind_twist(py::module_& m) {
    py::class_<PyCycle>(m, "Cycle", "A limit cycle of the reduced U-dynamics and its asymptotic twist (36).")
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
