// plate.simulate: a trajectory in the full, U- or averaged dynamics, along the field, or in the model `auto`
// picks (plate.Trajectory).
#include "bindings.hpp"
#include "interrupt.hpp"

#include "plate/hierarchy.hpp"

#include <cmath>

namespace plate::python {

namespace {

struct PyTrajectory {
    Scene scene;
    Trajectory tr;
    std::string dynamics;
    struct Model {   // dynamics='auto': what was picked, its predicted error, why the estimate failed if it did
        std::string picked;
        double predicted = 0;
        std::string note;
    };
    std::optional<Model> model;
};

py::array_t<double> samples_array(const Trajectory& tr, int what) {
    std::vector<double> d;
    for (const Sample& s : tr.samples) {
        const Vec3& v = what == 0 ? s.q : what == 1 ? s.qd : s.n;
        d.insert(d.end(), {v[0], v[1], v[2]});
    }
    return array(d, {static_cast<py::ssize_t>(tr.samples.size()), 3});
}

// Pickled state: the scene, how it ran, and every sample, event and count as numbers (Python floats
// are doubles: the trajectory comes back to the bit).
py::tuple trajectory_state(const PyTrajectory& p) {
    py::list samples, events;
    for (const Sample& s : p.tr.samples) samples.append(sample_state(s));
    for (const ModeEvent& e : p.tr.events) events.append(event_state(e));
    return py::make_tuple(p.scene, p.dynamics,
                          p.model ? py::object(py::make_tuple(p.model->picked, p.model->predicted, p.model->note)) : py::none(),
                          samples, stop_state(p.tr.stop), stats_state(p.tr.stats), events,
                          py::make_tuple(p.tr.held_time[0], p.tr.held_time[1], p.tr.held_time[2]));
}
PyTrajectory trajectory_of(const py::tuple& t) {
    require(t.size() == 8, "plate.Trajectory: not a pickled trajectory");
    PyTrajectory p{t[0].cast<Scene>(), {}, t[1].cast<std::string>(), std::nullopt};
    if (!t[2].is_none()) {
        const auto m = t[2].cast<py::tuple>();
        p.model = PyTrajectory::Model{m[0].cast<std::string>(), m[1].cast<double>(), m[2].cast<std::string>()};
    }
    for (const py::handle& h : t[3].cast<py::list>()) p.tr.samples.push_back(sample_of(h));
    p.tr.stop = stop_of(t[4]);
    p.tr.stats = stats_of(t[5]);
    for (const py::handle& h : t[6].cast<py::list>()) p.tr.events.push_back(event_of(h));
    const auto held = t[7].cast<py::tuple>();
    for (std::size_t i = 0; i < 3; ++i) p.tr.held_time[i] = held[i].cast<double>();
    return p;
}

}   // namespace

void bind_simulate(py::module_& m) {
    py::class_<PyTrajectory>(m, "Trajectory", "Samples of a simulation, with the contact mode on each step.")
        .def(py::pickle(&trajectory_state, &trajectory_of))
        .def("__repr__",
             [](const PyTrajectory& p) {
                 const auto& s = p.tr.samples;
                 return "<plate.Trajectory of '" + p.scene.name + "' (" + p.dynamics + "): " + std::to_string(s.size()) +
                        " samples" + (s.empty() ? "" : ", t " + num(s.front().t) + " to " + num(s.back().t) + " s") +
                        (p.tr.stop.reason == StopReason::None ? "" : ", stopped: " + std::string(stop_name(p.tr.stop.reason))) +
                        ">";
             })
        .def_property_readonly("t",
                               [](const PyTrajectory& p) {
                                   std::vector<double> t;
                                   for (const Sample& s : p.tr.samples) t.push_back(s.t);
                                   return array(t, {static_cast<py::ssize_t>(t.size())});
                               })
        .def_property_readonly(
            "q", [](const PyTrajectory& p) { return samples_array(p.tr, 0); }, "(n, 3): s_x, s_y, theta")
        .def_property_readonly(
            "qd", [](const PyTrajectory& p) { return samples_array(p.tr, 1); }, "(n, 3): the part's twist relative to the plate")
        .def_property_readonly(
            "normal_forces", [](const PyTrajectory& p) { return samples_array(p.tr, 2); }, "(n, 3) [N]")
        .def_property_readonly(
            "mode",
            [](const PyTrajectory& p) {
                std::vector<std::string> m;
                for (const Sample& s : p.tr.samples) m.push_back(mode_name(s.mode));
                return m;
            },
            "the contact mode on the step that ended at each sample: slide, pivot1-3, stuck")
        .def_property_readonly(
            "events",
            [](const PyTrajectory& p) {
                std::vector<std::tuple<double, std::string, std::string>> e;
                for (const ModeEvent& ev : p.tr.events) e.emplace_back(ev.t, mode_name(ev.from), mode_name(ev.to));
                return e;
            },
            "every change of contact mode: (t, from, to)")
        .def_property_readonly(
            "held_time",
            [](const PyTrajectory& p) {
                return std::vector<double>(p.tr.held_time.begin(), p.tr.held_time.begin() + p.scene.part.contacts());
            },
            "time each contact had zero slip [s]")
        .def_property_readonly("stop", [](const PyTrajectory& p) { return to_py(p.tr.stop); })
        .def_property_readonly("steps", [](const PyTrajectory& p) { return p.tr.stats.steps; })
        .def_property_readonly("dynamics", [](const PyTrajectory& p) { return p.dynamics; })
        .def_property_readonly(
            "model",
            [](const PyTrajectory& p) -> py::object {
                if (!p.model) return py::none();
                py::dict d;
                d["picked"] = p.model->picked;
                d["predicted_error"] = p.model->predicted;
                d["note"] = p.model->note;
                return std::move(d);
            },
            "dynamics='auto': {'picked': part / dynamics, 'predicted_error': of rho and radians, 'note'}; else None");
    m.def(
        "simulate",
        [](const Scene& sc, const std::vector<double>& start, double time, const std::string& dynamics,
           std::optional<std::vector<double>> twist, std::optional<double> sample, double rtol, long max_steps, double tol,
           double model_tol) {
            require(dynamics == "full" || dynamics == "u" || dynamics == "field" || dynamics == "averaged" || dynamics == "auto",
                    "dynamics: expected 'full', 'u', 'field', 'averaged' or 'auto', got '" + dynamics + "'");
            const Vec3 q0 = config(sc, start, "start");
            const Vec3 qd0 = twist ? config(sc, *twist, "twist") : Vec3::Zero();
            const double dt = sample.value_or(sc.plate.T / 4);
            require(std::isfinite(time) && time > 0, "time: expected a number > 0");
            require(std::isfinite(dt) && dt > 0, "sample: expected a number > 0");
            require(std::ceil(time / dt) + 1 <= 1e7, "time / sample: more than 10^7 rows; sample less often");
            require(rtol > 0 && rtol < 1e-2, "rtol: expected a number in (0, 1e-2)");
            require(max_steps >= 1, "max_steps: expected >= 1");
            require(dynamics != "field" || qd0.isZero(), "twist: has no meaning for dynamics='field'");
            require(dynamics != "auto" || qd0.isZero(), "twist: dynamics='auto' answers from rest");
            require(model_tol > 0, "model_tol: expected a number > 0");
            PyTrajectory p{sc, {}, dynamics, std::nullopt};
            p.tr = interruptible(py::none(), [&](Watch&) {
                Scene run = sc;
                std::string level = dynamics;
                if (dynamics == "auto") {   // the command line's choice (experiments/hierarchy.hpp), decided up front
                    const ModelPick pick = pick_model(sc, q0, time, model_tol);
                    run = pick.scene;
                    level = pick.rung.dynamics == Dynamics::Full ? "full" : pick.rung.dynamics == Dynamics::U ? "u" : "field";
                    p.model = {pick.rung.name(), pick.predicted, pick.estimate.ok ? "" : pick.estimate.note};
                    p.dynamics = "auto: " + pick.rung.name();
                }
                if (level == "field") {
                    LimitCycleOptions lo;
                    lo.tol = tol;
                    return field_curve(run, q0, time, dt, lo);
                }
                IntegrationOptions io;
                io.rtol = rtol;
                io.max_steps = max_steps;
                return level == "averaged" ? simulate_averaged(run, q0, qd0, time, dt, io)
                                           : simulate(run, level == "full" ? Dynamics::Full : Dynamics::U, q0, qd0, time, dt, io);
            });
            return p;
        },
        py::arg("scene"), py::arg("start"), py::arg("time"), py::kw_only(), py::arg("dynamics") = "full",
        py::arg("twist") = py::none(), py::arg("sample") = py::none(), py::arg("rtol") = 1e-9, py::arg("max_steps") = 20'000'000L,
        py::arg("tol") = 1e-7, py::arg("model_tol") = 1e-2,
        "A trajectory from configuration `start` with the part's twist `twist` relative to the plate (default:\n"
        "at rest) for `time` seconds, sampled every `sample` (default T/4): 'full' dynamics (31), 'u'\n"
        "U-dynamics (32), the 'field' integral curve, 'averaged' (full dynamics in bursts, the field's drift\n"
        "between them, as `plate simulate --dynamics averaged`) or 'auto' (the cheapest part model and\n"
        "dynamics predicted within `model_tol` of the full model, decided up front from rest: the choice in\n"
        "trajectory.model). Stick-slip is simulated through. A run that leaves the model (a normal force\n"
        "reaches zero) ends there: trajectory.stop says when and which contact.");
}

}   // namespace plate::python
