#include "internal.hpp"

namespace plate {

using namespace design_detail;

double sink_coning_limit(const Vec2& at, const DesignOptions& opt) {
    if (opt.max_coning >= 0) return opt.max_coning;
    const double walk = at.norm() * opt.hold;   // [m s]: the sink's walk per unit coning rate
    return walk > 0 ? 0.5 * opt.verify_distance / walk : std::numeric_limits<double>::infinity();
}

int default_starts(const Scene& part_scene, const DesignTarget& target) {
    const bool sink = target.kind == DesignTargetKind::Sink || target.kind == DesignTargetKind::LineSink ||
                      (target.kind == DesignTargetKind::FixedPoint && part_scene.part.point);
    return sink ? 4 : 16;
}


}  // namespace plate

namespace plate::design_detail {

DesignSummary dispatch(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt) {
    const double T = opt.period > 0 ? opt.period : part_scene.plate.T;
    if (!(T > 0)) throw std::invalid_argument("no plate period (give one)");
    if (target.kind == DesignTargetKind::Transport) {
        if (!(target.velocity.norm() > 0)) throw std::invalid_argument("a transport target needs a velocity");
        if (target.omega != 0)
            throw std::invalid_argument("transport with a turn: a plate that only translates cannot turn a part with one "
                                        "friction coefficient, and a turning plate's alpha x s makes the twist depend on "
                                        "position (a whirl), so no uniform twist with OMEGA != 0 is designed (DesignTarget)");
        if (!part_scene.part.point) {
            const auto mu = part_scene.part.mu.head(part_scene.part.contacts());
            if (mu.maxCoeff() > mu.minCoeff() * (1 + 1e-9))
                throw std::invalid_argument("transport of a part whose contacts' friction differs: a translating plate turns it "
                                            "(the weathervane) and its velocity with it, so it has no uniform twist (try orient)");
        }
        return design_transport(part_scene, target, opt, T);
    }
    if (!(std::abs(target.at.x()) <= opt.region && std::abs(target.at.y()) <= opt.region))
        throw std::invalid_argument("the target lies outside the plate region");
    if (!part_scene.part.point) {
        // (with one friction coefficient on every contact a translating plate cannot turn the part:
        // the rotating plate's search, design_rigid, is left)
        const auto mu = part_scene.part.mu.head(part_scene.part.contacts());
        if (target.kind == DesignTargetKind::Orient && mu.maxCoeff() > mu.minCoeff() * (1 + 1e-9))
            return design_orient(part_scene, target, opt, T);
        if (target.kind == DesignTargetKind::LineSink)
            throw std::invalid_argument("a line sink is built for point parts only");
        if (target.kind == DesignTargetKind::Sink) return design_sink(part_scene, target, opt, T);
        if (target.kind != DesignTargetKind::FixedPoint) return design_rigid(part_scene, target, opt, T);
        // The half-turn pair first, broken where rz about its centre leaves one stable fixed point
        // (design_rigid_pair, break_pair); where the pair itself fails (no sink for this part), the
        // general search over all six axes at n = 1, 2 (design_rigid).
        DesignSummary pair = design_rigid_pair(part_scene, target, opt, T);
        if (pair.verified) return pair;
        DesignSummary general = design_rigid(part_scene, target, opt, T);
        std::ostringstream note;
        note.precision(3);
        note << "the half-turn pair failed (" << pair.failure << "; " << pair.evaluations << " evaluations, " << pair.seconds
             << " s, counted below)";
        general.notes.insert(general.notes.begin(), note.str());
        general.evaluations += pair.evaluations;
        general.cycles += pair.cycles;
        general.starts += pair.starts;   // (both searches')
        general.seconds += pair.seconds;
        return general;
    }
    if (target.kind == DesignTargetKind::Orient) throw std::invalid_argument("a point part has no orientation to set");
    if (target.kind == DesignTargetKind::LineSink) return design_line_sink(part_scene, target, opt, T);
    return design_sink(part_scene, target, opt, T);
}

}  // namespace plate::design_detail

namespace plate {

using namespace design_detail;

DesignSummary design(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt) {
    // Every design is verified in full dynamics before it is reported: no runs, no verification (the
    // sinks, lines, transports and orienters would otherwise pass on the field alone).
    if (opt.verify_starts < 1) throw std::invalid_argument("verify_starts must be at least 1 (designs are verified in full dynamics)");
    DesignOptions o = opt;
    if (o.starts <= 0) o.starts = default_starts(part_scene, target);
    DesignSummary sum = dispatch(part_scene, target, o);
    if (sum.starts == 0) sum.starts = o.starts;   // (set where a search ran its own number of starts)
    return sum;
}


}  // namespace plate
