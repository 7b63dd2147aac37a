#include "rwcalc/pulse_writer.hpp"

#include <algorithm>
#include <charconv>
#include <cstdint>

#include "rwcalc/error.hpp"
#include "rwcalc/output.hpp"

namespace rwcalc {

std::string format_pulse_file(const Metadata& metadata, std::span<const std::int64_t> pulses) {
  std::string text;
  for (const auto& [key, value] : metadata) {
    text += "# ";
    text += key;
    text += ": ";
    text += value;
    text += '\n';
  }
  text += "pulses\n";
  const std::size_t head = text.size();
  // Room for the widest value (digits and sign) plus the newline on every line.
  std::int64_t widest = 0;
  for (const std::int64_t c : pulses) widest = std::max(widest, c < 0 ? (c == INT64_MIN ? INT64_MAX : -c) : c);
  std::size_t width = 3;  // sign, one digit, newline
  for (std::int64_t w = widest; w >= 10; w /= 10) ++width;
  text.resize(head + pulses.size() * width);
  char* p = text.data() + head;
  char* const end = text.data() + text.size();
  for (const std::int64_t c : pulses) {
    p = std::to_chars(p, end, c).ptr;
    *p++ = '\n';
  }
  text.resize(static_cast<std::size_t>(p - text.data()));
  return text;
}

std::string format_pulse_file(const Metadata& metadata, const PhaseSeries& series) {
  if (!series.exact()) {
    // A floating series (an output-chain filter gives sub-pulse resolution): the cumulative
    // angle in ″ under the header `angle`, 6 decimals.
    if (series.values.empty()) throw AnalysisError("the series to write is empty");
    std::string text;
    for (const auto& [key, value] : metadata) text += "# " + key + ": " + value + '\n';
    text += "angle\n";
    const std::size_t head = text.size();
    text.resize(head + series.values.size() * 32);
    char* p = text.data() + head;
    char* const end = text.data() + text.size();
    for (const double v : series.values) {
      p = std::to_chars(p, end, v, std::chars_format::fixed, 6).ptr;
      *p++ = '\n';
    }
    text.resize(static_cast<std::size_t>(p - text.data()));
    return text;
  }
  std::vector<std::int64_t> c(series.points() - 1);
  for (std::size_t k = 0; k < c.size(); ++k)
    c[k] = static_cast<std::int64_t>(static_cast<std::uint64_t>(series.count(k + 1)) -
                                     static_cast<std::uint64_t>(series.count(k)));
  return format_pulse_file(metadata, std::span<const std::int64_t>(c));
}

void write_pulse_file(const std::string& path, const Metadata& metadata, const PhaseSeries& series, bool force) {
  write_file_atomic(path, format_pulse_file(metadata, series), force);
}

}  // namespace rwcalc
