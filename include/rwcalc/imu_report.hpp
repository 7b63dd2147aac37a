#pragma once
#ifndef RWCALC_USES_REPORT
#error "rwcalc/imu_report.hpp belongs to the report layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file imu_report.hpp
/// The page of `rwcalc imu --report DIR` (index.html), in the look of the HTML test report
/// (report.hpp): title block, the noise file's keys, one table per sensor kind (a row per term, a
/// column per axis), each axis' warnings, the figure and the files beside the page.
#include <nlohmann/json.hpp>
#include <string>

#include "rwcalc/validate.hpp"

namespace rwcalc {

struct ImuPageOptions {
  std::string figure;                   ///< the figure's file beside the page; empty: none
  std::string noise_file = "imu.yaml";  ///< the Kalibr noise file beside the page
  std::string json_file = "imu.json";   ///< the whole result beside the page
  std::string text_file = "imu.txt";    ///< the text tables beside the page

  /// The first rule these options break, in words (validate.hpp); nothing when they are valid.
  [[nodiscard]] Violation validate() const;
};

/// The page from `rwcalc imu --json`'s object (channels, noise, conventions).
std::string imu_report_html(const nlohmann::json& imu, const ImuPageOptions& options);

}  // namespace rwcalc
