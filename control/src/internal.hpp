// Internal to the control library: what build_control_model calls beyond the public API.
#pragma once

#include "plate/control.hpp"

namespace plate::detail {

// Fills m.transitions (control.hpp) from m.fields: pairs of uniform fields once, others on opt.grid.
void add_transitions(ControlModel& m, const ControlModelOptions& opt);

}   // namespace plate::detail
