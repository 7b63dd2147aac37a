#pragma once
#ifndef RWCALC_USES_REPORT
#error "rwcalc/allan_report.hpp belongs to the report layer, which this layer may not use (docs/architecture.md)"
#endif
// The `allan` command's table and CSV of an AllanResult (src/report/allan_report.cpp).
#include <cstddef>
#include <string>

#include "rwcalc/allan.hpp"

namespace rwcalc {

/// What the report header says about the record.
struct AllanReportInfo {
  std::string source;       ///< file name as given
  std::size_t samples = 0;  ///< samples read
  double rate_hz = 0;       ///< sample rate, Hz
  std::string rate_source;  ///< where the rate came from ("option", "metadata", …); may be empty
  std::string input;        ///< what was read (describe_input in reader.hpp); may be empty
};

/// Human-readable table: a header block (source, estimator, confidence, unit convention, samples,
/// rate) and columns AF, τ (s), terms, α, EDF, σ_min, σ, σ_max with the deviation unit.
std::string format_allan_table(const AllanResult& r, const AllanReportInfo& info);
/// CSV with a header row naming each column and its unit.
std::string format_allan_csv(const AllanResult& r);
/// Unit label of the deviations for people: "°/h" for gyro data, "input units/s" otherwise.
std::string unit_label(const AllanResult& r);

}  // namespace rwcalc
