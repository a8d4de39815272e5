// The scenes shipped in scenes/, loaded by name for the tests: the one home of the path the test
// files share ("fig4" is PLATE_SOURCE_DIR/scenes/fig4.json).
#pragma once

#include "plate/scene_io.hpp"

#include <string>

namespace plate_tests {

inline plate::Scene scene(const std::string& name) { return plate::load_scene(PLATE_SOURCE_DIR "/scenes/" + name + ".json"); }

}   // namespace plate_tests
