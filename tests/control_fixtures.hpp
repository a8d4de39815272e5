// What the control tests share: the shipped scenes' folders, a library of shipped motions written to a
// temporary folder, and a sink's fixed point found independently (Newton on the field).
#pragma once

#include "plate/control.hpp"
#include "plate/scene_io.hpp"

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>
#include <vector>

namespace plate::test {

namespace fs = std::filesystem;

inline const std::string kScenes = PLATE_SOURCE_DIR "/scenes/";
inline const std::string kLib = kScenes + "control/fig1_point/";
inline const std::string kFig4 = kScenes + "control/fig4/";

// A library of the given shipped motions of folder `from` (and the sink, when given), written beside the
// shipped scenes' copies in the test's folder; "still" is the still plate.
inline MotionLibrary library_of(const Scene& part, const std::vector<std::string>& names, const std::string& sink = "",
                                const std::string& from = kLib) {
    const fs::path dir = fs::temp_directory_path() / ("plate_control_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    std::string text = "{\"motions\": [";
    for (const std::string& n : names) {
        if (n == "still") {
            text += "{\"name\": \"still\", \"still\": true},";
            continue;
        }
        fs::copy_file(from + n + ".json", dir / (n + ".json"), fs::copy_options::overwrite_existing);
        text += "{\"name\": \"" + n + "\", \"scene\": \"" + n + ".json\"},";
    }
    if (!sink.empty()) {
        fs::copy_file(sink, dir / "sink.json", fs::copy_options::overwrite_existing);
        text += "{\"name\": \"sink\", \"scene\": \"sink.json\"},";
    }
    text.back() = ']';
    std::ofstream(dir / "library.json") << text << "}";
    return load_motion_library((dir / "library.json").string(), part);
}

// The zero of the velocity field near q by Newton's method with a central-difference Jacobian.
inline Vec3 sink_point(const Scene& sc, Vec3 q) {
    LimitCycleOptions lo;
    lo.tol = 1e-10;
    for (int it = 0; it < 8; ++it) {
        const Vec3 f = field_at(sc, q, lo);
        Eigen::Matrix2d J;
        const double h = 1e-4;
        for (int c = 0; c < 2; ++c) {
            Vec3 e = Vec3::Zero();
            e[c] = h;
            J.col(c) = (field_at(sc, q + e, lo) - field_at(sc, q - e, lo)).head<2>() / (2 * h);
        }
        q.head<2>() -= J.lu().solve(f.head<2>());
    }
    return q;
}

// fig1_point's part (`part`) with e_fast, n_fast, w_fast, s_fast (2 mm per period) and the sink of
// scenes/designs/point_sink.json (motion 4), its field on a 9 x 9 grid over [0, 0.04] x [-0.03, 0.01].
inline ControlModel sink_model(const Scene& part) {
    ControlModelOptions mo;
    mo.grid.nx = mo.grid.ny = 9;
    mo.grid.x0 = 0.0;
    mo.grid.x1 = 0.04;
    mo.grid.y0 = -0.03;
    mo.grid.y1 = 0.01;
    mo.field.threads = 1;
    return build_control_model(
        part, library_of(part, {"e_fast", "n_fast", "w_fast", "s_fast"}, kScenes + "designs/point_sink.json"), mo);
}

}   // namespace plate::test
