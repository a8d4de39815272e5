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
#include <vector>

namespace plate {

// Bad input: the message names the file and the field and says what was expected.
struct InputError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

Scene load_scene(const std::string& path);                               // throws InputError
Scene parse_scene(const std::string& text, const std::string& source);   // throws InputError
// Checks the physical admissibility of a scene built in code (same checks as the reader):
// finite positive mass, gravity and period; a symmetric positive definite inertia whose principal
// moments satisfy the triangle inequality and whose radius of gyration about z lies within
// kGyrationRange of the contacts' reach (else: a unit error); contacts coplanar, below the centre
// of mass, not nearly collinear (the normal-force solve's condition number at most
// kMaxContactCondition) and around it (else the part tips over); friction in [0, kMaxFriction];
// mass, gravity, period and amplitudes in the model's ranges (below).
void validate_scene(const Scene& scene);   // throws InputError
// Admissible but outside the intended regime (the CLI prints them): friction above
// kHighFriction, a contact with less than kNearTipping of the weight at rest, sliding friction
// able to tip the part (mu h beyond the centre of mass's distance to a support edge), a radius of
// gyration beyond kGyrationWarn of the contacts' reach (units?), a downward acceleration at a
// contact that can reach g, a slip-speed scale that moves the part more than kTravelPerPeriod
// times its size per period.
std::vector<std::string> scene_warnings(const Scene& scene);
inline constexpr double kMaxContactCondition = 1e-10 / 2.220446049250313e-16;
inline constexpr double kGyrationRange = 100, kGyrationWarn = 10;
inline constexpr double kMaxFriction = 10, kHighFriction = 2;
inline constexpr double kNearTipping = 0.02, kTravelPerPeriod = 10;
inline constexpr double kMassRange[2] = {1e-9, 1e6};     // kg
inline constexpr double kPeriodRange[2] = {1e-5, 1e3};   // s
inline constexpr double kMaxGravity = 1e3;               // m/s^2
inline constexpr double kMaxAmplitude = 1e6;             // m/s^2 or rad/s^2
// The scene in the file form above (parse_scene(scene_to_json(s).dump()) gives s back).
nlohmann::json scene_to_json(const Scene& scene);

}   // namespace plate
