#pragma once
// The HTML test report's look and cells (report.cpp), for the other pages that share it
// (`imu --report`, imu_report.cpp).
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace rwcalc::html {

/// The report's stylesheet (the contents of its <style>): screen and A4 print layout with the page
/// number, in the current language; `page_prefix` (CSS string text) goes before "Page N of M".
[[nodiscard]] std::string stylesheet(const std::string& page_prefix = "");
/// Outside text escaped for HTML content and quoted attributes, control characters made visible.
[[nodiscard]] std::string text(std::string_view s);
/// The same, shown as typed (no decimal comma put into it).
[[nodiscard]] std::string typed(std::string_view s);
/// A coefficient cell: "value ± σ" with the 95 % interval below, or "< bound" when unresolved
/// (keys value, sigma, low95, high95, resolved).
[[nodiscard]] std::string coefficient_cell(const nlohmann::json& c);

}  // namespace rwcalc::html
