// plate.robustness (outcome shares, the fixed point's spread and its sensitivities under an uncertainty
// spec: plate.Robustness) and plate.uncertain_parameters (the spec's parameters, in draw order).
#include "bindings.hpp"
#include "interrupt.hpp"
#include "pickling.hpp"

#include "plate/robustness.hpp"

#include <cmath>
#include <limits>

namespace plate::python {

namespace {

struct PyRobustness {
    RobustnessSummary s;
    RobustnessOptions o;
    UncertaintySpec spec;
};

}   // namespace

namespace pickling {
void io(Archive& a, PyRobustness& r) { a(r.s, r.o, r.spec); }
}   // namespace pickling

namespace {

// A spec from a path (str) or a dict in the file's form (checked as a file is: plate.InputError).
UncertaintySpec spec_of(const py::object& u) {
    if (py::isinstance<py::str>(u)) return load_uncertainty(u.cast<std::string>());
    require(py::isinstance<py::dict>(u), "uncertainty: expected a spec file's path or a dict in its form");
    const std::string text = py::module_::import("json").attr("dumps")(u).cast<std::string>();
    return parse_uncertainty(text, "<dict>");
}

}   // namespace

void bind_robustness(py::module_& m) {
    py::class_<PyRobustness> cls(
        m, "Robustness",
        "Where the part goes on the plates a real rig may be (plate robustness): per draw an outcome, the "
        "target's fixed point, arrival times; the spread and its first-order prediction.");
    cls.def(pickling::pickle_as<PyRobustness>("plate.Robustness"));
    cls.def("__repr__", [](const PyRobustness& r) {
        const int n = static_cast<int>(r.s.draws.size());
        std::string shares;
        for (int c = 0; c < kOutcomes; ++c)
            if (r.s.counts[c] > 0)
                shares += std::string(shares.empty() ? "" : ", ") + outcome_name(static_cast<Outcome>(c)) + " " +
                          num(double(r.s.counts[c]) / n, 3);
        return "<plate.Robustness " + std::to_string(n) + " draws: " + shares + "; radius95 " + num(r.s.radius95) + " m>";
    });
    cls.def_property_readonly(
           "outcomes",
           [](const PyRobustness& r) {
               py::dict d;
               const int n = static_cast<int>(r.s.draws.size());
               for (int k = 0; k < kOutcomes; ++k) d[outcome_name(static_cast<Outcome>(k))] = double(r.s.counts[k]) / n;
               return d;
           },
           "each outcome's share of the draws (unique, competing, none, contact lost, failed)")
        .def_property_readonly(
            "outcome",
            [](const PyRobustness& r) {
                std::vector<std::string> v;
                for (const DrawResult& d : r.s.draws) v.push_back(outcome_name(d.outcome));
                return v;
            },
            "each draw's outcome, in draw order")
        .def_property_readonly(
            "fixed_points",
            [](const PyRobustness& r) {
                std::vector<double> v;
                for (const DrawResult& d : r.s.draws)
                    for (int c = 0; c < 3; ++c)
                        v.push_back(d.matched ? d.fixed_point[c] : std::numeric_limits<double>::quiet_NaN());
                return array(v, {static_cast<py::ssize_t>(r.s.draws.size()), 3});
            },
            "the target's fixed point per draw, shape (draws, 3) [m, m, rad]; NaN rows where it has none")
        .def_property_readonly(
            "deviations",
            [](const PyRobustness& r) {
                std::vector<double> v;
                for (const DrawResult& d : r.s.draws) v.insert(v.end(), d.p.begin(), d.p.end());
                const auto n = static_cast<py::ssize_t>(r.s.draws.size());
                return array(v, {n, n ? static_cast<py::ssize_t>(v.size()) / n : 0});
            },
            "each draw's deviations p, shape (draws, parameters) (plate.uncertain_parameters' order)")
        .def_property_readonly(
            "sensitivities",
            [](const PyRobustness& r) {
                std::vector<double> v;
                for (const Sensitivity& s : r.s.sensitivities)
                    for (int c = 0; c < 3; ++c) v.push_back(s.dq[c]);
                return array(v, {static_cast<py::ssize_t>(r.s.sensitivities.size()), 3});
            },
            "d q* / d p per parameter, shape (parameters, 3) (zero rows for a zero spread; empty if not computed)")
        .def_property_readonly(
            "radius95", [](const PyRobustness& r) { return r.s.radius95; }, "[m]")
        .def_property_readonly(
            "angle95", [](const PyRobustness& r) { return r.s.angle95; }, "[rad]")
        .def_property_readonly(
            "predicted_radius95", [](const PyRobustness& r) { return r.s.predicted_radius95; }, "[m]")
        .def_property_readonly(
            "predicted_angle95", [](const PyRobustness& r) { return r.s.predicted_angle95; }, "[rad]")
        .def_property_readonly("covariance", [](const PyRobustness& r) { return Eigen::Matrix3d(r.s.covariance); })
        .def_property_readonly("predicted_covariance",
                               [](const PyRobustness& r) { return Eigen::Matrix3d(r.s.predicted_covariance); })
        .def_property_readonly("target", [](const PyRobustness& r) { return r.s.target; })
        .def_property_readonly("seconds", [](const PyRobustness& r) { return r.s.seconds; })
        .def_property_readonly(
            "summary", [](const PyRobustness& r) { return json_to_python(robustness_json(r.s, r.o, r.spec)); },
            "the command line's JSON (`plate robustness`) as a dict");
    m.def(
        "robustness",
        [](const Scene& sc, const py::object& uncertainty, int draws, std::optional<std::vector<double>> target, int grid,
           int starts, double horizon, int full_draws, bool sensitivities, int threads, double tol, double rtol, int max_periods,
           const std::string& solver, long max_rhs, const py::object& progress) {
            require(draws >= 1 && starts >= 0 && full_draws >= 0, "draws >= 1, starts >= 0 and full_draws >= 0 expected");
            require(std::isfinite(horizon) && horizon > 0, "horizon: expected a positive number of seconds");
            require(grid >= 2 && grid <= 201, "grid: expected 2..201 points per axis");
            require(threads >= 0, "threads: expected >= 0 (0: all cores)");
            PyRobustness r;
            r.spec = spec_of(uncertainty);
            r.o.draws = draws;
            if (target) r.o.target = config(sc, *target, "target");
            r.o.grid.nx = r.o.grid.ny = grid;
            r.o.grid.nth = sc.part.point ? 1 : grid;
            r.o.starts = starts;
            r.o.horizon = horizon;
            r.o.full_draws = full_draws;
            r.o.sensitivities = sensitivities;
            r.o.threads = threads;
            r.o.fixed.cycle = cycle_options(tol, rtol, max_periods, solver, max_rhs);
            r.s = interruptible(progress, [&](Watch& watch) {
                r.o.progress = [&watch](int done, int total) { watch.report(done, total); };
                return robustness(sc, r.spec, r.o);   // (invalid_argument: ValueError)
            });
            r.o.progress = nullptr;
            return r;
        },
        py::arg("scene"), py::arg("uncertainty"), py::kw_only(), py::arg("draws") = 200, py::arg("target") = py::none(),
        py::arg("grid") = 7, py::arg("starts") = 8, py::arg("horizon") = 60.0, py::arg("full_draws") = 4,
        py::arg("sensitivities") = true, py::arg("threads") = 0, py::arg("tol") = 1e-7, py::arg("rtol") = 1e-8,
        py::arg("max_periods") = 400, py::arg("solver") = "shooting", py::arg("max_rhs") = 2'000'000L,
        py::arg("progress") = py::none(),
        "The scene under an uncertainty spec (a file's path or a dict): outcome shares, the target's fixed point per draw, "
        "its spread and first-order sensitivities, arrival times (plate robustness). progress: a callable given a\n"
        "plate.Progress (draws done of total, an estimate of the seconds left) every 0.05 s while it changes.\n"
        "Ctrl-C stops it (KeyboardInterrupt, no result).");
    m.def(
        "uncertain_parameters",
        [](const Scene& sc, const py::object& uncertainty) {
            std::vector<std::tuple<std::string, std::string, double>> v;
            for (const UncertainParameter& p : uncertain_parameters(sc, spec_of(uncertainty)))
                v.emplace_back(p.name, p.unit, p.standard_deviation);
            return v;
        },
        py::arg("scene"), py::arg("uncertainty"),
        "The spec's parameters in draw order: (name, unit, standard deviation) each (numeric/include/plate/uncertainty.hpp).");
}

}   // namespace plate::python
