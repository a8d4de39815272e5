// A design target: what a plate motion is designed to do with a part (issue 16), parsed and judged in
// one place for every front end -- the CLI's `--target KIND ...`, a campaign's "target": [KIND, ...],
// Python's plate.design(target=...) -- so that a target one of them refuses, each refuses with the same
// message (tests/design/test_design_target.cpp). A new kind of target is one file with its designer and
// one line: register_design_target (docs/architecture.md, "Adding a design target").
#pragma once

#include "plate/model.hpp"

#include <nlohmann/json_fwd.hpp>

#include <functional>
#include <string>
#include <vector>

namespace plate {

struct DesignOptions;
struct DesignSummary;

// The built-in kinds, and Registered: a kind added by register_design_target, named by `name`.
enum class DesignTargetKind { Sink, FixedPoint, Transport, Orient, LineSink, Registered };
struct DesignTarget {
    // Sink: every start in the region ends at position `at`: for a point part the unique stable
    // fixed point of its velocity field ("fixed-point X Y" is the same target); for a rigid part
    // whatever its orientation, which is left free (it may turn on at the sink: the summary's pulls).
    // Transport: the part moves at the uniform velocity `velocity` everywhere in the region. A plate
    // that only translates (x, y, z harmonics n = 1, 2) gives a point part the same velocity at every
    // position (nothing in its dynamics depends on where it is), so the field is uniform by
    // construction and the search only sets its value. A rigid part with one friction coefficient on
    // such a plate is that point part exactly: every contact slides with the centre of mass (nothing
    // turns it: the torque -(sum_i N_i r_i) x mu u vanishes, sum_i N_i r_i being along u), and friction's
    // resultant is -mu N u as for the point (tests/design/test_design_transport.cpp checks fig4's part at
    // every orientation). So it is designed as that point part and
    // verified as itself (the 7^3 field's twists, theta' included, and full-dynamics runs). `omega`
    // (transport with a turn) is refused: a translating plate cannot turn such a part, and a turning
    // plate adds alpha x s, a whirl that makes the twist depend on position (not uniform); a part whose
    // friction differs turns on any translating plate (the weathervane), its velocity with it.
    // FixedPoint: (at, theta) the unique stable fixed point of the twist field (a rigid part; for a
    // point part the same as Sink). Designed as a half-turn pair ((at, theta) and (at, theta + pi) both
    // stable), then broken by rz about its centre (DesignOptions::break_pair); what verifies is reported
    // with the target's basin share and each competing stable fixed point's, unique only where the grid
    // finds no other. Orient: every start ends at orientation theta, position free (a
    // part whose contacts' friction differs: by a plate that only translates, a weathervane; else
    // designed as a fixed point at the region's centre and verified on the orientation).
    // LineSink (point parts): every start ends on the line through `at` along direction `theta`, and
    // stays where it arrives (a line of fixed points: no drift along it).
    DesignTargetKind kind = DesignTargetKind::Sink;
    Vec2 at = Vec2::Zero();
    double theta = 0;               // [rad]
    Vec2 velocity = Vec2::Zero();   // [m/s]
    double omega = 0;               // transport's turn [rad/s] (refused unless 0, above)
    // Registered kinds: the registry's name and the target's numbers as given.
    std::string name;
    std::vector<double> values;
};


// --- a target in words: KIND followed by numbers ---------------------------------------------------
//   sink X Y | fixed-point X Y [THETA] | orient THETA | line-sink X Y PHI | transport VX VY [OMEGA]
// and the registered kinds. fixed-point takes THETA for a rigid part and not for a point part.

// The kinds and their numbers, as the messages below state them.
std::string design_target_usage();
// KIND and its numbers as a target; throws std::invalid_argument naming the kind and what the kinds
// expect ("sink: expected sink X Y, ...", also for a KIND that is none of them).
DesignTarget parse_design_target(const std::string& kind, const std::vector<double>& values, bool point_part);
// The target's KIND word and its numbers (parse_design_target's inverse).
std::string design_target_kind(const DesignTarget& t);
std::vector<double> design_target_values(const DesignTarget& t, bool point_part);

// --- judged once, in the library ------------------------------------------------------------------

// The options every front end may set, within the ranges every front end accepts (limits from 0 to
// kMaxAmplitude, a period of 0 -- the part scene's -- or within kPeriodRange, hold 0 to 3600 s, starts
// >= 0, evaluations and verify_starts >= 1, max_harmonic >= 0, max_coning a number); throws
// std::invalid_argument naming the option as DesignOptions and Python name it ("limits: ..."; the
// command line names its flag: "--limits: ...").
void validate_design_options(const DesignOptions& opt);
// The target for this part and these options (a period to design at, a transport's velocity, a target
// inside the region, a line sink for point parts only, ...); throws std::invalid_argument with the
// message the user sees. design() calls both before it searches.
void validate_design_target(const DesignTarget& t, const Scene& part_scene, const DesignOptions& opt);

// --- new kinds of target --------------------------------------------------------------------------

// Designs for `target` with the plate period T (validated: the options, the period, the region).
using Designer =
    std::function<DesignSummary(const Scene& part_scene, const DesignTarget& target, const DesignOptions& opt, double T)>;
struct DesignTargetType {
    std::string name;          // the KIND word
    std::string numbers;       // what follows it, for the usage ("X Y")
    int count = 0;             // how many numbers
    bool point = true;         // for point parts
    bool rigid = true;         // for rigid parts
    int default_starts = 16;   // the search's starts when DesignOptions::starts is 0
    Designer design;
};
// Adds a kind of target (std::invalid_argument if the name is taken); parse_design_target and design()
// know it from then on, as DesignTargetKind::Registered with its name.
void register_design_target(DesignTargetType type);

// --- the summary as JSON (the CLI prints it; campaigns and Python read the same fields) -----------

// The design's summary: the target, the search, the verification (runs, hold, fixed points) and the
// notes; `scene_path` is where the designed scene is written. Units: m, rad, s, m/s, 1/s.
nlohmann::json design_summary_json(const DesignSummary& d, const Scene& part_scene, const DesignTarget& t,
                                   const DesignOptions& opt, const std::string& scene_path);

}   // namespace plate
