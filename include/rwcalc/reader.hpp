#pragma once
#ifndef RWCALC_USES_IO
#error "rwcalc/reader.hpp belongs to the io layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file reader.hpp
/// Reading gyro and clock recordings into a PhaseSeries without losing or bending a sample.
///
/// Text, one sample per line, read as a stream (memory follows the samples, not the text).
/// Accepted: `#` comment lines; metadata lines `# key: value` or `# key = value` (rate_hz,
/// scale_arcsec_per_pulse, temperature_c, serial in any case; any other key kept verbatim); an
/// optional header row; delimiters comma, semicolon, tab or blanks (detected from the header or
/// the first data line); a decimal comma where the delimiter is not a comma; CRLF or CR line ends;
/// a UTF-8 BOM; gzip (by content); "-" for standard input. Blank lines carry no sample. Any other
/// malformed line is an InputError naming the file and the line. See docs/input-formats.md.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "rwcalc/memory.hpp"
#include "rwcalc/series.hpp"
#include "rwcalc/validate.hpp"

namespace rwcalc {

/// What the selected column holds.
enum class InputMode {
  Pulses,   ///< per-sample pulse increments (integers): the GL-2D format; default
  Counter,  ///< a cumulative counter reading that wraps at 2^counter_bits
  Angle,    ///< cumulative angle or phase samples, in angle_unit
  Rate,     ///< rate samples, in rate_unit (or dimensionless frequency for clocks)
  /// per-sample increments of angle (Δθ) or velocity (Δv), in angle_unit: an IMU's integrated output
  Increment,
};
/// Unit of Angle input. Second means clock phase (time error) in seconds; MetrePerSecond is an
/// accelerometer's cumulative velocity (integrated Δv).
enum class AngleUnit { Arcsec, Deg, Rad, Second, MetrePerSecond };
/// Unit of Rate input. Unitless means dimensionless clock frequency (fractional frequency); the
/// last four are accelerometer units (g = 9.80665 m/s², the standard gravity).
enum class RateUnit { DegPerHour, DegPerSecond, RadPerSecond, Unitless, MetrePerSecond2, G, MilliG, MicroG };

/// Unset options mean "not given": the column's name may then choose (see docs/input-formats.md).
struct ReadOptions {
  /// --input; unset: implied by a unit suffix of the column's name (`gyro_x_dps` → rate), else pulses
  std::optional<InputMode> mode;
  /// Column holding the samples: a header name, or a 1-based index as text ("2"). Empty: the
  /// column named "pulses" (or counter/angle/phase/rate/gyro by mode), else the only non-time
  /// column, else an error asking for --column (also when two columns have such names).
  std::string column;
  /// A `column` that names a time column (time_s, timestamp …) is an error rather than samples
  /// (imu: a sensor's channel is never the time).
  bool column_not_time = false;
  /// What the error for a column that reads as no unit suggests (imu: its unit options); empty:
  /// --input and a unit suffix.
  std::string unit_advice;
  /// --time-column: the header name of the time column to use (the other time columns are then
  /// left unread); empty: the time columns by name (field.header.stamp before %time).
  std::string time_column;
  /// --topic: the sensor_msgs/Imu topic of a ROS bag; empty: the bag's only Imu topic.
  std::string topic;
  std::optional<double> rate_hz;        ///< --rate, Hz; overrides metadata; checked against a time column
  std::optional<double> scale_arcsec;   ///< --scale: pulse weight, ″ per pulse; overrides metadata
  int counter_bits = 32;                ///< wrap width of Counter mode (1..64)
  std::optional<AngleUnit> angle_unit;  ///< unset: the column name's suffix (`_deg`), else arcsec
  std::optional<RateUnit> rate_unit;    ///< unset: the column name's suffix (`_dps`), else deg/h
  /// A time-column step off the period by more than this fraction of it is jitter (accepted and
  /// reported) while it stays within half a period; 1.5 periods or more is a gap (an error).
  double time_tolerance = 0.01;
  /// `--gaps segments`: a gap in the time column splits the record into segments (each analysed
  /// without a difference spanning a gap) instead of being refused.
  bool gaps_as_segments = false;
  /// What identifies the gyro and the test, given on the command line (--serial, --operator,
  /// --test-date, --conditions): keys "serial", "operator", "test_date", "conditions". They take
  /// the place of the file's metadata of the same name (a note says so when that differs).
  std::map<std::string, std::string> identification;
  /// The most memory the samples kept may take (--max-memory); unset: default_memory_ceiling().
  /// A record beyond it is an InputError naming the line where it was reached and the memory needed.
  std::optional<MemoryCeiling> memory;
  /// Where the reading's progress line goes (progress.hpp: the bytes read of the input's size);
  /// nullptr: none.
  std::FILE* progress = nullptr;

