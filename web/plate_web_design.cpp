// The playground's design (issue 55; built when NLopt's source is at hand, web/design.cmake): a point
// part's sink designed as `plate design PART --target sink X Y` designs it -- the same library call on the
// same options, on one thread -- and answered with the summary `plate design` prints and the scene it
// writes (only when verified, as the program writes it).
//   request  {"op": "design", "scene": TEXT, "target": [X, Y],
//             "starts": N, "evaluations": N, "seed": N, "hold": s (each optional: the program's defaults)}
#include "plate_web.hpp"

#include "plate/design.hpp"
#include "plate/design_target.hpp"
#include "plate/scene_io.hpp"

#include <stdexcept>

namespace plate::web {

bool design_available(std::string& why) {
    why.clear();
    return true;
}

nlohmann::json design_answer(const Scene& sc, const nlohmann::json& rq) {
    if (!sc.part.point)
        throw std::invalid_argument("the playground designs a point part's sink only (a rigid part's: plate design)");
    const nlohmann::json& at = rq.at("target");
    const DesignTarget target = parse_design_target("sink", {at.at(0).get<double>(), at.at(1).get<double>()}, true);
    DesignOptions o;
    o.threads = 1;   // (no threads in the module; the design is the same on any number)
    o.starts = rq.value("starts", o.starts);
    o.local_evaluations = rq.value("evaluations", o.local_evaluations);
    o.seed = rq.value("seed", o.seed);
    o.hold = rq.value("hold", o.hold);
    const DesignSummary d = design(sc, target, o);   // (judges the options and the target, as the program does)
    nlohmann::json out = {{"summary", design_summary_json(d, sc, target, o, "")}, {"verified", d.verified}};
    if (d.verified) {
        out["scene"] = scene_to_json(d.scene);
        out["warnings"] = scene_warnings(d.scene);
    }
    return out;
}

}   // namespace plate::web
