// plate design: the plate motion that sends a part where wanted (a sink, fixed point, orientation,
// line sink or transport), verified before it is written.
#include "commands.hpp"

#include "plate/design.hpp"
#include "plate/farm.hpp"
#include "plate/output.hpp"

#include <cstdint>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace plate::cli {
namespace {

struct DesignArgs : Options {
    std::string scene, out;
    std::vector<std::string> target;
    std::vector<double> limits, corner_limits, plate_half_size;
    double period = 0, hold = DesignOptions{}.hold, max_coning = DesignOptions{}.max_coning;
    std::uint64_t seed = 1;
    int threads = 0, starts = DesignOptions{}.starts, evaluations = DesignOptions{}.local_evaluations, harmonics = 0;
    std::string axes, robust;
    double arrive = DesignOptions{}.arrive, robust_radius = DesignOptions{}.robust_radius,
           robust_share = DesignOptions{}.robust_share;
    int robust_draws = DesignOptions{}.robust_draws;
    explicit DesignArgs(CLI::App& app)
        : Options(app, "design",
                  "the plate motion that sends a part where wanted: a sink, fixed point, orientation or transport, verified",
                  "Designs a plate motion for the part of PART_SCENE (its plate block is ignored but for its period)\n"
                  "and verifies it before reporting. Targets:\n"
                  "  sink X Y          point part: the unique stable fixed point of the velocity field at (X, Y);\n"
                  "                    rigid part: its position ends at (X, Y) whatever its orientation (left free)\n"
                  "  fixed-point X Y THETA  rigid part: (X, Y, THETA) the unique stable fixed point of the twist field\n"
                  "                    (or, where that is out of reach, the target's basin share and the competing\n"
                  "                    fixed points); point part: fixed-point X Y = sink X Y\n"
                  "  orient THETA      rigid part: every start ends at orientation THETA (position free; a part\n"
                  "                    whose contacts' friction differs: by a plate that only translates)\n"
                  "  line-sink X Y PHI point part: every start ends on the line through (X, Y) along PHI [rad]\n"
                  "  transport VX VY   a uniform velocity (VX, VY) [m/s] over the plate (a rigid part: one friction\n"
                  "                    coefficient; OMEGA, a turn, is refused: see the README)\n"
                  "--limits LIN ANG: the peak over the period of each axis' summed signal |u_a(t)|, what actuators\n"
                  "saturate on: LIN for x, y, z [m/s^2], ANG for rx, ry, rz [rad/s^2] (default 20, 150), on the motion\n"
                  "as designed (shifted, turned, rz added; the summary's \"peaks\"); not each harmonic's amplitude,\n"
                  "which may exceed it where the others flatten the crest. --corner-limits DISP VEL [m, m/s] (optional)\n"
                  "bound what the plate's stops and its actuators' speed see: the peak length of the displacement and\n"
                  "of the velocity of the plate's corners at (+-HX, +-HY) of --plate-half-size (default: the flight\n"
                  "check's square, the region widened by the part's reach), to first order in the plate's rotation;\n"
                  "0 leaves one free. The summary's \"corner_peaks\" say where the design ends up. g plus the\n"
                  "vertical acceleration stays above 0.2 g over the plate (a constraint). NLopt COBYLA from --starts\n"
                  "seeded feasible motions (default 4 for sinks and line sinks, 16 otherwise),\n"
                  "--evaluations each (default 400). Verification: the field's fixed points on a 7x7 grid and full\n"
                  "dynamics from 20 seeded random starts; sinks and fixed points also hold: released at rest at the\n"
                  "target, the part is still within 5 mm after --hold seconds (default 120; coning, rx and ry out of\n"
                  "phase, turns the field about the plate's centre, so it limits the coning). --axes and --harmonics\n"
                  "narrow each target's motion family (sinks x, y, rx, ry at n = 1, 3; line sinks y, rx at n = 1;\n"
                  "transport and orienters x, y, z at n = 1, 2; rigid fixed points all six at n = 1, 2): the other\n"
                  "harmonics stay zero. --robust SPEC (sinks and fixed points): the design must hold on the plates\n"
                  "the uncertainty spec draws -- a point part's sink is searched with its fixed point's first-order 95 %\n"
                  "radius within --robust-radius (default 0.002 m); every robust design is then verified on\n"
                  "--robust-draws fresh draws (default 200; plate robustness): the target unique and reached from every\n"
                  "start within --arrive seconds (default 60) on at least --robust-share of them (default 0.95), their\n"
                  "95 % radius within --robust-radius, and full dynamics on the nominal plate and 10 drawn ones arriving.\n"
                  "Writes the designed\n"
                  "scene to --out and a JSON summary to stdout; exit 4 (and no scene) if the design fails verification.\n") {
        scene_file(scene, "PART_SCENE");
        words("--target", target, 1, 8, "KIND ...", design_target_usage() + "; required");
        text("--out", out, "SCENE.json", "the designed scene; required");
        numbers("--limits", limits, 2, 2, "LIN ANG",
                "each axis' peak acceleration over the period, linear and angular (default 20 m/s^2, 150 rad/s^2)");
        numbers("--corner-limits", corner_limits, 2, 2, "DISP VEL",
                "the peak displacement [m] and velocity [m/s] of the plate's corners (0: none; default none)");
        numbers("--plate-half-size", plate_half_size, 2, 2, "HX HY",
                "the plate's corners at (+-HX, +-HY) [m] for --corner-limits (default: the flight check's square)");
        number("--period", period, "the plate's period [s]", "the part scene's");
        whole("--seed", seed, 0, 1L << 40, "the seed");
        whole("--threads", threads, 0, 256, "threads (0: all cores)");
        whole("--starts", starts, 1, 10000, "seeded starts of the search", "4 for sinks and line sinks, 16 otherwise");
        whole("--evaluations", evaluations, 1, 1'000'000, "evaluations per start");
        number("--hold", hold, "seconds a part released at the target must stay within 5 mm (0: not checked)", "120");
        number("--max-coning", max_coning, "a sink's largest coning rate [rad/s] (negative: from the hold)", "from the hold");
        text("--axes", axes, "x,y,z,rx,ry,rz", "the axes the motion may use (default: the target's own)");
        whole("--harmonics", harmonics, 1, 64, "the highest harmonic n the motion may use", "the target's own");
        text("--robust", robust, "SPEC.json", "design for the plates this uncertainty spec draws (sinks, fixed points)");
        number("--arrive", arrive, "robust: every start reaches the target within this [s]");
        number("--robust-radius", robust_radius, "robust: the fixed point's 95 % radius over the draws [m]");
        number("--robust-share", robust_share, "robust: the share of draws that must succeed");
        whole("--robust-draws", robust_draws, 1, 100000, "robust: the verification's draws");
    }
};


// --target KIND NUMBERS... as a DesignTarget for `part`: the library's parser (design_target.hpp), which
// campaigns and Python use too; its refusal as a UsageError with its message.
DesignTarget parse_target(const std::vector<std::string>& target, const Scene& part) {
    std::vector<double> v;
    for (std::size_t i = 1; i < target.size(); ++i) v.push_back(parse_num("--target", target[i]));
    try {
        return parse_design_target(target[0], v, part.part.point);
    } catch (const std::invalid_argument& e) {
        throw UsageError(std::string("--target ") + e.what());   // ("--target KIND: expected ...")
    }
}

// The library's judgement of the options (validate_design_options) as a UsageError naming the flag:
// "hold: ..." -> "--hold: ...", local_evaluations -> --evaluations, max_harmonic -> --harmonics.
void judge_options(const DesignOptions& o) {
    try {
        validate_design_options(o);
    } catch (const std::invalid_argument& e) {
        std::string m = e.what();
        const std::pair<const char*, const char*> flags[] = {
            {"local_evaluations:", "evaluations:"}, {"max_harmonic:", "harmonics:"},         {"max_coning:", "max-coning:"},
            {"robust_radius:", "robust-radius:"},   {"robust_share:", "robust-share:"},      {"robust_draws:", "robust-draws:"},
            {"corner_limits:", "corner-limits:"},   {"plate_half_size:", "plate-half-size:"}};
        for (const auto& [name, flag] : flags)
            if (m.rfind(name, 0) == 0) m = flag + m.substr(std::string(name).size());
        throw UsageError("--" + m);
    }
}

// The search's and the verification's options from the command line, checked (UsageError).
DesignOptions design_options(const DesignArgs& a) {
    DesignOptions o;
    if (a.has("--limits")) {
        o.lin_limit = a.limits[0];
        o.ang_limit = a.limits[1];
    }
    if (a.has("--corner-limits")) {
        o.corner_displacement_limit = a.corner_limits[0];
        o.corner_velocity_limit = a.corner_limits[1];
    }
    if (a.has("--plate-half-size")) o.plate_half_size = Vec2(a.plate_half_size[0], a.plate_half_size[1]);
    o.period = a.period;   // (the ranges are judged by the library, as for campaigns and Python)
    o.hold = a.hold;
    o.max_coning = a.max_coning;   // (any finite number: negative asks for the hold's limit)
    o.seed = a.seed;
    o.threads = a.threads;
    o.starts = a.starts;
    o.local_evaluations = a.evaluations;
    if (a.has("--harmonics")) o.max_harmonic = a.harmonics;
    o.arrive = a.arrive;
    o.robust_radius = a.robust_radius;
    o.robust_share = a.robust_share;
    o.robust_draws = a.robust_draws;
    o.robust_full_draws = std::min(o.robust_full_draws, o.robust_draws);
    if (a.has("--axes")) {
        std::istringstream in(a.axes);
        std::string name;
        while (std::getline(in, name, ',')) {
            bool found = false;
            for (int k = 0; k < 6; ++k)
                if (name == axis_name(static_cast<Axis>(k))) {
                    o.axes.push_back(static_cast<Axis>(k));
                    found = true;
                }
            if (!found) throw UsageError("--axes: expected a comma-separated list of x, y, z, rx, ry, rz, got '" + name + "'");
        }
        if (o.axes.empty()) throw UsageError("--axes: expected at least one of x, y, z, rx, ry, rz");
    }
    return o;
}

int cmd_design(const DesignArgs& a, Io& cio) {
    launched_farm(cio, a.threads);
    const Scene part = scene_arg(a.scene, cio);
    if (!a.has("--target")) throw UsageError("missing --target KIND A B");
    if (!a.has("--out")) throw UsageError("missing --out SCENE.json");
    const DesignTarget t = parse_target(a.target, part);
    DesignOptions o = design_options(a);
    if (a.has("--robust")) o.robust = parse_uncertainty(input_text(a.robust, "uncertainty spec", cio), a.robust);
    judge_options(o);
    // Under mpirun the starts, the verification field's planes and the verification runs are shared
    // over the ranks; every rank follows the same path, rank 0 writes.
    if (cio.farm) o.tasks = sweep::farm_tasks(*cio.farm);
    DesignSummary d;
    try {
        d = design(part, t, o);
    } catch (const std::invalid_argument& e) {
        throw UsageError(e.what());
    }
    if (cio.farm && !cio.farm->root()) return d.verified ? 0 : 4;
    const bool rigid = !part.part.point;
    const nlohmann::json j = design_summary_json(d, part, t, o, a.out);
    if (d.verified) {
        write_file_atomic(a.out, [&](std::ostream& out) { out << scene_to_json(d.scene).dump(2) << "\n"; });
        for (const std::string& w : scene_warnings(d.scene)) cio.err << "warning: designed scene: " << w << "\n";
    }
    cio.out << j.dump(2) << std::endl;
    if (!d.verified) {
        cio.err << "plate design: " << a.scene << ": the design failed verification: " << d.failure << " (no scene written)"
                << std::endl;
        return 4;
    }
    if (rigid && t.kind == DesignTargetKind::FixedPoint && !d.unique) {   // (verified, but say it plainly)
        cio.err << "plate design: " << a.scene << ": not unique: the target holds " << d.basin_share << " of the random starts";
        for (const auto& c : d.competitors)
            cio.err << "; a stable fixed point at (" << c.point.q[0] << ", " << c.point.q[1] << ", " << c.point.q[2] << ") holds "
                    << c.basin_share;
        cio.err << std::endl;
    }
    return 0;
}

}   // namespace

Command add_design(CLI::App& app) { return make_command<DesignArgs>(app, cmd_design); }

}   // namespace plate::cli
