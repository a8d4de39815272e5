// The archive of pickling.hpp and each library struct's members, listed once (written and read by the
// same list). A member added to one of these structs must be added here; python/tests/test_pickle.py
// compares every property and the summary of each result after a round trip.
#include "pickling.hpp"

#include <mutex>
#include <set>
#include <stdexcept>

namespace plate::python::pickling {

void Archive::raw(void* p, std::size_t n) {
    if (!reading_) {
        buf_.append(static_cast<const char*>(p), n);
        return;
    }
    if (n > left()) throw std::invalid_argument("a pickled state that ends early (not one this module wrote)");
    if (n > 0) std::memcpy(p, buf_.data() + pos_, n);
    pos_ += n;
}

std::size_t count(Archive& a, std::size_t n, std::size_t least) {
    std::uint64_t k = n;
    io(a, k);
    if (a.reading() && k > a.left() / least)
        throw std::invalid_argument("a pickled state with a count beyond its length (not one this module wrote)");
    return static_cast<std::size_t>(k);
}

void io(Archive& a, std::string& s) {
    const std::size_t n = count(a, s.size(), 1);
    if (a.reading()) s.assign(n, '\0');
    a.raw(s.data(), n);
}

void io(Archive& a, const char*& s) {
    static std::mutex lock;
    static std::set<std::string> interned;   // (a set's strings stay where they are)
    std::string text = a.reading() ? std::string() : std::string(s);
    io(a, text);
    if (!a.reading()) return;
    std::lock_guard<std::mutex> hold(lock);
    s = interned.insert(text).first->c_str();
}

void io(Archive& a, std::vector<bool>& v) {
    const std::size_t n = count(a, v.size(), 1);
    if (a.reading()) v.assign(n, false);
    for (std::size_t i = 0; i < n; ++i) {
        bool b = v[i];
        io(a, b);
        v[i] = b;
    }
}

void io(Archive& a, nlohmann::json& j) {
    std::vector<std::uint8_t> cbor = a.reading() ? std::vector<std::uint8_t>() : nlohmann::json::to_cbor(j);
    io(a, cbor);
    if (a.reading()) j = nlohmann::json::from_cbor(cbor);
}

void io(Archive& a, Scene& s) {
    std::string text = a.reading() ? std::string() : scene_to_json(s).dump();
    std::string source = s.source;
    a(text, source);
    if (a.reading()) s = parse_scene(text, source);
}

void io(Archive& a, StopEvent& e) { a(e.reason, e.contact, e.t); }
void io(Archive& a, GridSpec& g) { a(g.nx, g.ny, g.nth, g.x0, g.x1, g.y0, g.y1, g.th0); }
void io(Archive& a, IntegrationOptions& o) { a(o.rtol, o.slip_eps, o.h_min, o.h0, o.max_steps, o.large_slip_factor); }
void io(Archive& a, LimitCycleOptions& o) {
    a(o.integration, o.tol, o.max_periods, o.record, o.restarts, o.solver, o.anderson_memory, o.max_rhs_evaluations,
      o.first_period_tight);
}
void io(Archive& a, FixedPointOptions& o) {
    a(o.cycle, o.ftol, o.max_newton, o.null_ratio, o.max_rhs_evaluations, o.max_orbit_starts);
}

void io(Archive& a, FixedPoint& p) { a(p.q, p.eigenvalues, p.stability, p.residual, p.eigen_error); }
void io(Archive& a, FixedLine& l) { a(l.points, l.direction, l.stability, l.eigenvalues, l.length, l.eigen_error); }
void io(Archive& a, StuckRegion& r) { a(r.lo, r.hi, r.all_theta, r.grid_points, r.touches_edge); }
void io(Archive& a, RotatingAttractor& r) {
    a(r.q, r.rate, r.period, r.multipliers, r.stability, r.residual, r.wobble, r.centre, r.radius, r.pivot);
}
void io(Archive& a, FixedPoints& f) {
    a(f.point_part, f.points, f.lines, f.candidates, f.cells, f.undefined_cells, f.unsearched_cells, f.stuck_cells, f.evaluations,
      f.rhs_evaluations, f.stuck_regions, f.rotating, f.near_zero_cells, f.near_zero_unsearched, f.coarse_zeros,
      f.unresolved_cells, f.suggested_grid);
}

void io(Archive& a, DesignStartRun& r) { a(r.x, r.y, r.theta, r.end, r.end_distance, r.seconds, r.from, r.at_from, r.stop); }
void io(Archive& a, DesignSummary::Competitor& c) { a(c.point, c.basin_share); }
void io(Archive& a, DesignSummary::OrientationPull& p) { a(p.theta, p.zero, p.eigenvalues); }
void io(Archive& a, DesignSummary& d) {
    a(d.verified, d.unique, d.failure, d.scene, d.rate, d.eigenvalues, d.eigenvalues3, d.starts, d.evaluations, d.cycles,
      d.fixed_points, d.fixed_point, d.fixed_point_eigenvalues, d.basin_share, d.basin_share_bound, d.competitors, d.runs,
      d.worst_end_distance, d.held, d.coning, d.peaks, d.corner_peaks.displacement, d.corner_peaks.velocity, d.corner_half_size,
      d.min_vertical_margin, d.pulls, d.ring_theta, d.ring_twist, d.transport_mean, d.transport_turn, d.transport_spread,
      d.transport_tolerance, d.seconds, d.predicted_radius95, d.robustness, d.notes);
}

void io(Archive& a, Spread& s) { a(s.spread, s.distribution); }
void io(Archive& a, UncertaintySpec& u) {
    a(u.source, u.seed, u.friction, u.mass, u.inertia, u.contacts_mm, u.com_offset_mm, u.amplitude, u.phase, u.unmodelled_up_to,
      u.unmodelled_rms_fraction, u.period);
}
void io(Archive& a, UncertainParameter& p) { a(p.name, p.unit, p.standard_deviation); }
void io(Archive& a, Sensitivity& s) { a(s.parameter, s.dq, s.variance_share); }
void io(Archive& a, DrawResult& d) {
    a(d.index, d.outcome, d.note, d.matched, d.fixed_point, d.rate, d.attractors, d.p, d.arrival, d.arrival_full);
}
void io(Archive& a, RobustnessSummary& s) {
    a(s.nominal, s.target, s.nominal_result, s.draws, s.starts, s.counts, s.mean_offset, s.radius95, s.angle95, s.covariance,
      s.sensitivities, s.jacobian, s.predicted_covariance, s.predicted_radius95, s.predicted_angle95, s.sensitivity_seconds,
      s.linear_error_median, s.linear_error_max, s.nonlinear_draws, s.notes, s.seconds);
}
void io(Archive& a, RobustnessOptions& o) {
    a(o.draws, o.target, o.grid, o.fixed, o.match_distance, o.match_angle, o.starts, o.arrive_distance, o.arrive_angle, o.horizon,
      o.curve_step, o.full_draws, o.sensitivities, o.threads);
}

void heading(Archive& a, const char* kind) {
    const std::string want = std::string(kind) + " " + PLATE_VERSION;
    std::string got = want;
    io(a, got);
    if (a.reading() && got != want)
        throw std::invalid_argument(std::string(kind) + ": a pickled state of '" + got.substr(0, 60) + "', expected '" + want +
                                    "' (pickles are read by the version of plate that wrote them)");
}

void finished(const Archive& a, const char* kind) {
    if (a.left() != 0)
        throw std::invalid_argument(std::string(kind) + ": a pickled state with " + std::to_string(a.left()) +
                                    " bytes beyond its last member (not one this module wrote)");
}

}   // namespace plate::python::pickling
