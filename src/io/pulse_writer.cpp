#include "rwcalc/pulse_writer.hpp"
#include "rwcalc/i18n.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>

#include "rwcalc/error.hpp"
#include "rwcalc/output.hpp"

namespace rwcalc {

namespace {

// Text is handed to the output in pieces of about this size.
constexpr std::size_t kFlushBytes = std::size_t{1} << 20;

std::string header_text(const Metadata& metadata, const char* column) {
  std::string text;
  for (const auto& [key, value] : metadata) text += "# " + key + ": " + value + "\n";
  return text + column + "\n";
}

// Where the next line goes, for the messages about a value that cannot be written.
struct LinePosition {
  std::string_view file;
  std::size_t line = 0;         // the last line written
  std::size_t next_sample = 0;  // the sample index k of the next line
};

[[noreturn]] void throw_unwritable(const LinePosition& at, const std::string& cause) {
  throw UsageError(
      trf("{}: line {} (sample {}): {}; the file was not written", at.file, at.line, at.next_sample, cause));
}

void append_line(std::string& text, std::int64_t v) {
  char line[24];
  char* p = std::to_chars(line, line + sizeof line - 1, v).ptr;
  *p++ = '\n';
  text.append(line, p);
}

// One line per count: the increment C_k − C_{k−1} (`previous` is C_{k−1}; updated). An increment
// beyond 64 bits would be written wrapped, i.e. as a wrong number: refused.
void append_increments(std::string& text, std::span<const std::int64_t> counts, std::int64_t& previous,
                       LinePosition& at) {
  for (const std::int64_t c : counts) {
    ++at.line;
    std::int64_t d = 0;
    if (__builtin_sub_overflow(c, previous, &d))
      throw_unwritable(at, trf("the pulse count goes from {} to {}, an increment beyond 64 bits", previous, c));
    append_line(text, d);
    previous = c;
    ++at.next_sample;
  }
}

// One line per angle, ″ with 6 decimals. A NaN or an infinity is no angle: refused.
void append_angles(std::string& text, std::span<const double> angles, LinePosition& at) {
  char line[400];  // the widest finite double in fixed notation with 6 decimals is 317 characters
  for (const double v : angles) {
    ++at.line;
    if (!std::isfinite(v)) throw_unwritable(at, trf("the angle is {}, not a number of arcsec", v));
    char* p = std::to_chars(line, line + sizeof line - 1, v, std::chars_format::fixed, 6).ptr;
    *p++ = '\n';
    text.append(line, p);
    ++at.next_sample;
  }
}

}  // namespace

std::string format_pulse_file(const Metadata& metadata, std::span<const std::int64_t> pulses) {
  std::string text = header_text(metadata, "pulses");
  for (const std::int64_t c : pulses) append_line(text, c);
  return text;
}

std::string format_pulse_file(const Metadata& metadata, const PhaseSeries& series) {
  const bool exact = series.exact();
  // A floating series (an output-chain filter gives sub-pulse resolution): the cumulative
  // angle in ″ under the header `angle`, from x_0.
  if (!exact && series.values.empty()) throw AnalysisError(tr("the series to write is empty"));
  std::string text = header_text(metadata, exact ? "pulses" : "angle");
  // The first line is x_0 in the angle column, the increment of sample 1 in the pulses column.
  LinePosition at{"the pulse file", static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')),
                  exact ? 1u : 0u};
  if (!exact) {
    append_angles(text, series.values, at);
    return text;
  }
  const std::vector<std::int64_t>& counts = series.counts;
  std::int64_t previous = counts.front();
  append_increments(text, std::span<const std::int64_t>(counts).subspan(1), previous, at);
  return text;
}

PulseFileWriter::PulseFileWriter(const std::string& path, const Metadata& metadata, Column column, bool force)
    : path_(path),
      out_(path, force),
      column_(column),
      text_(header_text(metadata, column == Column::Pulses ? "pulses" : "angle")) {
  line_ = static_cast<std::size_t>(std::count(text_.begin(), text_.end(), '\n'));
  if (column_ == Column::Angle) {
    // The angle column starts at θ_0 = 0, as format_pulse_file writes a floating series.
    LinePosition at{path_, line_, 0};
    const double zero = 0.0;
    append_angles(text_, std::span<const double>(&zero, 1), at);
    line_ = at.line;
  }
}

void PulseFileWriter::add_counts(std::span<const std::int64_t> counts) {
  if (column_ != Column::Pulses) throw AnalysisError(trf("{}: pulse counts given for an angle file", path_));
  LinePosition at{path_, line_, sample_ + 1};
  append_increments(text_, counts, previous_, at);
  line_ = at.line;
  sample_ = at.next_sample - 1;
  flush_when_full();
}

void PulseFileWriter::add_angles(std::span<const double> angles) {
  if (column_ != Column::Angle) throw AnalysisError(trf("{}: angles given for a pulse file", path_));
  LinePosition at{path_, line_, sample_ + 1};
  append_angles(text_, angles, at);
  line_ = at.line;
  sample_ = at.next_sample - 1;
  flush_when_full();
}

void PulseFileWriter::flush_when_full() {
  if (text_.size() < kFlushBytes) return;
  out_.write(text_);
  text_.clear();
}

void PulseFileWriter::commit() {
  out_.write(text_);
  text_.clear();
  out_.commit();
}

}  // namespace rwcalc
