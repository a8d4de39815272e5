// plate random-scene: a seeded random part and plate motion (like Fig. 3), as a scene file.
#include "commands.hpp"

#include "plate/output.hpp"
#include "plate/random_scene.hpp"

#include <cstdint>
#include <string>

namespace plate::cli {
namespace {

struct RandomSceneArgs : Options {
    std::uint64_t seed = 0;
    bool thin = false, point = false;
    std::string out = "-";
    explicit RandomSceneArgs(CLI::App& app)
        : Options(app, "random-scene", "a seeded random part and plate motion (like Fig. 3), as a scene file",
                  "A random part (thick by default) and a random plate motion (harmonics 1-2 on every axis,\n"
                  "vertical acceleration kept below 0.6 g within 3 cm of the centre), reproducible by seed.\n") {
        whole("--seed", seed, 0, 1L << 62, "the seed; required", "");
        flag("--thin", thin, "a thin part (contacts in the plane of the centre of mass: Theorem 1)");
        flag("--point", point, "a point part");
        text("--out", out, "FILE", "the scene file (default: standard output)");
    }
};

int cmd_random_scene(const RandomSceneArgs& a, Io& cio) {
    if (!a.has("--seed")) throw UsageError("missing --seed N");
    RandomSceneOptions ro;
    ro.thin = a.thin;
    ro.point = a.point;
    if (ro.thin && ro.point) throw UsageError("--thin and --point exclude each other");
    const Scene sc = random_scene(a.seed, ro);
    write_file_atomic(
        a.out, [&](std::ostream& out) { out << scene_to_json(sc).dump(2) << "\n"; }, cio.out);
    return 0;
}

}   // namespace

Command add_random_scene(CLI::App& app) { return make_command<RandomSceneArgs>(app, cmd_random_scene); }

}   // namespace plate::cli
