#pragma once
// The layout of a recording's text: metadata lines (`# key: value`), the header row, the
// delimiter, and which column holds the samples, the time and the temperature.
#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "rwcalc/reader.hpp"

namespace rwcalc::detail {

/// Text helpers of the reader. The offending text for a message: at most ~40 characters, non-printable bytes escaped.
std::string quoted(std::string_view s);
inline std::string_view trim(std::string_view s, bool tabs = true) {
  auto blank = [tabs](char c) { return c == ' ' || (tabs && c == '\t'); };
  while (!s.empty() && blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && blank(s.back())) s.remove_suffix(1);
  return s;
}
bool iequals(std::string_view a, std::string_view b);
/// A field with its decimal comma turned into a point, when that reading applies: exactly one
/// comma, no point, and the delimiter is not a comma (comma_ok).
std::string_view normalise_decimal(std::string_view f, bool comma_ok, std::string& scratch);
/// Does the field read as a number (even one out of range, or NaN/Inf)? Decides header rows.
bool looks_numeric(std::string_view f, bool comma_ok);

/// Every `# key: value` (or `# key = value`) line. rate_hz, scale_arcsec_per_pulse, temperature_c
/// and serial are matched in any case and with '-' for '_', and kept under those names.
struct Metadata {
  std::map<std::string, std::string> all;
  std::optional<double> rate_hz, scale_arcsec, temperature_c;
  std::size_t rate_line = 0;
  /// The first key rwcalc does not read that looks like a sample rate / a pulse weight, and its line.
  std::optional<std::pair<std::string, std::size_t>> unread_rate_key, unread_scale_key;

  /// Take the text after '#' of comment line `line`; a comment that is no `key: value` is ignored.
  void read(std::string_view body, std::size_t line, const std::string& file);
};

enum class Delim { Comma, Semicolon, Tab, Blanks };
/// What a column is read for. Time2: a second time column, which must agree with the first.
/// Nanosec: the nanoseconds of a ROS 2 stamp split as `sec`, `nanosec` (the Time column holds the seconds).
enum class Role : unsigned char { Skip, Value, Time, Time2, Temperature, Nanosec };

/// A time column's name and the unit it is in.
struct TimeName {
  std::string_view name;
  std::string_view unit;  ///< "" for a name without a unit: told by the stamps' magnitude
  double per_second;      ///< units per second; 0 for a name without a unit
};

/// The unit of a time column whose name carries none, from its first stamp: epoch-like stamps tell
/// their unit (Unix time is ~1.7e9 s, ~1.7e12 ms, ~1.7e15 us, ~1.7e18 ns); stamps below 1e6 are
/// seconds from near 0. nullptr when the stamp tells nothing (1e6 up to 1e8).
const TimeName* time_unit_of_stamp(double first);

/// The input mode and units, with the options given and the selected column's name: a unit suffix
/// (`gyro_x_dps`) chooses what no option fixed; what it chose is said in `notes`, an option that
/// contradicts it in `warnings`.
struct InputChoice {
  InputMode mode = InputMode::Pulses;
  AngleUnit angle_unit = AngleUnit::Arcsec;
  RateUnit rate_unit = RateUnit::DegPerHour;
  std::vector<std::string> notes, warnings;
};
/// `column`: the selected column's header name ("" without a header); accelerometer suffixes
/// (`_g`, `_mg`, `_ug`, `_mps2`) choose rate input in that unit as gyro suffixes do.
InputChoice choose_input(const ReadOptions& o, std::string_view column, const std::string& file, std::size_t line);

struct Layout {
  Delim delim = Delim::Blanks;
  std::size_t layout_line = 0;  ///< the line that fixed the delimiter
  std::vector<std::string> header;
  std::size_t header_line = 0;
  std::size_t ncols = 0;
  std::vector<Role> roles;
  std::size_t value_col = 0;
  std::optional<std::size_t> time_col, time2_col, temp_col, nanosec_col;
  /// The choices of time column that no option made, one sentence each (Recording::notes).
  std::vector<std::string> notes;
  const TimeName* time_unit = nullptr;
  const TimeName* time2_unit = nullptr;

  /// Tab, then semicolon, then comma (unless it is a decimal comma in a blank-separated line).
  static Delim detect_delimiter(std::string_view line);
  /// Choose the columns once the first data line is known (`where`: the header row, else that line).
  void choose(const ReadOptions& o, std::size_t where, const std::string& file);
  /// "'a' (1), 'b' (2)" for header columns, "1, 2" without a header; cut after ~200 characters.
  [[nodiscard]] std::string column_list(const std::vector<std::size_t>& cols) const;
  /// The column of a role for messages: "column 'pulses'", "time column 1".
  [[nodiscard]] std::string describe(Role role) const;

 private:
  void choose_by_name(const ReadOptions& o, bool value_given, const std::string& file);
  void choose_given(const std::string& want, std::size_t where, const std::string& file);
  void choose_times(const ReadOptions& o, std::vector<std::size_t>& times, const std::string& file);
  [[nodiscard]] std::size_t named_column(const std::string& want, std::string_view option,
                                         const std::string& file) const;
};

std::string_view delim_name(Delim d);

}  // namespace rwcalc::detail
