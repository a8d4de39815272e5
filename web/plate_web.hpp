// What web/plate_web.cpp's API takes from the design's file (plate_web_design.cpp when the module was
// built with NLopt, plate_web_no_design.cpp when not; web/design.cmake picks one).
#pragma once

#include "plate/model.hpp"

#include <nlohmann/json.hpp>

#include <string>

namespace plate::web {

// Whether this module designs; when not, `why` says why (a sentence for the page).
bool design_available(std::string& why);
// A point part's sink designed for the request's target (plate_web_design.cpp's header says the request).
nlohmann::json design_answer(const Scene& sc, const nlohmann::json& rq);

}   // namespace plate::web
