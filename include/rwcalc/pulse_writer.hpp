#pragma once
#ifndef RWCALC_USES_IO
#error "rwcalc/pulse_writer.hpp belongs to the io layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file pulse_writer.hpp
/// GL-2D pulse files: `# key: value` metadata, the header `pulses` and one increment per line, or
/// the header `angle` and the cumulative angle in ″.
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "rwcalc/output.hpp"
#include "rwcalc/series.hpp"

namespace rwcalc {

/// Ordered `key: value` metadata lines written before the header.
using Metadata = std::vector<std::pair<std::string, std::string>>;

/// A pulse file of the given per-sample counts.
[[nodiscard]] std::string format_pulse_file(const Metadata& metadata, std::span<const std::int64_t> pulses);

/// The increments of an exact series (counts), or the cumulative angle of a floating one.
/// Throws UsageError for a value that cannot be written (see PulseFileWriter).
[[nodiscard]] std::string format_pulse_file(const Metadata& metadata, const PhaseSeries& series);

/// Writes a pulse file while its record is generated (memory does not grow with the record). A
/// value that cannot be written (increment beyond 64 bits, non-finite angle) throws UsageError.
class PulseFileWriter {
 public:
  enum class Column { Pulses, Angle };
  PulseFileWriter(const std::string& path, const Metadata& metadata, Column column, bool force);

  /// The cumulative counts C_k of the next samples (C_0 = 0 precedes the first).
  void add_counts(std::span<const std::int64_t> counts);
  /// The cumulative angles θ_k of the next samples, ″.
  void add_angles(std::span<const double> angles);
  void commit();

 private:
  void flush_when_full();
  std::string path_;
  AtomicOutput out_;
  Column column_;
  std::string text_;           // lines not yet handed to out_
  std::size_t line_ = 0;       // line number of the last line so far
  std::size_t sample_ = 0;     // index k of the last sample written
  std::int64_t previous_ = 0;  // C_{sample_}
};

}  // namespace rwcalc
