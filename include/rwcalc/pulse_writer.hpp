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

#include "rwcalc/output.hpp"
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

/// Write a pulse file atomically (".gz" is gzip-compressed). Throws OutputError, and UsageError
/// (nothing written) for a value PulseFileWriter cannot write.
void write_pulse_file(const std::string& path, const Metadata& metadata, const PhaseSeries& series, bool force);

/// Writes a pulse file while its record is generated, so that memory does not grow with the
/// record: the metadata and the header first, then each block of samples as it comes (the text
/// is buffered and handed to an AtomicOutput about once per MiB), and commit() puts the file in
/// place (see AtomicOutput: whole or not at all; "-" is standard output). The column is
/// `pulses` (the increments of cumulative counts, add_counts) or `angle` (the cumulative angle
/// in ″, 6 decimals, add_angles). A value that cannot be written as it is — an increment
/// beyond 64 bits, a non-finite angle — throws UsageError naming the file, the line and the
/// sample, and the file is not written.
class PulseFileWriter {
 public:
  enum class Column { Pulses, Angle };
  PulseFileWriter(const std::string& path, const Metadata& metadata, Column column, bool force);

  /// The cumulative counts C_k of the next samples (C_0 = 0 precedes the first).
  void add_counts(std::span<const std::int64_t> counts);
  /// The cumulative angles θ_k of the next samples, ″.
  void add_angles(std::span<const double> angles);
  /// Write what is buffered and move the file into place.
  void commit();

 private:
  void flush_when_full();
  std::string path_;
  AtomicOutput out_;
  Column column_;
  std::string text_;          // lines not yet handed to out_
  std::size_t line_ = 0;      // line number of the last line in the file so far
  std::size_t sample_ = 0;    // index k of the last sample written
  std::int64_t previous_ = 0; // C_{sample_}
};

}  // namespace rwcalc
