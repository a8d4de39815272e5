// Design targets in words, judged once (design_target.hpp), and the summary as JSON.
#include "internal.hpp"

#include "plate/scene_io.hpp"

#include <nlohmann/json.hpp>

#include <deque>
#include <mutex>

namespace plate {

using namespace design_detail;

namespace {

struct BuiltIn {
    DesignTargetKind kind;
    const char* name;
};
constexpr BuiltIn kBuiltIn[] = {{DesignTargetKind::Sink, "sink"},
                                {DesignTargetKind::FixedPoint, "fixed-point"},
                                {DesignTargetKind::Orient, "orient"},
                                {DesignTargetKind::LineSink, "line-sink"},
                                {DesignTargetKind::Transport, "transport"}};

std::mutex registry_mutex;
std::deque<DesignTargetType>& registry() {   // (a deque: entries never move)
    static std::deque<DesignTargetType> r;
    return r;
}

std::string number_text(double x) {
    std::ostringstream s;
    s.precision(3);
    s << x;
    return s.str();
}

}   // namespace

namespace design_detail {

const DesignTargetType* registered(const std::string& name) {
    std::lock_guard<std::mutex> lock(registry_mutex);
    for (const DesignTargetType& r : registry())
        if (r.name == name) return &r;   // (entries never move or go: the pointer stays valid)
    return nullptr;
}

}   // namespace design_detail

std::string design_target_usage() {
    std::string s =
        "sink X Y, fixed-point X Y (point part) or X Y THETA (rigid part), orient THETA, line-sink X Y PHI "
        "or transport VX VY [OMEGA]";
    std::lock_guard<std::mutex> lock(registry_mutex);
    for (const DesignTargetType& r : registry()) s += ", " + r.name + (r.numbers.empty() ? "" : " " + r.numbers);
    return s;
}

DesignTarget parse_design_target(const std::string& kind, const std::vector<double>& v, bool point_part) {
    DesignTarget t;
    const BuiltIn* b = nullptr;
    for (const BuiltIn& x : kBuiltIn)
        if (kind == x.name) b = &x;
    if (const DesignTargetType* r = b ? nullptr : registered(kind)) {
        if (static_cast<int>(v.size()) != r->count) throw std::invalid_argument(kind + ": expected " + kind + " " + r->numbers);
        t.kind = DesignTargetKind::Registered;
        t.name = kind;
        t.values = v;
        return t;
    }
    if (!b) throw std::invalid_argument(kind + ": expected " + design_target_usage());
    const std::size_t want = b->kind == DesignTargetKind::Orient ? 1
                             : (b->kind == DesignTargetKind::FixedPoint && !point_part) || b->kind == DesignTargetKind::LineSink
                                 ? 3
                                 : 2;
    if (v.size() != want && !(b->kind == DesignTargetKind::Transport && v.size() == 3))
        throw std::invalid_argument(kind + ": expected " + design_target_usage());
    t.kind = b->kind;
    switch (b->kind) {
        case DesignTargetKind::Sink:
        case DesignTargetKind::FixedPoint:
            t.at = Vec2(v[0], v[1]);
            if (v.size() == 3) t.theta = v[2];
            break;
        case DesignTargetKind::Orient:
            t.theta = v[0];
            break;
        case DesignTargetKind::LineSink:
            t.at = Vec2(v[0], v[1]);
            t.theta = v[2];
            break;
        case DesignTargetKind::Transport:
            t.velocity = Vec2(v[0], v[1]);
            if (v.size() == 3) t.omega = v[2];
            break;
        case DesignTargetKind::Registered:
            break;
    }
    return t;
}

std::string design_target_kind(const DesignTarget& t) {
    if (t.kind == DesignTargetKind::Registered) return t.name;
    for (const BuiltIn& x : kBuiltIn)
        if (x.kind == t.kind) return x.name;
    return "";
}

std::vector<double> design_target_values(const DesignTarget& t, bool point_part) {
    switch (t.kind) {
        case DesignTargetKind::Sink:
            return {t.at.x(), t.at.y()};
        case DesignTargetKind::FixedPoint:
            return point_part ? std::vector<double>{t.at.x(), t.at.y()} : std::vector<double>{t.at.x(), t.at.y(), t.theta};
        case DesignTargetKind::Orient:
            return {t.theta};
        case DesignTargetKind::LineSink:
            return {t.at.x(), t.at.y(), t.theta};
        case DesignTargetKind::Transport:
            return t.omega != 0 ? std::vector<double>{t.velocity.x(), t.velocity.y(), t.omega}
                                : std::vector<double>{t.velocity.x(), t.velocity.y()};
        case DesignTargetKind::Registered:
            return t.values;
    }
    return {};
}

void validate_design_options(const DesignOptions& o) {
    // Every design is verified in full dynamics before it is reported: no runs, no verification (the
    // sinks, lines, transports and orienters would otherwise pass on the field alone).
    if (o.verify_starts < 1)
        throw std::invalid_argument("verify_starts must be at least 1 (designs are verified in full dynamics)");
    const auto require = [](bool ok, const std::string& what) {
        if (!ok) throw std::invalid_argument(what);
    };
    require(o.lin_limit >= 0 && o.ang_limit >= 0 && o.lin_limit <= kMaxAmplitude && o.ang_limit <= kMaxAmplitude,
            "limits: expected amplitudes from 0 to " + number_text(kMaxAmplitude));
    require(o.corner_displacement_limit >= 0 && o.corner_displacement_limit <= 1 && o.corner_velocity_limit >= 0 &&
                o.corner_velocity_limit <= 100,
            "corner_limits: expected a displacement from 0 to 1 m and a velocity from 0 to 100 m/s (0: none)");
    require(o.plate_half_size.x() >= 0 && o.plate_half_size.y() >= 0 && o.plate_half_size.x() <= 10 &&
                o.plate_half_size.y() <= 10 && (o.plate_half_size.x() > 0) == (o.plate_half_size.y() > 0),
            "plate_half_size: expected both zero (the flight check's square) or both in (0, 10] m");
    require(o.period == 0 || (o.period >= kPeriodRange[0] && o.period <= kPeriodRange[1]),
            "period: expected 0 (the part scene's) or " + number_text(kPeriodRange[0]) + " to " + number_text(kPeriodRange[1]) +
                " s");
    require(o.hold >= 0 && o.hold <= 3600, "hold: expected 0 to 3600 s (0: not checked)");
    require(!std::isnan(o.max_coning), "max_coning: expected a number (negative: from the hold; infinite: no limit)");
    require(o.starts >= 0, "starts: expected >= 0 (0: the target's default)");
    require(o.local_evaluations >= 1, "local_evaluations: expected >= 1");
    require(o.max_harmonic >= 0, "max_harmonic: expected >= 0 (0: the target's own)");
    if (o.robust) validate_uncertainty(*o.robust);
    require(o.robust_radius > 0 && o.robust_radius <= 0.05, "robust_radius: expected 0 to 0.05 m");
    require(o.robust_angle > 0 && o.robust_angle <= kPi, "robust_angle: expected 0 to pi rad");
    require(o.robust_share > 0 && o.robust_share <= 1, "robust_share: expected a share in (0, 1]");
    require(o.robust_draws >= 1 && o.robust_draws <= 100000, "robust_draws: expected 1 to 100000");
    require(o.robust_full_draws >= 0 && o.robust_full_draws <= o.robust_draws, "robust_full_draws: expected 0 to robust_draws");
    require(o.arrive > 0 && o.arrive <= 3600, "arrive: expected 0 to 3600 s");
}

void validate_design_target(const DesignTarget& target, const Scene& part_scene, const DesignOptions& opt) {
    const double T = opt.period > 0 ? opt.period : part_scene.plate.T;
    if (!(T > 0)) throw std::invalid_argument("no plate period (give one)");
    const bool rigid = !part_scene.part.point;
    if (target.kind == DesignTargetKind::Registered) {
        const DesignTargetType* r = registered(target.name);
        if (!r) throw std::invalid_argument("unknown target '" + target.name + "'");
        if (rigid ? !r->rigid : !r->point)
            throw std::invalid_argument("a " + r->name + " target is built for " + (rigid ? "point" : "rigid") + " parts only");
        return;
    }
    if (opt.robust && target.kind != DesignTargetKind::Sink && target.kind != DesignTargetKind::FixedPoint)
        throw std::invalid_argument(
            "robust: designed for sinks and fixed points only (the outcomes of plate robustness are "
            "about a fixed point)");
    if (opt.robust && rigid && target.kind == DesignTargetKind::Sink)
        throw std::invalid_argument(
            "robust: a rigid part's sink leaves its orientation free, so it has no fixed point to "
            "follow over the draws; design a fixed point");
    if (target.kind == DesignTargetKind::Transport) {
        if (!(target.velocity.norm() > 0)) throw std::invalid_argument("a transport target needs a velocity");
        if (target.omega != 0)
            throw std::invalid_argument(
                "transport with a turn: a plate that only translates cannot turn a part with one "
                "friction coefficient, and a turning plate's alpha x s makes the twist depend on "
                "position (a whirl), so no uniform twist with OMEGA != 0 is designed (DesignTarget)");
        if (rigid && friction_differs(part_scene.part))
            throw std::invalid_argument(
                "transport of a part whose contacts' friction differs: a translating plate turns it "
                "(the weathervane) and its velocity with it, so it has no uniform twist (try orient)");
        return;
    }
    if (!(std::abs(target.at.x()) <= opt.region && std::abs(target.at.y()) <= opt.region))
        throw std::invalid_argument("the target lies outside the plate region");
    if (rigid && target.kind == DesignTargetKind::LineSink)
        throw std::invalid_argument("a line sink is built for point parts only");
    if (!rigid && target.kind == DesignTargetKind::Orient) throw std::invalid_argument("a point part has no orientation to set");
}

void register_design_target(DesignTargetType type) {
    if (type.name.empty() || !type.design) throw std::invalid_argument("a design target needs a name and a designer");
    std::lock_guard<std::mutex> lock(registry_mutex);
    for (const BuiltIn& x : kBuiltIn)
        if (type.name == x.name) throw std::invalid_argument("design target '" + type.name + "' exists");
    for (const DesignTargetType& r : registry())
        if (r.name == type.name) throw std::invalid_argument("design target '" + type.name + "' exists");
    registry().push_back(std::move(type));
}


}   // namespace plate
