// The conversions the module's pieces share (bindings.hpp): options, configurations, arrays, JSON.
#include "bindings.hpp"

#include <sstream>

#include <cmath>

namespace plate::python {

py::object json_to_python(const nlohmann::json& j) { return py::module_::import("json").attr("loads")(j.dump()); }

Vec3 config(const Scene& sc, const std::vector<double>& v, const char* name) {
    const std::size_t need = sc.part.point ? 2 : 3;
    if (v.size() != need)
        throw py::value_error(std::string(name) + ": expected " + std::to_string(need) + " numbers (" +
                              (sc.part.point ? "point part: SX SY" : "SX SY THETA") + "), got " + std::to_string(v.size()));
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

std::string num(double x, int digits) {
    std::ostringstream s;
    s.precision(digits);
    s << x;
    return s.str();
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

PyStop to_py(const StopEvent& e) {
    return {stop_name(e.reason), e.contact + 1, e.t, e.reason == StopReason::None ? "" : e.describe()};
}

std::optional<std::string> path_of(const py::handle& o) {
    if (py::isinstance<py::str>(o)) return o.cast<std::string>();
    if (!py::hasattr(o, "__fspath__")) return std::nullopt;
    const py::object p = py::module_::import("os").attr("fspath")(o);
    if (!py::isinstance<py::str>(p)) return std::nullopt;   // (a bytes path: not a file name this library takes)
    return p.cast<std::string>();
}

py::tuple mode_state(const Mode& m) { return py::make_tuple(static_cast<int>(m.kind), m.k, m.sense); }
Mode mode_of(const py::handle& state) {
    const auto t = state.cast<py::tuple>();
    require(t.size() == 3, "a pickled contact mode is (kind, contact, sense)");
    Mode m;
    m.kind = static_cast<ModeKind>(t[0].cast<int>());
    m.k = t[1].cast<int>();
    m.sense = t[2].cast<double>();
    return m;
}

py::tuple event_state(const ModeEvent& e) { return py::make_tuple(e.t, mode_state(e.from), mode_state(e.to)); }
ModeEvent event_of(const py::handle& state) {
    const auto t = state.cast<py::tuple>();
    require(t.size() == 3, "a pickled mode event is (t, from, to)");
    return {t[0].cast<double>(), mode_of(t[1]), mode_of(t[2])};
}

py::tuple stop_state(const StopEvent& e) { return py::make_tuple(static_cast<int>(e.reason), e.contact, e.t); }
StopEvent stop_of(const py::handle& state) {
    const auto t = state.cast<py::tuple>();
    require(t.size() == 3, "a pickled stop is (reason, contact, t)");
    StopEvent e;
    e.reason = static_cast<StopReason>(t[0].cast<int>());
    e.contact = t[1].cast<int>();
    e.t = t[2].cast<double>();
    return e;
}

py::tuple stats_state(const Stats& s) {
    return py::make_tuple(s.rhs_evals, s.steps, s.rejected, s.slip_reversals, s.mode_switches, s.min_normal_force);
}
Stats stats_of(const py::handle& state) {
    const auto t = state.cast<py::tuple>();
    require(t.size() == 6, "pickled run counts are 6 numbers");
    Stats s;
    s.rhs_evals = t[0].cast<long>();
    s.steps = t[1].cast<long>();
    s.rejected = t[2].cast<long>();
    s.slip_reversals = t[3].cast<long>();
    s.mode_switches = t[4].cast<long>();
    s.min_normal_force = t[5].cast<double>();
    return s;
}

py::tuple sample_state(const Sample& s) {
    return py::make_tuple(s.t, s.q[0], s.q[1], s.q[2], s.qd[0], s.qd[1], s.qd[2], s.n[0], s.n[1], s.n[2], mode_state(s.mode));
}
Sample sample_of(const py::handle& state) {
    const auto v = state.cast<py::tuple>();
    require(v.size() == 11, "a pickled sample is (t, q, qd, n, mode)");
    Sample s;
    s.t = v[0].cast<double>();
    for (std::size_t i = 0; i < 3; ++i) {
        s.q[static_cast<int>(i)] = v[1 + i].cast<double>();
        s.qd[static_cast<int>(i)] = v[4 + i].cast<double>();
        s.n[static_cast<int>(i)] = v[7 + i].cast<double>();
    }
    s.mode = mode_of(v[10]);
    return s;
}

}   // namespace plate::python