  /// The first rule these options break, in words (validate.hpp); nothing when they are valid.
  [[nodiscard]] Violation validate() const;
};

/// Where the sample rate came from (reported in outputs).
enum class RateSource { Option, Metadata, TimeColumn, Default };

/// Time-column steps that deviate from the period (the median step) by more than the time
/// tolerance but less than half a period: accepted, and reported.
struct TimeJitter {
  std::size_t steps = 0;    ///< steps off by more than the tolerance
  double max_fraction = 0;  ///< largest |step − period| / period over all steps
  double rms_fraction = 0;  ///< rms of (step − period) / period over all steps
};

struct Recording {
  std::string source;  ///< the path as given ("-" for stdin)
  /// The input as stored (compressed bytes, for gzip): its size and SHA-256, as `sha256sum` prints it.
  std::uint64_t file_bytes = 0;
  std::string sha256;
  PhaseSeries phase;       ///< the cumulative angle/phase, ready for the estimators
  double rate_hz = 400.0;  ///< sample rate, Hz (phase.tau0_s = 1/rate_hz)
  RateSource rate_source = RateSource::Default;
  std::size_t samples = 0;  ///< data lines read (samples of the selected column)
  /// every `# key: value` (or `key = value`) line; the known keys under their lower-case names
  std::map<std::string, std::string> metadata;
  std::optional<double> temperature_c;  ///< mean of a temperature_c column, else metadata, °C
  std::string column_name;              ///< the column that was read (header name or "column N")
  std::size_t column_index = 0;         ///< its 1-based position in the line
  /// the time column that was checked, if any (the first of two, which were found to agree)
  std::optional<std::string> time_column;
  InputMode mode = InputMode::Pulses;
  AngleUnit angle_unit = AngleUnit::Arcsec;   ///< the unit angle input was read in
  RateUnit rate_unit = RateUnit::DegPerHour;  ///< the unit rate input was read in
  /// The time column's unit ("s", "ms", "us", "ns") and how it was decided ("name" or "magnitude").
  std::string time_unit, time_unit_source;
  TimeJitter jitter;
  /// The choices the reader made that no option fixed, one sentence each ("rate unit deg/s from the
  /// column name 'gyro_x_dps'"); the commands print them and the JSON outputs carry them.
  std::vector<std::string> notes;
  /// Options that contradict the file (a --rate-unit other than the column name's): the option is used.
  std::vector<std::string> warnings;
  /// Counter input: how many times the counter wrapped (a backwards step counts as a wrap).
  std::size_t counter_wraps = 0;
  /// `--gaps segments`: the stretches between gaps of the time column, in samples (empty: no gap).
  /// Sample `first` is the first after a gap of `gap_s` seconds (0 for the first segment) at `line`.
  struct Segment {
    std::size_t first = 0;
    std::size_t samples = 0;
    double gap_s = 0;
    std::size_t line = 0;
  };
  std::vector<Segment> segments;
  /// Where each run of consecutive data lines starts: (sample index, 1-based line number), sorted
  /// by sample index. A new run starts after a comment or blank line inside the data.
  std::vector<std::pair<std::size_t, std::size_t>> line_runs;

  /// Rate samples in deviation units (°/h for gyro), one per phase increment; handy for block
  /// statistics and outlier detection. Index i is the increment x_{i+1} − x_i.
  [[nodiscard]] std::vector<double> rates() const;
  /// 1-based line number of data sample k (0-based), 0 if k is out of range.
  [[nodiscard]] std::size_t line_of_sample(std::size_t k) const noexcept;
  /// 1-based line number of the data line that produced rate sample i (see rates()): sample i for
  /// pulse and rate input, sample i+1 (the later reading) for counter and angle input.
  [[nodiscard]] std::size_t line_of_rate(std::size_t i) const noexcept;
};

/// The identification keys a test report shows, in order: serial, operator, test_date, conditions.
inline constexpr std::string_view kIdentificationKeys[] = {"serial", "operator", "test_date", "conditions"};

/// Read a file (or "-" for stdin). Throws InputError (file, line, message) on any malformed input.
Recording read_recording(const std::string& path, const ReadOptions& options = {});

/// Several columns of one file (or "-") in one pass over its text: a recording for each of
/// `columns`' options, in their order, each as read_recording would give it. The first column's
/// errors on a line come before the second's.
std::vector<Recording> read_recordings(const std::string& path, std::span<const ReadOptions> columns);

/// Read from text already in memory (used by tests and fuzzers); `name` labels errors.
/// The text may be gzip-compressed (detected by its magic bytes).
Recording read_recording_text(std::string_view text, const std::string& name, const ReadOptions& options = {});

/// The columns of a file whose names tell an IMU channel (a unit suffix such as `_dps` or `_g`, or
/// a ROS field such as `angular_velocity.x`, `linear_acceleration.x`), gyros and accelerometers in
/// file order; a ROS bag's six channels. Reads the header row only; standard input has none to spare.
struct ImuColumnNames {
  std::vector<std::string> gyro, accel;
};
ImuColumnNames imu_column_names(const std::string& path, const ReadOptions& options);

/// The unit the samples were read in: "pulse" or "count" (of Recording::phase.arcsec_per_count),
/// the angle unit ("arcsec", "deg", "rad", "s", "m/s") or the rate unit ("deg/h", "deg/s", "rad/s",
/// "1", "m/s^2", "g", "mg", "ug").
std::string_view input_unit(const Recording& rec);
/// One line for output headers: "column 'gyro_x_dps': rate samples in deg/s".
std::string describe_input(const Recording& rec);

/// True for an accelerometer unit (m/s², g, mg, µg; m/s of cumulative velocity).
bool is_accelerometer_unit(RateUnit u) noexcept;
bool is_accelerometer_unit(AngleUnit u) noexcept;
/// Parse names used on the command line; throw UsageError on anything else. Rate units also take
/// "m/s2", "mps2" for m/s² and "µg" for ug.
InputMode parse_input_mode(std::string_view s);
AngleUnit parse_angle_unit(std::string_view s);
RateUnit parse_rate_unit(std::string_view s);
std::string_view to_string(InputMode m);
std::string_view to_string(RateSource s);
std::string_view to_string(AngleUnit u);
std::string_view to_string(RateUnit u);

}  // namespace rwcalc
