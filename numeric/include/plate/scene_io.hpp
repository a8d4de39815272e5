// Scene files (JSON). The form is fixed: unknown or missing fields are errors.
//
//   { "name": "fig4", "gravity": 9.81,
//     "part":  { "mass": m, "inertia": [[3],[3],[3]], "contacts": [[3],[3],[3]],
//                "friction": mu | [mu1, mu2, mu3] },          // point part: mass, friction
//     "plate": { "period": T,
//                "harmonics": [ {"axis": "x|y|z|rx|ry|rz", "n": k, "amp": a, "phase": phi} ] } }
#pragma once

#include "plate/model.hpp"

#include <nlohmann/json.hpp>

#include <stdexcept>
#include <string>

namespace plate {

// Bad input: the message names the file and the field and says what was expected.
struct InputError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

Scene load_scene(const std::string& path);               // throws InputError
Scene parse_scene(const std::string& text, const std::string& source);  // throws InputError
// Checks the physical admissibility of a scene built in code (same checks as the reader).
void validate_scene(const Scene& scene);                 // throws InputError
// The scene in the file form above (parse_scene(scene_to_json(s).dump()) gives s back).
nlohmann::json scene_to_json(const Scene& scene);

}  // namespace plate
