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

}   // namespace plate::python
