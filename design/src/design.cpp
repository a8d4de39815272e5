// design(): the options and the target judged once (design_target.cpp), then one dispatch table from
// the target's kind to its designer (one file per target family; registered kinds by name).
#include "internal.hpp"

namespace plate {

using namespace design_detail;

double sink_coning_limit(const Vec2& at, const DesignOptions& opt) {
    if (opt.max_coning >= 0) return opt.max_coning;
    const double walk = at.norm() * opt.hold;   // [m s]: the sink's walk per unit coning rate
    return walk > 0 ? 0.5 * opt.verify_distance / walk : std::numeric_limits<double>::infinity();
}

int default_starts(const Scene& part_scene, const DesignTarget& target) {
    if (target.kind == DesignTargetKind::Registered) {
        const DesignTargetType* r = registered(target.name);
        return r ? r->default_starts : 16;
    }
    const bool sink = target.kind == DesignTargetKind::Sink || target.kind == DesignTargetKind::LineSink ||
                      (target.kind == DesignTargetKind::FixedPoint && part_scene.part.point);
    return sink ? 4 : 16;
}

namespace {

// A rigid part's fixed point: the half-turn pair first, broken where rz about its centre leaves one
// stable fixed point (design_rigid_pair, break_pair); where the pair itself fails (no sink for this
// part), the general search over all six axes at n = 1, 2 (design_rigid). A point part's is its sink.
DesignSummary design_fixed_point(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt, double T) {
    if (part_scene.part.point) return design_sink(part_scene, target, opt, T);
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

// Orient: a part whose contacts' friction differs by a translating plate (the weathervane); with one
// friction coefficient on every contact a translating plate cannot turn the part, and the rotating
// plate's search, design_rigid, is left.
DesignSummary design_orientation(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt, double T) {
    if (friction_differs(part_scene.part)) return design_orient(part_scene, target, opt, T);
    return design_rigid(part_scene, target, opt, T);
}

DesignSummary design_registered(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt, double T) {
    return registered(target.name)->design(part_scene, target, opt, T);   // (validate_design_target found it)
}

// The dispatch: each kind's designer (a new built-in kind: its file and one line here; see also
// register_design_target for kinds added from outside the library).
using BuiltInDesigner = DesignSummary (*)(const Scene&, const DesignTarget&, const DesignOptions&, double);
constexpr std::pair<DesignTargetKind, BuiltInDesigner> kDesigners[] = {
    {DesignTargetKind::Sink, design_sink},                // sink.cpp
    {DesignTargetKind::FixedPoint, design_fixed_point},   // rigid_fixed_point.cpp, break_pair.cpp
    {DesignTargetKind::Transport, design_transport},      // transport.cpp
    {DesignTargetKind::Orient, design_orientation},       // orient.cpp
    {DesignTargetKind::LineSink, design_line_sink},       // line_sink.cpp
    {DesignTargetKind::Registered, design_registered},
};

}   // namespace

DesignSummary design(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt) {
    validate_design_options(opt);
    DesignOptions o = opt;
    if (o.starts <= 0) o.starts = default_starts(part_scene, target);
    validate_design_target(target, part_scene, o);
    const double T = o.period > 0 ? o.period : part_scene.plate.T;
    DesignSummary sum;
    for (const auto& [kind, designer] : kDesigners)
        if (kind == target.kind) sum = designer(part_scene, target, o, T);
    if (sum.starts == 0) sum.starts = o.starts;   // (set where a search ran its own number of starts)
    judge_peaks(sum, o);                          // (the limits bound the motion returned, whatever built it)
    if (o.robust && sum.verified) verify_robust(sum, target, o);
    return sum;
}

}   // namespace plate
