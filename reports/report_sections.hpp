// Internal: the report's sections, one file per topic, each writing its part of the page into the
// context (report_html.hpp); write_report (report.cpp) calls the ones asked for, in page order.
//   report_sections_proofs.cpp  derivation, kernels, proofs, fig3
//   report_sections_fields.cpp  fields (with stick-slip against the regularised-friction limit)
//   report_sections_design.cpp  design, orient, fixed-point
//   report_sections_robustness.cpp  robustness (the shipped designs under the PPOD spec)
//   report_sections_identify.cpp  identify (a filmed track fitted, with profile likelihoods)
//   report_sections_control.cpp  control (closed loop against the open-loop design)
#pragma once

#include "report.hpp"
#include "report_html.hpp"

#include <cstdint>
#include <filesystem>

namespace plate::report {

void section_derivation(html::Ctx& c);
void section_kernels(html::Ctx& c, std::uint64_t seed);
void section_proofs(html::Ctx& c, const ReportOptions& opt);
void section_fig3(html::Ctx& c, const std::filesystem::path& src);
void section_fields(html::Ctx& c, const std::filesystem::path& src, const ReportOptions& opt);
void section_design(html::Ctx& c, const std::filesystem::path& src, const ReportOptions& opt);
void section_orient(html::Ctx& c, const std::filesystem::path& src, const ReportOptions& opt);
void section_fixed_point(html::Ctx& c, const std::filesystem::path& src, const ReportOptions& opt);
void section_robustness(html::Ctx& c, const std::filesystem::path& src, const ReportOptions& opt);
void section_identify(html::Ctx& c, const std::filesystem::path& src, const ReportOptions& opt);
void section_control(html::Ctx& c, const std::filesystem::path& src, const ReportOptions& opt);

}   // namespace plate::report
