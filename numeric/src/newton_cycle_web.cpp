// The Newton cycle solver in the web build (web/CMakeLists.txt), which leaves GSL out: refused, with
// the solvers that remain. The native build compiles newton_cycle.cpp (GSL's gnewton) instead.
// (docs/decisions/web.md)
#include "cycle_solvers.hpp"

#include <stdexcept>

namespace plate::detail {

LimitCycleSummary newton_cycle(const Scene&, const Vec3&, const LimitCycleOptions&, const Vec3&) {
    throw std::invalid_argument(
        "the newton cycle solver needs GSL, which the web build leaves out (expected period-by-period, anderson or "
        "shooting)");
}

}   // namespace plate::detail
