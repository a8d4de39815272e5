// plate.identify: a part's friction and centre-of-mass offset from camera tracks (plate.Identification),
// identify/include/plate/identify.hpp.
#include "bindings.hpp"
#include "interrupt.hpp"
#include "pickling.hpp"

#include "plate/identify.hpp"
#include "plate/profile.hpp"

#include <algorithm>
#include <cmath>

namespace plate::python {

namespace {

struct PyIdentification {
    IdentifySummary s;
    IdentifyOptions o;
    bool profiled = false;
    ProfileSummary p;
    ProfileOptions po;
};

}   // namespace

// Each struct's members once (pickling.hpp).
namespace pickling {
void io(Archive& a, FittedParameter& p) {
    a(p.name, p.unit, p.estimate, p.sd, p.sd_cells, p.sd_envelope, p.lo, p.hi, p.identifiable, p.at_bound, p.dchi2_lo, p.dchi2_hi,
      p.linearity);
}
void io(Archive& a, Unidentifiable& u) { a(u.combination, u.half_width); }
void io(Archive& a, TrackFit& t) { a(t.source, t.frames, t.start, t.rms_xy_mm, t.rms_theta_mrad, t.chi2); }
void io(Archive& a, IdentifySummary& s) {
    a(s.params, s.covariance, s.unidentifiable, s.tracks, s.chi2, s.residuals, s.dof, s.reduced_chi2, s.p_value,
      s.explains_tracks, s.starts_run, s.best_start, s.held, s.iterations, s.coarse_iterations, s.coarse_seconds, s.cells_seconds,
      s.envelope_seconds, s.wide_iterations, s.wide_chi2_drop, s.wide_seconds, s.pieces, s.piece_iterations, s.hops,
      s.piece_seconds, s.termination, s.converged, s.seconds, s.start_costs, s.fitted);
}
void io(Archive& a, IdentifyOptions& o) {
    a(o.params, o.level, o.starts, o.seed, o.max_iterations, o.time_limit, o.settle_periods, o.rtol, o.threads,
      o.fit_starts_first, o.central_search, o.segment_seconds, o.segment_settle_periods, o.initial_trust_radius, o.jacobian_reuse,
      o.hops, o.coarse_iterations, o.cell_samples, o.envelope, o.wide_iterations, o.mu_min, o.mu_max, o.com_max);
}
void io(Archive& a, ProfilePoint& p) { a(p.value, p.dchi2); }
void io(Archive& a, ParameterProfile& p) {
    a(p.name, p.unit, p.estimate, p.points, p.lo, p.hi, p.lo_end, p.hi_end, p.bound_lo, p.bound_hi, p.linear_lo, p.linear_hi,
      p.lo_reported, p.hi_reported, p.interval_is_profile, p.identifiable, p.chi2_drop, p.verdict, p.simulations, p.seconds);
}
void io(Archive& a, ProfileSummary& s) { a(s.profiles, s.chi2_min, s.simulations, s.seconds); }
void io(Archive& a, ProfileOptions& o) {
    a(o.params, o.max_steps, o.max_iterations, o.max_simulations, o.time_limit, o.agreement);
}
void io(Archive& a, PyIdentification& r) { a(r.s, r.o, r.profiled, r.p, r.po); }
}   // namespace pickling

namespace {

// A track from a plate.Track or a track file's path, str or os.PathLike (read as the command line reads it).
Track track_of(const py::handle& t) {
    if (py::isinstance<Track>(t)) return t.cast<Track>();
    const auto path = path_of(t);
    require(path.has_value(), "tracks: expected plate.Track objects or track files' paths (str or os.PathLike)");
    return read_track_csv(*path);
}

// One number per fitted parameter, in the order asked.
py::array_t<double> per_parameter(const IdentifySummary& s, double FittedParameter::*field) {
    std::vector<double> v;
    for (const FittedParameter& p : s.params) v.push_back(p.*field);
    return array(v, {static_cast<py::ssize_t>(v.size())});
}

}   // namespace

namespace {

// plate.identify: the fit (and the profiles asked), judged as the command line's.
void bind_identify_function(py::module_& m) {
    m.def(
        "identify",
        [](const Scene& sc, const py::list& tracks, const std::vector<std::string>& params, const std::string& dynamics,
           int starts, std::uint64_t seed, int max_iterations, double time_limit, double settle_periods, double rtol, int threads,
           double pieces, int coarse, int wide, int cells, bool envelope, const py::object& profile, int profile_steps,
           double profile_time_limit) {
            require(dynamics == "full" || dynamics == "u", "dynamics: expected 'full' or 'u', got '" + dynamics + "'");
            std::vector<Track> tr;
            for (const py::handle& t : tracks) tr.push_back(track_of(t));
            PyIdentification r;
            r.o.params = params;
            r.o.level = dynamics == "full" ? Dynamics::Full : Dynamics::U;
            r.o.starts = starts;
            r.o.seed = seed;
            r.o.max_iterations = max_iterations;
            r.o.time_limit = time_limit;
            r.o.settle_periods = settle_periods;
            r.o.rtol = rtol;
            r.o.threads = threads;
            r.o.segment_seconds = pieces;
            r.o.coarse_iterations = coarse;
            r.o.wide_iterations = wide;
            r.o.cell_samples = cells;
            r.o.envelope = envelope;
            r.profiled = !profile.is_none();
            if (r.profiled && !(py::isinstance<py::str>(profile) && profile.cast<std::string>() == "all"))
                r.po.params = profile.cast<std::vector<std::string>>();
            r.po.max_steps = profile_steps;
            r.po.time_limit = profile_time_limit;
            if (r.profiled) r.po.validate();
            for (const std::string& name : r.po.params)
                require(std::find(params.begin(), params.end(), name) != params.end(),
                        "profile: " + name + " is not among the fitted params");
            r.s = interruptible(py::none(), [&](Watch&) { return identify(sc, tr, r.o); });
            if (r.profiled) r.p = interruptible(py::none(), [&](Watch&) { return profile_likelihood(sc, tr, r.o, r.s, r.po); });
            return r;
        },
        py::arg("scene"), py::arg("tracks"), py::arg("params"), py::kw_only(), py::arg("dynamics") = "full",
        py::arg("starts") = IdentifyOptions{}.starts, py::arg("seed") = IdentifyOptions{}.seed,
        py::arg("max_iterations") = IdentifyOptions{}.max_iterations, py::arg("time_limit") = IdentifyOptions{}.time_limit,
        py::arg("settle_periods") = IdentifyOptions{}.settle_periods, py::arg("rtol") = IdentifyOptions{}.rtol,
        py::arg("threads") = IdentifyOptions{}.threads, py::arg("pieces") = IdentifyOptions{}.segment_seconds,
        py::arg("coarse") = IdentifyOptions{}.coarse_iterations, py::arg("wide") = IdentifyOptions{}.wide_iterations,
        py::arg("cells") = IdentifyOptions{}.cell_samples, py::arg("envelope") = IdentifyOptions{}.envelope,
        py::arg("profile") = py::none(), py::arg("profile_steps") = ProfileOptions{}.max_steps,
        py::arg("profile_time_limit") = ProfileOptions{}.time_limit,
        "Fits the named parameters of `scene`'s part (mu_k, mu_k1..3, mu_s, mu_s1..3, com_x, com_y) to `tracks`\n"
        "(plate.Track objects or track files' paths) by least squares over the hybrid simulation, as `plate identify`.\n"
        "pieces: the search's first stage fits the tracks cut into pieces of this many seconds (0: none), as --pieces.\n"
        "coarse: before them, at most this many coarse steps of the kinetic coefficients and offsets, as --coarse.\n"
        "wide: after the search, at most this many wide steps (every coordinate and start) and line steps a rung, as --wide.\n"
        "cells: points drawn about the fit to find the spread over the chi-square's cells (0: none), as --cells.\n"
        "envelope: the within-cell sd widened to the secants' over several cells (False: not), as --no-envelope.\n"
        "Tracks from another set-up, too few frames or a bad file raise plate.InputError naming the file and line.\n"
        "profile='all' or a list of fitted names: their profile likelihoods too (plate identify --profile; at most\n"
        "profile_steps re-minimisations a side, all within profile_time_limit s), in .profiles and .summary.");
}

}   // namespace

void bind_identify(py::module_& m) {
    py::class_<PyIdentification>(m, "Identification",
                                 "A least-squares fit of a part's parameters to camera tracks (plate identify): estimates, "
                                 "their covariance and 95 % intervals, and what the tracks cannot separate.")
        .def(pickling::pickle_as<PyIdentification>("plate.Identification"))
        .def_property_readonly(
            "names",
            [](const PyIdentification& r) {
                std::vector<std::string> v;
                for (const FittedParameter& p : r.s.params) v.push_back(p.name);
                return v;
            },
            "the fitted parameters, in the order asked")
        .def_property_readonly(
            "estimates", [](const PyIdentification& r) { return per_parameter(r.s, &FittedParameter::estimate); },
            "the estimates (friction: 1, com_x/com_y: m)")
        .def_property_readonly(
            "sd", [](const PyIdentification& r) { return per_parameter(r.s, &FittedParameter::sd); },
            "standard deviations (the spread over the chi-square's cells and the envelope included); NaN where not "
            "identifiable")
        .def_property_readonly(
            "sd_cells", [](const PyIdentification& r) { return per_parameter(r.s, &FittedParameter::sd_cells); },
            "of sd, the spread over the chi-square's cells near the fit (sd^2 - sd_cells^2 - sd_envelope^2: within the "
            "fit's cell); NaN where not identifiable")
        .def_property_readonly(
            "sd_envelope", [](const PyIdentification& r) { return per_parameter(r.s, &FittedParameter::sd_envelope); },
            "of sd, the envelope's widening of the within-cell sd (secants over several cells; 0 where not wider); NaN "
            "where not identifiable")
        .def_property_readonly(
            "intervals",
            [](const PyIdentification& r) {
                std::vector<double> v;
                for (const FittedParameter& p : r.s.params) v.insert(v.end(), {p.lo, p.hi});
                return array(v, {static_cast<py::ssize_t>(r.s.params.size()), 2});
            },
            "95 % intervals, shape (parameters, 2); NaN rows where not identifiable")
        .def_property_readonly(
            "identifiable",
            [](const PyIdentification& r) {
                std::vector<bool> v;
                for (const FittedParameter& p : r.s.params) v.push_back(p.identifiable);
                return v;
            },
            "per parameter: False where the tracks cannot place it within its physical range")
        .def_property_readonly(
            "interval_check",
            [](const PyIdentification& r) {
                py::list out;
                for (const FittedParameter& p : r.s.params) {
                    py::dict d;
                    d["name"] = p.name;
                    d["dchi2_at_ends"] = py::make_tuple(p.dchi2_lo, p.dchi2_hi);
                    d["verdict"] = to_string(p.linearity);
                    out.append(d);
                }
                return out;
            },
            "per parameter, the 95 % interval within the fit's cell (estimate -+ 1.96 sqrt(sd^2 - sd_cells^2 - sd_envelope^2)) "
            "checked "
            "at its ends: a dict -- dchi2_at_ends (the chi-square's rise there along the linearised profile's path; "
            "3.84 where the chi-square is quadratic; NaN where not checked), verdict ('holds', 'too narrow', "
            "'unconfirmed' or 'not checked')")
        .def_property_readonly(
            "covariance", [](const PyIdentification& r) { return Eigen::MatrixXd(r.s.covariance); },
            "of the estimates, rows and columns as names (NaN where not identifiable)")
        .def_property_readonly(
            "chi2", [](const PyIdentification& r) { return r.s.chi2; }, "sum of squared noise-scaled residuals")
        .def_property_readonly(
            "reduced_chi2", [](const PyIdentification& r) { return r.s.reduced_chi2; },
            "chi2 / degrees of freedom: near 1 when the model and the cameras' noise are right")
        .def_property_readonly(
            "p_value", [](const PyIdentification& r) { return r.s.p_value; },
            "P(chi-square of dof degrees >= chi2): what the noise alone would exceed")
        .def_property_readonly(
            "explains_tracks", [](const PyIdentification& r) { return r.s.explains_tracks; },
            "p_value at or above 1e-3 (or NaN: no degrees of freedom, not judged); False: a local minimum (its intervals "
            "mean nothing), a model the tracks contradict, or noise sds too small (intervals too narrow)")
        .def_property_readonly("converged", [](const PyIdentification& r) { return r.s.converged; })
        .def_property_readonly(
            "fitted", [](const PyIdentification& r) { return r.s.fitted; }, "the scene at the estimates")
        .def_property_readonly(
            "profiles",
            [](const PyIdentification& r) {
                py::list out;
                for (const ParameterProfile& pr : r.p.profiles) {
                    std::vector<double> pts;
                    for (const ProfilePoint& q : pr.points) pts.insert(pts.end(), {q.value, q.dchi2});
                    py::dict d;
                    d["name"] = pr.name;
                    d["unit"] = pr.unit;
                    d["estimate"] = pr.estimate;
                    d["points"] = array(pts, {static_cast<py::ssize_t>(pr.points.size()), 2});
                    d["interval"] = py::make_tuple(pr.lo, pr.hi);
                    d["ends"] = py::make_tuple(to_string(pr.lo_end), to_string(pr.hi_end));
                    d["bounds"] = py::make_tuple(pr.bound_lo, pr.bound_hi);
                    d["interval_is_profile"] = pr.interval_is_profile;
                    d["reported"] = py::make_tuple(pr.lo_reported, pr.hi_reported);
                    d["identifiable"] = pr.identifiable;
                    d["verdict"] = pr.verdict;
                    d["simulations"] = pr.simulations;
                    d["seconds"] = pr.seconds;
                    out.append(d);
                }
                return out;
            },
            "the profile likelihoods asked (profile=): per parameter a dict -- points (value, chi2 - chi2_min) as an "
            "(n, 2) array, interval (lo, hi), ends ('crossed', 'at bound' or 'cut short'), bounds, interval_is_profile "
            "(the reported 95 % interval is the profile's, else the linearised one), reported (the profile's interval "
            "widened by the cells' spread, as reported where interval_is_profile), identifiable, verdict; [] if none")
        .def_property_readonly(
            "summary",
            [](const PyIdentification& r) {
                return json_to_python(r.profiled ? identify_json(r.s, r.o, r.p, r.po) : identify_json(r.s, r.o));
            },
            "the command line's JSON (plate identify --out, with --profile when profile= was given), as a dict")
        .def("__repr__", [](const PyIdentification& r) {
            std::string s = "<plate.Identification:";
            for (const FittedParameter& p : r.s.params)
                s += " " + p.name + " = " + std::to_string(p.estimate) +
                     (p.identifiable ? " +- " + std::to_string(1.96 * p.sd) : " (not identifiable)");
            if (!r.s.explains_tracks) s += " [does not explain the tracks: p = " + std::to_string(r.s.p_value) + "]";
            return s + ">";
        });
    bind_identify_function(m);
}

}   // namespace plate::python
