// The engine (engine.hpp) compiled for the three models of models.hpp: its definitions, in four
// parts, are included here and instantiated once per model.
#include "engine.hpp"
#include "models.hpp"

#include "engine_creep.hxx"
#include "engine_events.hxx"
#include "engine_modes.hxx"
#include "engine_step.hxx"

namespace plate::detail {

template class Engine<ReducedModel>;
template class Engine<UModel>;
template class Engine<FullModel>;

}   // namespace plate::detail
