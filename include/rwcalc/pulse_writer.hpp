#pragma once
/// @file pulse_writer.hpp
/// Writing GL-2D pulse files: `# key: value` metadata lines, a header `pulses`, then one integer
/// pulse count per line (the per-sample increments c_k = C_k − C_{k−1}). The file is what
/// rwcalc's reader takes by default (rate and scale come from the metadata).
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "rwcalc/series.hpp"

namespace rwcalc {

/// Ordered `key: value` metadata lines written before the header.
using Metadata = std::vector<std::pair<std::string, std::string>>;

/// Render a pulse file to text (fast: one char buffer, std::to_chars; no streams per line).
[[nodiscard]] std::string format_pulse_file(const Metadata& metadata, std::span<const std::int64_t> pulses);

/// Render the increments of an exact series (counts) as a pulse file; a floating series (values,
/// e.g. after an output-chain low-pass) as the cumulative angle in ″ under the header `angle`
/// (read back with `--input angle`).
[[nodiscard]] std::string format_pulse_file(const Metadata& metadata, const PhaseSeries& series);

/// Write a pulse file atomically (".gz" is gzip-compressed). Throws OutputError.
void write_pulse_file(const std::string& path, const Metadata& metadata, const PhaseSeries& series, bool force);

}  // namespace rwcalc
