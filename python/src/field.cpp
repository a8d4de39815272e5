// plate.field (the asymptotic twist field on a grid, plate.Field) and plate.fixed_points (its zeros).
#include "bindings.hpp"
#include "interrupt.hpp"
#include "pickling.hpp"

#include <cmath>
#include <stdexcept>

namespace plate::python {

namespace {

struct PyFixedPoints {
    Scene scene;
    FixedPoints fp;
};

}   // namespace

namespace pickling {
void io(Archive& a, PyFixedPoints& p) { a(p.scene, p.fp); }
}   // namespace pickling
using pickling::pickle_as;

namespace {

// The field's arrays over its grid: shape (nx, ny, ntheta, 3) (point parts: ntheta = 1).
py::array_t<double> field_array(const Field& f, int what) {
    const GridSpec& g = f.grid;
    std::vector<double> d;
    d.reserve(f.points.size() * 3);
    for (const FieldPoint& p : f.points)
        for (int c = 0; c < 3; ++c) d.push_back(what == 0 ? p.q[c] : what == 1 ? p.twist[c] : p.stick_fraction[c]);
    return array(d, {g.nx, g.ny, g.nth, 3});
}

// Pickled state: the scene, the grid, and every configuration's numbers (Python floats are doubles: the
// field comes back to the bit).
py::tuple field_state(const PyField& p) {
    const Field& f = p.f;
    const GridSpec& g = f.grid;
    py::list points;
    for (const FieldPoint& q : f.points)
        points.append(py::make_tuple(q.q[0], q.q[1], q.q[2], q.twist[0], q.twist[1], q.twist[2], q.converged, q.periods,
                                     q.residual, q.min_normal_force, static_cast<int>(q.stop), q.rhs_evals, q.stick_fraction[0],
                                     q.stick_fraction[1], q.stick_fraction[2]));
    return py::make_tuple(p.scene, py::make_tuple(g.nx, g.ny, g.nth, g.x0, g.x1, g.y0, g.y1, g.th0), f.point_part, points,
                          py::make_tuple(f.seconds, f.rhs_evals, f.threads, f.budget_spent));
}
PyField field_of(const py::tuple& t) {
    require(t.size() == 5, "plate.Field: not a pickled field");
    PyField p{t[0].cast<Scene>(), {}};
    Field& f = p.f;
    const auto g = t[1].cast<py::tuple>();
    f.grid.nx = g[0].cast<int>();
    f.grid.ny = g[1].cast<int>();
    f.grid.nth = g[2].cast<int>();
    f.grid.x0 = g[3].cast<double>();
    f.grid.x1 = g[4].cast<double>();
    f.grid.y0 = g[5].cast<double>();
    f.grid.y1 = g[6].cast<double>();
    f.grid.th0 = g[7].cast<double>();
    f.point_part = t[2].cast<bool>();
    for (const py::handle& h : t[3].cast<py::list>()) {
        const auto v = h.cast<py::tuple>();
        FieldPoint q;
        for (int i = 0; i < 3; ++i) {
            q.q[i] = v[static_cast<std::size_t>(i)].cast<double>();
            q.twist[i] = v[static_cast<std::size_t>(3 + i)].cast<double>();
            q.stick_fraction[static_cast<std::size_t>(i)] = v[static_cast<std::size_t>(12 + i)].cast<double>();
        }
        q.converged = v[6].cast<bool>();
        q.periods = v[7].cast<int>();
        q.residual = v[8].cast<double>();
        q.min_normal_force = v[9].cast<double>();
        q.stop = static_cast<StopReason>(v[10].cast<int>());
        q.rhs_evals = v[11].cast<long>();
        f.points.push_back(q);
    }
    require(static_cast<int>(f.points.size()) == f.grid.size(), "plate.Field: a pickled field's points do not fill its grid");
    const auto r = t[4].cast<py::tuple>();
    f.seconds = r[0].cast<double>();
    f.rhs_evals = r[1].cast<long>();
    f.threads = r[2].cast<int>();
    f.budget_spent = r[3].cast<bool>();
    return p;
}

}   // namespace

void bind_field(py::module_& m) {
    py::class_<PyField>(m, "Field", "The asymptotic twist field on a grid (point parts: velocity field, ntheta = 1).")
        .def(py::pickle(&field_state, &field_of))
        .def("__repr__",
             [](const PyField& p) {
                 const GridSpec& g = p.f.grid;
                 long converged = 0;
                 for (const FieldPoint& q : p.f.points) converged += q.converged;
                 return "<plate.Field of '" + p.scene.name + "': " + std::to_string(g.nx) + "x" + std::to_string(g.ny) +
                        (p.f.point_part ? " velocity field" : "x" + std::to_string(g.nth) + " twist field") + " over s_x [" +
                        num(g.x0) + ", " + num(g.x1) + "] m, s_y [" + num(g.y0) + ", " + num(g.y1) + "] m; " +
                        std::to_string(converged) + " of " + std::to_string(p.f.points.size()) + " converged; " +
                        num(p.f.seconds, 3) + " s>";
             })
        .def_property_readonly("x",
                               [](const PyField& f) {
                                   std::vector<double> v;
                                   for (int i = 0; i < f.f.grid.nx; ++i) v.push_back(f.f.grid.at(i, 0, 0)[0]);
                                   return array(v, {f.f.grid.nx});
                               })
        .def_property_readonly("y",
                               [](const PyField& f) {
                                   std::vector<double> v;
                                   for (int j = 0; j < f.f.grid.ny; ++j) v.push_back(f.f.grid.at(0, j, 0)[1]);
                                   return array(v, {f.f.grid.ny});
                               })
        .def_property_readonly("theta",
                               [](const PyField& f) {
                                   std::vector<double> v;
                                   for (int k = 0; k < f.f.grid.nth; ++k) v.push_back(f.f.grid.at(0, 0, k)[2]);
                                   return array(v, {f.f.grid.nth});
                               })
        .def_property_readonly(
            "q", [](const PyField& f) { return field_array(f.f, 0); }, "configurations, shape (nx, ny, ntheta, 3)")
        .def_property_readonly(
            "twist", [](const PyField& f) { return field_array(f.f, 1); },
            "asymptotic twists, shape (nx, ny, ntheta, 3); NaN where undefined")
        .def_property_readonly(
            "stick_fraction", [](const PyField& f) { return field_array(f.f, 2); }, "per contact, shape (nx, ny, ntheta, 3)")
        .def_property_readonly("converged",
                               [](const PyField& f) {
                                   py::array_t<bool> a({f.f.grid.nx, f.f.grid.ny, f.f.grid.nth});
                                   for (std::size_t i = 0; i < f.f.points.size(); ++i)
                                       a.mutable_data()[i] = f.f.points[i].converged;
                                   return a;
                               })
        .def_property_readonly(
            "stops",
            [](const PyField& f) {
                std::vector<std::string> s;
                for (const FieldPoint& p : f.f.points) s.push_back(stop_name(p.stop));
                const GridSpec& g = f.f.grid;
                return py::module_::import("numpy").attr("array")(s).attr("reshape")(g.nx, g.ny, g.nth);
            },
            "why each configuration has no twist ('none' where it has): a numpy array of str, shape (nx, ny, ntheta)")
        .def_property_readonly("seconds", [](const PyField& f) { return f.f.seconds; })
        .def_property_readonly("rhs_evaluations", [](const PyField& f) { return f.f.rhs_evals; })
        .def_property_readonly("threads", [](const PyField& f) { return f.f.threads; })
        .def_property_readonly(
            "summary", [](const PyField& f) { return json_to_python(to_json(f.scene, f.f)); },
            "the command line's JSON (`plate field`) as a dict");
    m.def(
        "field",
        [](const Scene& sc, int grid, std::optional<int> nx, std::optional<int> ny, std::optional<int> ntheta,
           std::pair<double, double> x, std::pair<double, double> y, double theta0, int threads, double tol, double rtol,
           int max_periods, const std::string& solver, long max_rhs, long max_work, const py::object& progress) {
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
            PyField f{sc, interruptible(progress, [&](Watch& watch) {
                          require_field_work(sc, g, o.cycle, max_work, "max_work= (0: no budget)");
                          o.progress = [&watch](int done, int total) { watch.report(done, total); };
                          return compute_field(sc, g, o);
                      })};
            if (f.f.budget_spent)
                throw std::runtime_error("the work budget of max_work = " + std::to_string(max_work) +
                                         " right-hand sides was spent before the field was complete");
            return f;
        },
        py::arg("scene"), py::kw_only(), py::arg("grid") = 7, py::arg("nx") = py::none(), py::arg("ny") = py::none(),
        py::arg("ntheta") = py::none(), py::arg("x") = std::make_pair(-0.05, 0.05), py::arg("y") = std::make_pair(-0.05, 0.05),
        py::arg("theta0") = 0.0, py::arg("threads") = 0, py::arg("tol") = 1e-7, py::arg("rtol") = 1e-8,
        py::arg("max_periods") = 400, py::arg("solver") = "shooting", py::arg("max_rhs") = 20'000'000L,
        py::arg("max_work") = kDefaultFieldWork, py::arg("progress") = py::none(),
        "The asymptotic twist field on a regular grid over (s_x, s_y, theta), theta covering a full turn;\n"
        "configurations in parallel on `threads` cores (0: all). max_work: a budget in right-hand sides\n"
        "for the whole field, as the command line's --max-work (default 2e9; 0: none): the work is\n"
        "estimated up front from five cycles and a larger field is refused (ValueError with the estimate);\n"
        "a field that spends it anyway raises RuntimeError. progress: a callable given a plate.Progress\n"
        "(configurations done of total, an estimate of the seconds left) every 0.05 s while it changes.\n"
        "Ctrl-C stops it within 0.1 s (KeyboardInterrupt, no result).");
}

void bind_fixed_points(py::module_& m) {
    py::class_<FixedPoint>(m, "FixedPoint")
        .def(pickle_as<FixedPoint>("plate.FixedPoint"))
        .def_readonly("q", &FixedPoint::q, "(s_x, s_y, theta), theta in (-pi, pi]")
        .def_readonly("eigenvalues", &FixedPoint::eigenvalues, "of the field's Jacobian (point part: the first 2)")
        .def_property_readonly("stability", [](const FixedPoint& p) { return stability_name(p.stability); })
        .def_readonly("residual", &FixedPoint::residual)
        .def_readonly("eigen_error", &FixedPoint::eigen_error, "estimated error of the eigenvalues' real parts [1/s]")
        .def("__repr__", [](const FixedPoint& p) {
            return "<plate.FixedPoint " + std::string(stability_name(p.stability)) + " at (" + std::to_string(p.q[0]) + ", " +
                   std::to_string(p.q[1]) + ", " + std::to_string(p.q[2]) + ")>";
        });
    py::class_<StuckRegion>(m, "StuckRegion", "configurations where the part does not move, connected on the grid")
        .def(pickle_as<StuckRegion>("plate.StuckRegion"))
        .def_readonly("lo", &StuckRegion::lo, "lower bounds of (s_x, s_y, theta) [m, m, rad]")
        .def_readonly("hi", &StuckRegion::hi, "upper bounds (theta from lo up to hi, possibly beyond pi)")
        .def_readonly("all_theta", &StuckRegion::all_theta)
        .def_readonly("grid_points", &StuckRegion::grid_points)
        .def_readonly("touches_edge", &StuckRegion::touches_edge)
        .def("__repr__", [](const StuckRegion& r) {
            return "<plate.StuckRegion x in [" + num(r.lo[0]) + ", " + num(r.hi[0]) + "] m, y in [" + num(r.lo[1]) + ", " +
                   num(r.hi[1]) + "] m, " + std::to_string(r.grid_points) + " grid points>";
        });
    py::class_<RotatingAttractor>(m, "RotatingAttractor", "position settled while theta turns at a steady mean rate")
        .def(pickle_as<RotatingAttractor>("plate.RotatingAttractor"))
        .def_readonly("q", &RotatingAttractor::q, "(s_x, s_y) [m] on the section theta = q[2] [rad]")
        .def_readonly("rate", &RotatingAttractor::rate, "mean dtheta/dt [rad/s]; +: counter-clockwise")
        .def_readonly("period", &RotatingAttractor::period, "time for one turn [s]")
        .def_readonly("multipliers", &RotatingAttractor::multipliers, "of the return map on the section")
        .def_property_readonly("stability", [](const RotatingAttractor& r) { return stability_name(r.stability); })
        .def_readonly("residual", &RotatingAttractor::residual, "|return(q) - q| [m]")
        .def_readonly("wobble", &RotatingAttractor::wobble, "largest distance from q along the orbit [m]")
        .def_readonly("centre", &RotatingAttractor::centre, "the point the position circles [m] (the position when settled)")
        .def_readonly("radius", &RotatingAttractor::radius, "the position's distance from centre [m] (0: settled)")
        .def_readonly("pivot", &RotatingAttractor::pivot, "the part's point held at centre, in the part's frame [m]")
        .def("__repr__", [](const RotatingAttractor& r) {
            return "<plate.RotatingAttractor " + std::string(stability_name(r.stability)) + " at (" + num(r.q[0]) + ", " +
                   num(r.q[1]) + ") m, " + num(r.rate) + " rad/s>";
        });
    py::class_<FixedLine>(m, "FixedLine")
        .def(pickle_as<FixedLine>("plate.FixedLine"))
        .def_property_readonly("points", [](const FixedLine& l) { return l.points; })
        .def_readonly("direction", &FixedLine::direction)
        .def_property_readonly("stability", [](const FixedLine& l) { return stability_name(l.stability); })
        .def_readonly("eigenvalues", &FixedLine::eigenvalues)
        .def_readonly("length", &FixedLine::length)
        .def_readonly("eigen_error", &FixedLine::eigen_error)
        .def("__repr__", [](const FixedLine& l) {
            return "<plate.FixedLine " + std::string(stability_name(l.stability)) + ", " + std::to_string(l.points.size()) +
                   " points, length " + num(l.length) + " m>";
        });
    py::class_<PyFixedPoints>(m, "FixedPoints")
        .def(pickle_as<PyFixedPoints>("plate.FixedPoints"))
        .def_property_readonly("points", [](const PyFixedPoints& f) { return f.fp.points; })
        .def_property_readonly("lines", [](const PyFixedPoints& f) { return f.fp.lines; })
        .def_property_readonly("sentence", [](const PyFixedPoints& f) { return fixed_points_sentence(f.fp); })
        .def_property_readonly("undefined_cells", [](const PyFixedPoints& f) { return f.fp.undefined_cells; })
        .def_property_readonly("stuck_cells", [](const PyFixedPoints& f) { return f.fp.stuck_cells; })
        .def_property_readonly("stuck_regions", [](const PyFixedPoints& f) { return f.fp.stuck_regions; })
        .def_property_readonly("rotating", [](const PyFixedPoints& f) { return f.fp.rotating; })
        .def_property_readonly(
            "grid_too_coarse", [](const PyFixedPoints& f) { return f.fp.suggested_grid > 0; },
            "zeros found only where the corners' signs did not change, or near-zero cells left unsearched")
        .def_property_readonly(
            "summary", [](const PyFixedPoints& f) { return json_to_python(to_json(f.scene, f.fp)); },
            "the command line's JSON (`plate fixed-points`) as a dict")
        .def("__repr__", [](const PyFixedPoints& f) { return "<plate.FixedPoints: " + fixed_points_sentence(f.fp) + ">"; });
    m.def(
        "fixed_points",
        [](const PyField& f, double ftol, long max_rhs) {
            FixedPointOptions o;
            require(ftol > 0, "ftol: expected a number > 0");
            require(max_rhs >= 0, "max_rhs: expected >= 0 (0: no budget)");
            o.ftol = ftol;
            o.max_rhs_evaluations = max_rhs;
            return PyFixedPoints{f.scene, interruptible(py::none(), [&](Watch&) { return find_fixed_points(f.scene, f.f, o); })};
        },
        py::arg("field"), py::kw_only(), py::arg("ftol") = 1e-6, py::arg("max_rhs") = 20'000'000L,
        "Zeros of a field (from plate.field): candidate cells refined by Gauss-Newton, classified by the\n"
        "Jacobian's eigenvalues; curves of zeros as lines. Ctrl-C stops it (KeyboardInterrupt).");
}

}   // namespace plate::python
