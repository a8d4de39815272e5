// The playground's module without the design (web/design.cmake: NLopt's source could not be fetched):
// a design request is answered by saying why, and the page shows that sentence.
#include "plate_web.hpp"

#include <stdexcept>

namespace plate::web {

namespace {
constexpr const char* kWhy =
    "this build of the playground has no design: NLopt's source could not be fetched when it was built "
    "(build/web/nlopt-fetch.failed says why); plate design runs it natively";
}

bool design_available(std::string& why) {
    why = kWhy;
    return false;
}

nlohmann::json design_answer(const Scene&, const nlohmann::json&) { throw std::invalid_argument(kWhy); }

}   // namespace plate::web
