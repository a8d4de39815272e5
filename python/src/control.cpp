// plate.control (a closed-loop run, plate.ControlRun), the `python` policy (a Python callable deciding each
// period), plate.ControlEnv (the same loop a step at a time, Gym-like): control/include/plate/control.hpp;
// plate.control_parts (several point parts on one plate): control_multi.hpp.
#include "bindings.hpp"
#include "interrupt.hpp"
#include "pickling.hpp"

#include "plate/control.hpp"
#include "plate/control_multi.hpp"
#include "plate/observe.hpp"

#include <chrono>
#include <cmath>
#include <memory>
#include <sstream>

namespace plate::python {

namespace {

std::string num(double x) {
    std::ostringstream o;
    o << x;
    return o.str();
}

std::string dumps(const py::handle& d) { return py::module_::import("json").attr("dumps")(d).cast<std::string>(); }

// A truth, a camera or a library from a file's path (str or os.PathLike) or a dict in the file's form (checked as a file
// is: plate.InputError naming '<dict>'); a library dict's scene paths are relative to the working folder.
Truth truth_of(const py::object& t) {
    if (t.is_none()) return Truth{};
    if (const auto path = path_of(t)) return load_truth(*path);
    require(py::isinstance<py::dict>(t), "truth: expected a truth file's path or a dict in its form");
    return parse_truth(dumps(t), "<dict>");
}
std::optional<Camera> camera_opt(const py::object& c) {
    if (c.is_none()) return std::nullopt;
    return camera_of(c);
}
MotionLibrary library_of(const py::object& l, const Scene& sc) {
    if (const auto path = path_of(l)) return load_motion_library(*path, sc);
    require(py::isinstance<py::dict>(l), "library: expected a library file's path or a dict in its form");
    return parse_motion_library(dumps(l), "<dict>", "", sc);
}

// What the inputs of plate.control and plate.ControlEnv become: the model, the truth, the camera, the goal.
struct Setup {
    ControlModel model;
    Truth truth;
    std::optional<Camera> camera;
    Goal goal;
    Vec3 q0;
    ControlOptions opt;
};

Setup setup(const Scene& sc, const std::vector<double>& goal, const py::object& library, const py::object& truth,
            const py::object& camera, const std::optional<std::vector<double>>& start, double time, double tol,
            std::optional<std::uint64_t> seed, int grid) {
    Setup s{};
    s.goal.q = config(sc, goal, "goal");
    s.goal.point = sc.part.point;
    s.goal.tolerance = tol;
    require(tol > 0 && std::isfinite(tol), "tol: expected a number > 0");
    s.q0 = start ? config(sc, *start, "start") : Vec3::Zero();
    s.opt.duration = time;
    require(std::isfinite(time) && time > 0 && time / sc.plate.T <= static_cast<double>(kMaxControlPeriods),
            "time: expected a number > 0 of at most " + std::to_string(kMaxControlPeriods) + " plate periods");
    s.truth = truth_of(truth);
    s.camera = camera_opt(camera);
    if (seed) {   // one seed for the run's randomness: the truth's draw and the camera's noise and drops
        s.truth.draw = *seed;
        if (s.camera) s.camera->seed = *seed;
    }
    ControlModelOptions mo;   // as `plate control` builds it
    mo.grid.nx = mo.grid.ny = mo.grid.nth = grid;
    mo.field.cycle.max_rhs_evaluations = 2'000'000;
    try {
        mo.validate();
    } catch (const std::invalid_argument& e) {
        require(false, std::string("grid: ") + e.what());
    }
    MotionLibrary lib = library_of(library, sc);
    s.model = interruptible(py::none(), [&](Watch&) { return build_control_model(sc, std::move(lib), mo); });
    return s;
}

py::dict observation_dict(const Observation& o, long period, const ControlModel& m) {
    py::dict d;
    d["period"] = period;
    d["t"] = o.t;
    d["seen"] = o.seen;
    d["observed"] = o.seen ? py::object(array({o.q[0], o.q[1], o.q[2]}, {3})) : py::object(py::none());
    d["state_time"] = o.seen ? py::object(py::float_(o.state_time)) : py::object(py::none());
    d["motions"] = m.library.names;
    return d;
}

// A policy's answer as a decision: a library index, a motion's name, a plate.Scene with the scene's period
// or a list of harmonics dicts (the scene file's plate.harmonics). ValueError naming what was expected.
Decision decision_of(const py::handle& a, const ControlModel& m) {
    const std::string expected = "expected a library index (0 to " + std::to_string(m.motions() - 1) +
                                 "), a motion's name, a plate.Scene of period " + num(m.T()) + " s or a list of harmonics dicts";
    if (py::isinstance<py::int_>(a) && !py::isinstance<py::bool_>(a)) {
        const long k = a.cast<long>();
        require(k >= 0 && k < m.motions(), "motion index " + std::to_string(k) + ": not in the library; " + expected);
        return {static_cast<int>(k), std::nullopt};
    }
    if (py::isinstance<py::str>(a)) {
        const std::string n = a.cast<std::string>();
        for (int k = 0; k < m.motions(); ++k)
            if (m.library.names[k] == n) return {k, std::nullopt};
        require(false, "motion '" + n + "': not a motion of the library (" + m.library.source + "); " + expected);
    }
    if (py::isinstance<Scene>(a)) {
        const Scene sc = a.cast<Scene>();
        require(sc.plate.T == m.T(), "a plate motion of period " + num(sc.plate.T) + " s: " + expected);
        return {-1, sc.plate};
    }
    if (py::isinstance<py::list>(a)) {
        nlohmann::json j = scene_to_json(m.nominal);
        j["plate"]["harmonics"] = nlohmann::json::parse(dumps(a));
        return {-1, parse_scene(j.dump(), "the policy's harmonics").plate};
    }
    require(false, "the policy returned " + py::repr(a).cast<std::string>() + ": " + expected);
    return {};
}

// The `python` policy: the callable (or an object's decide(), with reset() called before a run if it has
// one) called once per period with the observation dict; the GIL taken for it.
class PythonPolicy : public Policy {
public:
    explicit PythonPolicy(py::object f) : f_(std::move(f)) {}
    std::string name() const override { return "python"; }
    void reset(const ControlModel& model, const Goal&) override {
        model_ = &model;
        py::gil_scoped_acquire gil;
        if (!PyCallable_Check(f_.ptr()) && py::hasattr(f_, "reset")) f_.attr("reset")();
    }
    Decision decide(const Observation& obs, long period) override {
        py::gil_scoped_acquire gil;
        const py::object call = PyCallable_Check(f_.ptr()) ? f_ : f_.attr("decide");
        return decision_of(call(observation_dict(obs, period, *model_)), *model_);
    }

private:
    py::object f_;
    const ControlModel* model_ = nullptr;
};

// plate.control's result.
struct PyControlRun {
    ControlSummary s;
    nlohmann::json summary;
    std::vector<std::string> motions;
};

}   // namespace

// Each struct's members once (pickling.hpp).
namespace pickling {
void io(Archive& a, ControlRow& r) { a(r.t, r.observed, r.truth, r.motion, r.decision_seconds); }
void io(Archive& a, ControlSummary& s) {
    a(s.policy, s.periods, s.reached, s.time_to_goal, s.first_within, s.final_error, s.final_theta_error, s.worst_overshoot,
      s.switches, s.decision_mean, s.decision_max, s.decision_p99, s.stop, s.interrupted, s.rows);
}
void io(Archive& a, PyControlRun& r) { a(r.s, r.summary, r.motions); }
}   // namespace pickling

namespace {

py::array_t<double> rows_array(const ControlSummary& s, bool observed) {
    std::vector<double> d;
    for (const ControlRow& r : s.rows) {
        const Vec3& v = observed ? r.observed : r.truth;
        d.insert(d.end(), {v[0], v[1], v[2]});
    }
    return array(d, {static_cast<py::ssize_t>(s.rows.size()), 3});
}

PyControlRun make_run(const ControlSummary& s, const Setup& st) {
    return {s, control_summary_json(s, st.model, st.goal), st.model.library.names};
}

// plate.ControlEnv's state: the setup and the loop of the current episode.
struct PyControlEnv {
    Setup st;
    std::optional<ControlLoop> loop;
    py::dict observe() const { return observation_dict(loop->observe(), loop->period(), st.model); }
};

void bind_control_run(py::module_& m) {
    py::class_<PyControlRun>(m, "ControlRun", "A closed-loop run (plate.control): one row per period start and the end.")
        .def(pickling::pickle_as<PyControlRun>("plate.ControlRun"))
        .def_property_readonly("t",
                               [](const PyControlRun& r) {
                                   std::vector<double> t;
                                   for (const ControlRow& row : r.s.rows) t.push_back(row.t);
                                   return array(t, {static_cast<py::ssize_t>(t.size())});
                               })
        .def_property_readonly(
            "observed", [](const PyControlRun& r) { return rows_array(r.s, true); },
            "(n, 3): the frame each decision used (plate frame; nan before the first frame)")
        .def_property_readonly(
            "truth", [](const PyControlRun& r) { return rows_array(r.s, false); },
            "(n, 3): the part's true world pose (x, y, heading) at each period start")
        .def_property_readonly(
            "motion",
            [](const PyControlRun& r) {
                py::array_t<int> a(static_cast<py::ssize_t>(r.s.rows.size()));
                for (std::size_t k = 0; k < r.s.rows.size(); ++k) a.mutable_at(k) = r.s.rows[k].motion;
                return a;
            },
            "(n,): the library index chosen each period (-1: the policy's own motion, and the end row)")
        .def_readonly("motions", &PyControlRun::motions, "the library's motion names")
        .def_property_readonly(
            "decision",
            [](const PyControlRun& r) {
                std::vector<double> d;
                for (const ControlRow& row : r.s.rows) d.push_back(row.decision_seconds);
                return array(d, {static_cast<py::ssize_t>(d.size())});
            },
            "(n,): each decision's wall time [s]")
        .def_property_readonly("stop", [](const PyControlRun& r) { return to_py(r.s.stop); })
        .def_property_readonly("reached", [](const PyControlRun& r) { return r.s.reached; })
        .def_property_readonly(
            "summary", [](const PyControlRun& r) { return json_to_python(r.summary); }, "the command line's summary JSON")
        .def("__repr__", [](const PyControlRun& r) {
            return "<plate.ControlRun policy " + r.s.policy + ": " + std::to_string(r.s.periods) + " periods, " +
                   (r.s.reached ? "goal reached at " + std::to_string(r.s.time_to_goal) + " s"
                                : std::string("goal not reached")) +
                   ", final error " + std::to_string(r.s.final_error * 1e3) + " mm, " + std::to_string(r.s.switches) +
                   " switches>";
        });
}

// plate.control_parts: several point parts on one plate, the multi-part library policy.
void bind_control_parts(py::module_& m) {
    m.def(
        "control_parts",
        [](const Scene& sc, const py::object& parts, const py::object& library, double time, const py::object& truth,
           const py::object& camera, std::optional<double> tol, std::optional<std::uint64_t> seed, std::optional<int> horizon,
           int grid) {
            MultiParts ps;
            if (const auto path = path_of(parts)) {
                ps = load_parts(*path);
            } else {
                require(py::isinstance<py::dict>(parts), "parts: expected a parts file's path or a dict in its form");
                ps = parse_parts(dumps(parts), "<dict>");
            }
            if (tol) ps.tolerance = *tol;
            ps.validate(sc);
            const Setup st = setup(sc, {0, 0}, library, truth, camera, std::nullopt, time, ps.tolerance, seed, grid);
            LibraryPolicyOptions lo;
            if (horizon) lo.horizon = *horizon;
            std::unique_ptr<MultiPolicy> p;
            try {
                p = make_multi_library_policy(lo);
            } catch (const std::invalid_argument& e) {
                require(false, std::string("horizon: ") + e.what());
            }
            const MultiControlSummary s = interruptible(
                py::none(), [&](Watch&) { return run_multi_control(st.model, *p, st.truth, st.camera, ps, st.opt); });
            const nlohmann::json summary = multi_control_summary_json(s, st.model, ps);
            std::vector<PyControlRun> runs;
            for (const ControlSummary& part : s.parts) runs.push_back({part, summary, st.model.library.names});
            return runs;
        },
        py::arg("scene"), py::arg("parts"), py::kw_only(), py::arg("library"), py::arg("time"), py::arg("truth") = py::none(),
        py::arg("camera") = py::none(), py::arg("tol") = py::none(), py::arg("seed") = py::none(),
        py::arg("horizon") = py::none(), py::arg("grid") = 13,
        "Several point parts on one plate (`plate control --parts`): parts, a parts file's path or a dict in its\n"
        "form ({'parts': [{'goal': [x, y], 'start': [x, y], 'weight': w}, ...]}); each plate period the library\n"
        "policy chooses one motion for all of them (first the parts' shape, then carrying them in; the least sum of\n"
        "weighted distances); each part follows it through the full dynamics, filmed by the camera (part i's seed:\n"
        "the camera's + i). library, truth, camera, seed, horizon and grid as for plate.control; tol (if given)\n"
        "replaces the file's tolerance. Returns a list of plate.ControlRun, one per part (its rows, reached, stop);\n"
        "each one's summary is the whole run's (the command line's JSON, per part under 'parts').");
}

}   // namespace

void bind_control(py::module_& m) {
    bind_control_run(m);
    m.def(
        "control",
        [](const Scene& sc, const std::vector<double>& goal, const py::object& library, double time, const py::object& truth,
           const py::object& camera, const std::optional<std::vector<double>>& start, const py::object& policy, double tol,
           std::optional<std::uint64_t> seed, std::optional<int> horizon, int grid, double switch_cost, bool correction) {
            const Setup st = setup(sc, goal, library, truth, camera, start, time, tol, seed, grid);
            std::unique_ptr<Policy> p;
            if (py::isinstance<py::str>(policy)) {
                const std::string name = policy.cast<std::string>();
                require(name == "library" || name == "mpc",
                        "policy: expected 'library', 'mpc' or a Python callable, got '" + name + "'");
                require(name == "mpc" || (switch_cost == MpcPolicyOptions{}.switch_cost && correction),
                        "switch_cost and correction are the mpc policy's");
                LibraryPolicyOptions lo;
                MpcPolicyOptions mo;
                if (horizon) lo.horizon = mo.horizon = *horizon;
                mo.switch_cost = switch_cost;
                mo.correct = correction;
                try {
                    p = name == "mpc" ? make_mpc_policy(mo) : make_library_policy(lo);
                    p->reset(st.model, st.goal);   // (what it cannot steer: refused before the run)
                } catch (const std::invalid_argument& e) {
                    require(false, "policy '" + name + "': " + e.what());
                }
            } else {
                require(PyCallable_Check(policy.ptr()) || py::hasattr(policy, "decide"),
                        "policy: expected 'library', 'mpc', a callable or an object with decide(observation)");
                p = std::make_unique<PythonPolicy>(policy);
            }
            const ControlSummary s = interruptible(
                py::none(), [&](Watch&) { return run_control(st.model, *p, st.truth, st.camera, st.goal, st.q0, st.opt); });
            return make_run(s, st);
        },
        py::arg("scene"), py::arg("goal"), py::kw_only(), py::arg("library"), py::arg("time"), py::arg("truth") = py::none(),
        py::arg("camera") = py::none(), py::arg("start") = py::none(), py::arg("policy") = "library",
        py::arg("tol") = Goal{}.tolerance, py::arg("seed") = py::none(), py::arg("horizon") = py::none(), py::arg("grid") = 13,
        py::arg("switch_cost") = MpcPolicyOptions{}.switch_cost, py::arg("correction") = true,
        "A closed-loop run (`plate control`): from `start` at rest, each plate period the policy chooses the next\n"
        "motion from the camera's newest frame; the true plate runs it through the full dynamics. library, truth,\n"
        "camera: a file's path or a dict in its form (camera also a plate.Camera; None: a perfect camera at phase 0,\n"
        "the scene itself as truth). policy: 'library' (a motion judged kept for horizon periods, default 2),\n"
        "'mpc' (the best sequence of horizon motions, default 3, plus switch_cost [m] per switch, on\n"
        "the model corrected online by a fitted gain and drift unless correction=False), or a callable f(observation) -> motion\n"
        "(observation: a dict period, t, seen, observed (s_x, s_y, theta) or None, state_time, motions; the motion:\n"
        "a library index, a motion's name, a plate.Scene of the same period or a list of harmonics dicts), or an\n"
        "object with decide(observation) (and reset(), called before the run). seed (if given): the truth's draw\n"
        "and the camera's seed. Returns a plate.ControlRun.");

    py::class_<PyControlEnv>(
        m, "ControlEnv",
        "The closed loop a plate period at a time, Gym-like (no RL package needed): reset(seed=None) -> observation;\n"
        "step(action) -> (observation, reward, terminated, truncated, info). One step runs one period of the true\n"
        "plate's full dynamics on the action (a motion, as a python policy returns it); reward = minus the part's\n"
        "true world-frame distance to the goal [m] after the step; terminated when within tol (or the true part\n"
        "lost contact: info['stop']); truncated at the time limit.")
        .def(py::init([](const Scene& sc, const std::vector<double>& goal, const py::object& library, const py::object& truth,
                         const py::object& camera, const std::optional<std::vector<double>>& start, double time, double tol,
                         std::optional<std::uint64_t> seed, int grid) {
                 return PyControlEnv{setup(sc, goal, library, truth, camera, start, time, tol, seed, grid), std::nullopt};
             }),
             py::arg("scene"), py::arg("goal"), py::kw_only(), py::arg("library"), py::arg("truth") = py::none(),
             py::arg("camera") = py::none(), py::arg("start") = py::none(), py::arg("time") = 10.0,
             py::arg("tol") = Goal{}.tolerance, py::arg("seed") = py::none(), py::arg("grid") = 13)
        .def(
            "reset",
            [](PyControlEnv& e, std::optional<std::uint64_t> seed) {
                if (seed) {
                    e.st.truth.draw = *seed;
                    if (e.st.camera) e.st.camera->seed = *seed;
                }
                e.loop.emplace(e.st.model, e.st.truth, e.st.camera, e.st.goal, e.st.q0, e.st.opt);
                return e.observe();
            },
            py::arg("seed") = py::none(),
            "Starts an episode from `start` at rest (seed: the truth's draw and the camera's seed; None: the last\n"
            "episode's); returns the observation.")
        .def(
            "step",
            [](PyControlEnv& e, const py::object& action) {
                if (!e.loop || e.loop->done()) throw std::runtime_error("plate.ControlEnv: the episode is over; call reset()");
                const Decision d = decision_of(action, e.st.model);
                {
                    py::gil_scoped_release free;
                    e.loop->step(d);
                }
                const Vec3 pose = e.loop->true_pose();
                const bool stopped = e.loop->stop().reason != StopReason::None;
                const bool terminated = stopped || e.st.goal.within(pose);
                py::dict info;
                info["true"] = array({pose[0], pose[1], pose[2]}, {3});
                info["stop"] = to_py(e.loop->stop());
                return py::make_tuple(e.observe(), -e.st.goal.error(pose), terminated, !terminated && e.loop->done(), info);
            },
            py::arg("action"))
        .def_property_readonly(
            "periods", [](const PyControlEnv& e) { return e.loop ? e.loop->periods() : 0L; }, "the episode's length in periods")
        .def_property_readonly("motions", [](const PyControlEnv& e) { return e.st.model.library.names; })
        .def(
            "run",
            [](const PyControlEnv& e) {
                require(e.loop.has_value(), "plate.ControlEnv: call reset() first");
                return make_run(e.loop->summary("env"), e.st);
            },
            "The episode so far as a plate.ControlRun (its rows and the current pose as the end row).");
    bind_control_parts(m);
}

}   // namespace plate::python
