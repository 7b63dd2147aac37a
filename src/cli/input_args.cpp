#include <fmt/format.h>

#include <nlohmann/json.hpp>
#include <ostream>

#include "commands.hpp"
#include "numeric_options.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"

namespace rwcalc::cli {

namespace {
constexpr const char* kIdGroup =
    N_("Identification (else the file's # serial:, # operator:, # test_date:, # conditions:)");
}

void SourceArgs::add_to(CLI::App& app) {
  app.add_option("--time-column", time_column,
                 tr("The time column to read, by its header name (the other time columns are then not read). "
                    "Default: the time columns by name; of a ROS export field.header.stamp, not %time"))
      ->group(tr("Input"));
  app.add_option("--time", time,
                 tr("Which time of a ROS bag or export: stamp (header.stamp, the sensor's) or receive (when the "
                    "bag recorded the message, %time)"))
      ->check(CLI::IsMember({"stamp", "receive"}))
      ->option_text("stamp|receive")
      ->group(tr("Input"));
  app.add_option("--topic", topic, tr("The sensor_msgs/Imu topic of a ROS bag (default: its only Imu topic)"))
      ->group(tr("Input"));
}

void SourceArgs::apply(ReadOptions& o) const {
  if (!time.empty() && !time_column.empty()) throw UsageError(tr("give --time or --time-column, not both"));
  o.time_column = time == "receive" ? "%time" : time_column;  // stamp: the default choice
  o.topic = topic;
}

void InputArgs::add_to(CLI::App& app) {
  source.add_to(app);
  app.add_option("--serial", serial, tr("Serial number of the gyro under test"))->group(tr(kIdGroup));
  app.add_option("--operator", operator_name, tr("Who ran the test"))->group(tr(kIdGroup));
  app.add_option("--test-date", test_date, tr("Date of the test, e.g. 2026-11-27"))->group(tr(kIdGroup));
  app.add_option("--conditions", conditions, tr("Test conditions, e.g. 'static, +25 °C, vertical axis'"))
      ->group(tr(kIdGroup));
  app.add_option("--input", input,
                 tr("What the column holds: pulses (per-sample pulse increments), counter (cumulative "
                    "counter, wraps at --counter-bits), angle (cumulative angle/phase in --angle-unit), "
                    "rate (rate samples in --rate-unit), increment (per-sample angle or velocity increments in "
                    "--angle-unit: an IMU's delta theta or delta v). Default: implied by a unit suffix of the column's "
                    "name (gyro_x_dps: rate), else pulses"))
      ->option_text("pulses|counter|angle|rate|increment")
      ->group(tr("Input"));
  app.add_option("--column", column, tr("Column to read: a header name or a 1-based index"))->group(tr("Input"));
  app.add_option("--rate", rate_hz,
                 tr("Sample rate, Hz (default: metadata rate_hz, else a time column, else 400 for pulse and counter "
                    "input; rate and angle input need one of these)"))
      ->check(real_in(kMinRateHz, kMaxRateHz, "Hz"))
      ->group(tr("Input"));
  app.add_option("--scale", scale_arcsec, tr("Pulse weight, arcsec per pulse (default: metadata or 0.92)"))
      ->check(real_in(kMinScaleArcsec, kMaxScaleArcsec, "arcsec"))
      ->group(tr("Input"));
  app.add_option("--counter-bits", counter_bits, tr("Width of a wrapping counter, bits (counter input)"))
      ->check(whole_in(1, 64))
      ->capture_default_str()
      ->group(tr("Input"));
  app.add_option("--angle-unit", angle_unit,
                 tr("Unit of angle input: arcsec, deg, rad, s (clock phase), or m/s (an accelerometer's cumulative "
                    "velocity). Default: the column name's suffix (_deg, _rad, _arcsec, _mps), else arcsec"))
      ->option_text("arcsec|deg|rad|s|m/s")
      ->group(tr("Input"));
  app.add_option("--rate-unit", rate_unit,
                 tr("Unit of rate input: deg/h, deg/s, rad/s, 1 (dimensionless clock frequency), or an "
                    "accelerometer's m/s^2, g, mg, ug. Default: the column name's suffix (_dps, _dph, _rads, _g, "
                    "_mps2, ...), else deg/h"))
      ->option_text("deg/h|deg/s|rad/s|1|m/s^2|g|mg|ug")
      ->group(tr("Input"));
  app.add_option("--time-tolerance", time_tolerance,
                 tr("Time-column steps off the sample period by more than this fraction of it are reported as "
                    "jitter (accepted up to half a period; 1.5 periods or more is a gap, an error)"))
      ->check(real_in(0.0, 0.5, ""))
      ->capture_default_str()
      ->group(tr("Input"));
  add_gaps_option(app, gaps);
  add_memory_option(app, max_memory);
}

CLI::Option* add_memory_option(CLI::App& app, std::string& size) {
  const auto check = [](std::string& s) {
    try {
      (void)memory_ceiling_option(s);
      return std::string();
    } catch (const UsageError& e) {
      return std::string(e.what());
    }
  };
  return app
      .add_option(
          kMaxMemoryOption, size,
          tr("The most memory one record may take, e.g. 8G (K, M, G, T: binary units). Default: half the memory "
             "rwcalc may use (the least of the physical memory, ulimit -v, ulimit -d and the cgroup's limit). A "
             "record beyond it is refused with the memory it needs"))
      ->check(CLI::Validator(check, "SIZE"))
      ->option_text("SIZE")
      ->group(tr("Input"));
}

MemoryCeiling memory_ceiling_of(const std::string& size) {
  return size.empty() ? default_memory_ceiling() : memory_ceiling_option(size);
}

void add_gaps_option(CLI::App& app, std::string& gaps) {
  app.add_option("--gaps", gaps,
                 tr("Gaps in the time column (steps of 1.5 periods or more): refuse (an error naming the gap), or "
                    "segments (the record is split at the gaps and the Allan variance pooled over the segments; "
                    "no difference spans a gap)"))
      ->check(CLI::IsMember({"refuse", "segments"}))
      ->option_text("refuse|segments")
      ->capture_default_str()
      ->group(tr("Input"));
}

ReadOptions InputArgs::options() const {
  ReadOptions o;
  if (!input.empty()) o.mode = parse_input_mode(input);
  o.column = column;
  o.rate_hz = rate_hz;
  o.scale_arcsec = scale_arcsec;
  o.counter_bits = counter_bits;
  if (!angle_unit.empty()) o.angle_unit = parse_angle_unit(angle_unit);
  if (!rate_unit.empty()) o.rate_unit = parse_rate_unit(rate_unit);
  o.time_tolerance = time_tolerance;
  o.gaps_as_segments = gaps == "segments";
  source.apply(o);
  if (!max_memory.empty()) o.memory = memory_ceiling_option(max_memory);
  const std::string* given[] = {&serial, &operator_name, &test_date, &conditions};
  for (std::size_t i = 0; i < std::size(given); ++i)
    if (!given[i]->empty()) o.identification[std::string(kIdentificationKeys[i])] = *given[i];
  return o;
}

void print_input_notes(std::ostream& err, const Recording& rec) {
  for (const std::string& w : rec.warnings) print_message(err, trf("warning: {}: {}", as_typed(rec.source), w));
  for (const std::string& n : rec.notes) print_message(err, trf("note: {}: {}", as_typed(rec.source), n));
}

void print_input_notes(std::ostream& err, const nlohmann::json& analysis) {
  const auto in = analysis.find("input");
  if (in == analysis.end() || !in->is_object()) return;
  const std::string source = as_typed(analysis.value("source", std::string()));
  for (const char* kind : {"warnings", "notes"})
    for (const auto& line : in->value(kind, nlohmann::json::array()))
      if (line.is_string())
        print_message(err, kind[0] == 'w' ? trf("warning: {}: {}", source, line.get<std::string>())
                                          : trf("note: {}: {}", source, line.get<std::string>()));
}

}  // namespace rwcalc::cli
