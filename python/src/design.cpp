// plate.design (a plate motion for a target, verified: plate.Design), plate.orientation_harmonics,
// plate.coning_rate and plate.axis_peaks.
#include "bindings.hpp"
#include "interrupt.hpp"
#include "pickling.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <sstream>

namespace plate::python {

namespace {

// "KIND NUMBERS...", as the command line's --target takes it.
DesignTarget target_from_words(const std::string& words, bool point_part) {
    std::istringstream in(words);
    std::string kind, w;
    in >> kind;
    std::vector<double> values;
    while (in >> w) {
        std::size_t used = 0;
        double x = 0;
        try {
            x = std::stod(w, &used);
        } catch (const std::exception&) {
            used = 0;
        }
        require(used == w.size() && std::isfinite(x), "target: expected KIND and numbers, got '" + w + "'");
        values.push_back(x);
    }
    return parse_design_target(kind, values, point_part);
}

}   // namespace

DesignTarget design_target_from_kwargs(const std::optional<std::pair<double, double>>& sink,
                                       const std::optional<std::pair<double, double>>& transport,
                                       const std::optional<std::tuple<double, double, double>>& fixed_point,
                                       const std::optional<double>& orient,
                                       const std::optional<std::tuple<double, double, double>>& line_sink,
                                       const std::optional<std::string>& target, bool point_part) {
    require(sink.has_value() + transport.has_value() + fixed_point.has_value() + orient.has_value() + line_sink.has_value() +
                    target.has_value() ==
                1,
            "design: give one target, sink=(x, y), transport=(vx, vy), fixed_point=(x, y, theta), orient=theta, "
            "line_sink=(x, y, phi) or target='KIND NUMBERS' as the command line's --target");
    // Every form goes through the library's parser (the command line's and campaigns' too).
    try {
        if (target) return target_from_words(*target, point_part);
        if (sink) return parse_design_target("sink", {sink->first, sink->second}, point_part);
        if (transport) return parse_design_target("transport", {transport->first, transport->second}, point_part);
        if (fixed_point) {
            const auto& [x, y, theta] = *fixed_point;   // (a point part's fixed point has no orientation)
            return parse_design_target("fixed-point", point_part ? std::vector<double>{x, y} : std::vector<double>{x, y, theta},
                                       point_part);
        }
        if (orient) return parse_design_target("orient", {*orient}, point_part);
        const auto& [x, y, phi] = *line_sink;
        return parse_design_target("line-sink", {x, y, phi}, point_part);
    } catch (const std::invalid_argument& e) {
        throw py::value_error(e.what());
    }
}

namespace {

// plate.design's result: the library's summary and the command line's JSON of it.
struct PyDesign : DesignSummary {
    nlohmann::json summary;
};

}   // namespace

namespace pickling {
void io(Archive& a, PyDesign& d) { a(static_cast<DesignSummary&>(d), d.summary); }
}   // namespace pickling

namespace {

// plate.design: the target and the options as keyword arguments, judged as the command line's.
void bind_design_function(py::module_& m) {
    m.def(
        "design",
        [](const Scene& part, std::optional<std::pair<double, double>> sink, std::optional<std::pair<double, double>> transport,
           std::optional<std::tuple<double, double, double>> fixed_point, std::optional<double> orient,
           std::optional<std::tuple<double, double, double>> line_sink, std::optional<std::pair<double, double>> limits,
           double period, std::uint64_t seed, int starts, std::optional<int> evaluations, int verify_starts, int threads,
           double hold, double max_coning, std::vector<std::string> axes, std::optional<int> harmonics,
           std::optional<std::string> target, std::optional<double> lin_limit, std::optional<double> ang_limit,
           std::optional<int> local_evaluations, std::optional<int> max_harmonic,
           std::optional<std::pair<double, double>> corner_limits, std::optional<std::pair<double, double>> plate_half_size) {
            const DesignTarget t =
                design_target_from_kwargs(sink, transport, fixed_point, orient, line_sink, target, part.part.point);
            DesignOptions o;   // (judged in the library: validate_design_options, as for the CLI and campaigns)
            // (the old spellings: lin_limit and ang_limit for limits, local_evaluations, max_harmonic)
            const std::optional<std::pair<double, double>> old_limits =
                lin_limit || ang_limit
                    ? std::optional(std::pair(lin_limit.value_or(o.lin_limit), ang_limit.value_or(o.ang_limit)))
                    : std::nullopt;
            const auto [lin, ang] =
                renamed(limits, old_limits, "limits", lin_limit ? "lin_limit" : "ang_limit", std::pair(o.lin_limit, o.ang_limit));
            o.lin_limit = lin;
            o.ang_limit = ang;
            if (corner_limits) std::tie(o.corner_displacement_limit, o.corner_velocity_limit) = *corner_limits;
            if (plate_half_size) o.plate_half_size = Vec2(plate_half_size->first, plate_half_size->second);
            o.period = period;
            o.seed = seed;
            o.starts = starts;
            o.local_evaluations =
                renamed(evaluations, local_evaluations, "evaluations", "local_evaluations", o.local_evaluations);
            o.verify_starts = verify_starts;
            o.threads = threads;
            o.hold = hold;
            o.max_coning = max_coning;
            for (const std::string& name : axes) {
                int k = 0;
                while (k < 6 && name != axis_name(static_cast<Axis>(k))) ++k;
                require(k < 6, "axes: expected names among x, y, z, rx, ry, rz, got '" + name + "'");
                o.axes.push_back(static_cast<Axis>(k));
            }
            o.max_harmonic = renamed(harmonics, max_harmonic, "harmonics", "max_harmonic", 0);
            PyDesign d{interruptible(py::none(), [&](Watch&) { return design(part, t, o); }),
                       {}};   // (invalid_argument: ValueError)
            d.summary = design_summary_json(d, part, t, o, "");
            d.summary["scene"] = nullptr;   // (no file: the designed scene is .scene)
            return d;
        },
        py::arg("part"), py::kw_only(), py::arg("sink") = py::none(), py::arg("transport") = py::none(),
        py::arg("fixed_point") = py::none(), py::arg("orient") = py::none(), py::arg("line_sink") = py::none(),
        py::arg("limits") = py::none(), py::arg("period") = 0.0, py::arg("seed") = 1, py::arg("starts") = 0,
        py::arg("evaluations") = py::none(), py::arg("verify_starts") = 20, py::arg("threads") = 0, py::arg("hold") = 120.0,
        py::arg("max_coning") = -1.0, py::arg("axes") = std::vector<std::string>{}, py::arg("harmonics") = py::none(),
        py::arg("target") = py::none(), py::arg("lin_limit") = py::none(), py::arg("ang_limit") = py::none(),
        py::arg("local_evaluations") = py::none(), py::arg("max_harmonic") = py::none(), py::arg("corner_limits") = py::none(),
        py::arg("plate_half_size") = py::none(),
        "Designs a plate motion within the peak limits (limits=(LIN, ANG), default (20, 150): LIN [m/s^2]\n"
        "for x, y, z and ANG [rad/s^2] for rx, ry, rz bound the peak over the period of each axis' summed\n"
        "signal; `peaks`; the command line's --limits), optionally within corner_limits=(DISP, VEL) [m, m/s]\n"
        "on the peak displacement and velocity of the plate's corners at +-plate_half_size [m] (default the\n"
        "flight check's square; `corner_peaks`; --corner-limits, --plate-half-size), and without\n"
        "flight, and verifies it (grid and\n"
        "full dynamics; sinks and fixed points also by a part released at the target staying within 5 mm\n"
        "for `hold` seconds, which limits a sink's coning unless max_coning >= 0 sets it [rad/s]).\n"
        "sink=(x, y) for a rigid part: its position ends at\n"
        "(x, y) whatever its orientation (`pulls`). Point parts: sink=(x, y) the unique stable fixed point of its field,\n"
        "line_sink=(x, y, phi) every start ends on the line through (x, y) along phi, or\n"
        "transport=(vx, vy) a uniform velocity over the plate (also a rigid part with one friction coefficient). Rigid parts: "
        "orient=theta for a part whose\n"
        "contacts' friction differs (a plate that only translates turns it like a weathervane; `ring` gives\n"
        "theta' over a turn); fixed_point=(x, y, theta), and orient for one friction coefficient: the summary\n"
        "gives the basin share and the competing fixed points (where no unique fixed point is found, a half-turn\n"
        "pair: theta and theta + pi both stable, unique False; see the README). axes=['x', ...] and\n"
        "harmonics=n narrow each target's motion family (the others stay zero; an empty family is a ValueError);\n"
        "evaluations: per start of the search (default 400). The old spellings lin_limit, ang_limit,\n"
        "local_evaluations and max_harmonic still work, with a DeprecationWarning, for one release.\n"
        "target='KIND NUMBERS' is any target as the command line's --target writes it (e.g. 'sink 0.02 -0.01'),\n"
        "judged by the same parser: what one refuses, the other refuses with the same message.");
}

}   // namespace

void bind_design(py::module_& m) {
    py::class_<PyDesign>(m, "Design", "A designed plate motion and its verification (plate.design).")
        .def(pickling::pickle_as<PyDesign>("plate.Design"))
        .def_property_readonly(
            "summary", [](const PyDesign& d) { return json_to_python(d.summary); },
            "the command line's JSON (`plate design`) as a dict ('scene': None, the designed scene being .scene)")
        .def("__repr__",
             [](const PyDesign& d) {
                 return "<plate.Design '" + d.scene.name + "': " + (d.verified ? "verified" : "not verified") +
                        (d.unique ? ", unique" : "") + ", rate " + num(d.rate) + " 1/s" +
                        (d.failure.empty() ? "" : " (" + d.failure + ")") + ">";
             })
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
        .def_property_readonly(
            "ring",
            [](const PyDesign& s) {
                std::vector<std::tuple<double, Vec3>> r;
                for (std::size_t k = 0; k < s.ring_theta.size(); ++k) r.emplace_back(s.ring_theta[k], s.ring_twist[k]);
                return r;
            },
            "orient by transport: (theta, twist) at the centre on the verification's ring of orientations")
        .def_readonly("basin_share", &DesignSummary::basin_share,
                      "rigid parts: the share of the verification runs that end at the target")
        .def_readonly("basin_share_bound", &DesignSummary::basin_share_bound,
                      "the largest share the design's symmetry allows (a half-turn pair: below 1)")
        .def_property_readonly(
            "competitors",
            [](const PyDesign& s) {
                std::vector<std::tuple<Vec3, double>> r;
                for (const auto& c : s.competitors) r.emplace_back(c.point.q, c.basin_share);
                return r;
            },
            "rigid parts: the other stable fixed points on the grid, (q, share of the runs ending there)")
        .def_property_readonly(
            "runs",
            [](const PyDesign& s) {
                std::vector<std::tuple<double, double, double, double>> r;
                for (const DesignStartRun& x : s.runs) r.emplace_back(x.x, x.y, x.seconds, x.end_distance);
                return r;
            },
            "(x, y, seconds, end distance) of each verification run")
        .def_property_readonly(
            "held", [](const PyDesign& s) { return std::make_tuple(s.held.seconds, s.held.end, s.held.end_distance); },
            "sinks and fixed points: (seconds, end, distance) of the part released at rest at the target")
        .def_readonly("coning", &DesignSummary::coning, "the design's coning rate [rad/s] (plate.coning_rate)")
        .def_readonly("peaks", &DesignSummary::peaks,
                      "the designed motion's peak per axis over the period, x y z [m/s^2], rx ry rz [rad/s^2] "
                      "(plate.axis_peaks): what limits bound")
        .def_property_readonly(
            "corner_peaks",
            [](const PyDesign& s) { return std::make_tuple(s.corner_peaks.displacement, s.corner_peaks.velocity); },
            "the designed motion's corners (at +-corner_half_size): (peak displacement [m], peak velocity [m/s]) "
            "(plate.corner_peaks): what corner_limits bound")
        .def_readonly("corner_half_size", &DesignSummary::corner_half_size, "the plate's corners the corner peaks are at [m]")
        .def_property_readonly(
            "pulls",
            [](const PyDesign& s) {
                std::vector<std::tuple<double, Vec2, Eigen::Vector2cd>> r;
                for (const auto& p : s.pulls) r.emplace_back(p.theta, p.zero, p.eigenvalues);
                return r;
            },
            "a rigid part's sink: (theta, where the position's field vanishes, its eigenvalues) per orientation");
    bind_design_function(m);
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
    m.def(
        "coning_rate", [](const Scene& sc) { return coning_rate(sc.plate); }, py::arg("scene"),
        "The plate's steady yaw drift from rx and ry out of phase [rad/s], which the asymptotic field does\n"
        "not see and the full dynamics does: sum_n Im(A_rx,n conj A_ry,n) / (2 (n w)^3).");
    m.def(
        "axis_peaks", [](const Scene& sc) { return axis_peaks(sc.plate); }, py::arg("scene"),
        "The peak over the period of each axis' summed plate acceleration |u_a(t)|, x y z [m/s^2], rx ry rz\n"
        "[rad/s^2]: what actuators saturate on, and what plate.design's limits bound.");
    m.def(
        "corner_peaks",
        [](const Scene& sc, const std::pair<double, double>& half_size) {
            require(half_size.first >= 0 && half_size.second >= 0 && std::isfinite(half_size.first) &&
                        std::isfinite(half_size.second),
                    "corner_peaks: half_size: expected two finite lengths >= 0 [m]");
            const CornerPeaks p = corner_peaks(sc.plate, Vec2(half_size.first, half_size.second));
            return std::make_tuple(p.displacement, p.velocity);
        },
        py::arg("scene"), py::arg("half_size"),
        "(peak displacement [m], peak velocity [m/s]) over the period of the plate's corners at\n"
        "(+-half_size[0], +-half_size[1]) [m], to first order in the plate's rotation: what plate.design's\n"
        "corner_limits bound.");
}

}   // namespace plate::python
