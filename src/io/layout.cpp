// Layout detection: metadata keys, the delimiter, and the choice of the sample, time and
// temperature columns. Two columns that could both be the one wanted are an error, never a choice.
#include "layout.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <numeric>

#include <fmt/format.h>

#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/limits.hpp"

namespace rwcalc::detail {

namespace {

constexpr std::size_t kQuoteLimit = 40;

// The first four are the units a stamp's magnitude can tell; "%time" is ROS's receive time (ns
// since the epoch) in CSV exports of ROS bags (`rostopic echo -p`), "field.header.stamp" the
// message's own stamp there, "__time" PlotJuggler's time in seconds.
constexpr TimeName kTimeNames[] = {{"time_s", "s", 1},     {"time_ms", "ms", 1e3},
                                   {"time_us", "us", 1e6}, {"time_ns", "ns", 1e9},
                                   {"time", "", 0},        {"t", "", 0},
                                   {"timestamp", "", 0},   {"t_s", "s", 1},
                                   {"time_sec", "s", 1},   {"timestamp_s", "s", 1},
                                   {"t_ms", "ms", 1e3},    {"timestamp_ms", "ms", 1e3},
                                   {"t_us", "us", 1e6},    {"timestamp_us", "us", 1e6},
                                   {"t_ns", "ns", 1e9},    {"timestamp_ns", "ns", 1e9},
                                   {"%time", "ns", 1e9},   {"field.header.stamp", "ns", 1e9},
                                   {"__time", "s", 1}};
constexpr const TimeName* kByMagnitude = &kTimeNames[4];  // "time": the headerless time column
constexpr const TimeName* kNanoseconds = &kTimeNames[3];
constexpr std::string_view kReceiveTime = "%time", kHeaderStamp = "field.header.stamp";
constexpr std::string_view kTemperatureNames[] = {"temperature_c", "temperature", "temp_c", "temp", "t_c"};

// The names of a column that holds the samples, by InputMode.
const std::vector<std::string_view> kValueNames[] = {{"pulses", "pulse", "counts", "count"},
                                                     {"counter", "count", "counts", "pulses"},
                                                     {"angle", "phase"},
                                                     {"rate", "gyro", "frequency", "freq"},
                                                     {"increment", "delta", "dtheta", "dv"}};

const TimeName* time_name(std::string_view field) {
  for (const TimeName& t : kTimeNames)
    if (iequals(field, t.name)) return &t;
  return nullptr;
}

bool any_named(std::string_view field, const auto& names) {
  return std::any_of(std::begin(names), std::end(names), [&](std::string_view n) { return iequals(field, n); });
}

std::vector<std::size_t> columns_where(const std::vector<std::string>& header, const auto& matches) {
  std::vector<std::size_t> out;
  for (std::size_t c = 0; c < header.size(); ++c)
    if (matches(header[c])) out.push_back(c);
  return out;
}

std::vector<std::size_t> all_columns(std::size_t n) {
  std::vector<std::size_t> all(n);
  std::iota(all.begin(), all.end(), std::size_t{0});
  return all;
}

// A metadata key as compared: without regard to case, '-' read as '_' ("Rate-Hz" is rate_hz).
std::string canonical_key(std::string_view key) {
  std::string k(key);
  for (char& c : k) c = c == '-' ? '_' : (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c;
  return k;
}

// Keys rwcalc does not read but that look like a sample rate or a pulse weight: with them in the
// file, falling back to 400 Hz or 0.92″ would be a silent choice.
bool looks_like_rate_key(const std::string& k) {
  const auto has = [&](std::string_view w) { return k.find(w) != std::string::npos; };
  return k == "rate" || k == "fs" || k == "freq" || k == "frequency" || k == "odr" || k == "data_rate" ||
         k == "output_rate" || has("hz") || (has("sampl") && (has("rate") || has("freq")));
}
bool looks_like_scale_key(const std::string& k) {
  return k.find("scale") != std::string::npos || k.find("arcsec") != std::string::npos ||
         k.find("per_pulse") != std::string::npos;
}

}  // namespace

std::string quoted(std::string_view s) {
  std::string out = "'";
  const std::size_t n = std::min(s.size(), kQuoteLimit);
  for (const char ch : s.substr(0, n)) {
    const auto c = static_cast<unsigned char>(ch);
    out += c < 0x20 || c == 0x7f ? fmt::format("\\x{:02x}", c) : std::string(1, ch);
  }
  return out + (s.size() > n ? fmt::format("...' ({} characters)", s.size()) : "'");
}

bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return (x | 0x20) == (y | 0x20) && ((x >= 'A' && x <= 'Z') || (x >= 'a' && x <= 'z') || x == y);
         });
}

std::string_view normalise_decimal(std::string_view f, bool comma_ok, std::string& scratch) {
  if (!comma_ok) return f;
  const auto c = f.find(',');
  if (c == std::string_view::npos || f.find(',', c + 1) != std::string_view::npos ||
      f.find('.') != std::string_view::npos)
    return f;
  scratch.assign(f);
  scratch[c] = '.';
  return scratch;
}

bool looks_numeric(std::string_view f, bool comma_ok) {
  std::string scratch;
  f = normalise_decimal(f, comma_ok, scratch);
  if (f.starts_with('+')) f.remove_prefix(1);
  double v = 0;
  const auto r = std::from_chars(f.data(), f.data() + f.size(), v);
  return !f.empty() && r.ptr == f.data() + f.size() && r.ec != std::errc::invalid_argument;
}

void Metadata::read(std::string_view body, std::size_t line, const std::string& file) {
  // key = letter or '_', then letters, digits, '_', '.', '-'; then ':' or '='.
  body = trim(body);
  std::size_t k = 0;
  auto key_char = [](char c, bool first) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_' ||
           (!first && ((c >= '0' && c <= '9') || c == '.' || c == '-'));
  };
  while (k < body.size() && key_char(body[k], k == 0)) ++k;
  if (k == 0) return;
  std::size_t c = k;
  while (c < body.size() && (body[c] == ' ' || body[c] == '\t')) ++c;
  if (c >= body.size() || (body[c] != ':' && body[c] != '=')) return;
  const std::string canonical = canonical_key(body.substr(0, k));
  const bool known = canonical == "rate_hz" || canonical == "scale_arcsec_per_pulse" || canonical == "temperature_c" ||
                     std::find(std::begin(kIdentificationKeys), std::end(kIdentificationKeys), canonical) !=
                         std::end(kIdentificationKeys);
  const std::string key = known ? canonical : std::string(body.substr(0, k));
  const std::string value(trim(body.substr(c + 1)));

  // A known number: positive where asked, equal to any earlier spelling of the key, and within
  // the usable range of rwcalc/limits.hpp (as for the options that override these keys).
  auto set_known = [&](std::optional<double>& slot, bool positive, double lo, double hi, const char* unit) {
    std::string scratch;
    std::string_view v = normalise_decimal(value, true, scratch);
    if (v.starts_with('+')) v.remove_prefix(1);
    double x = 0;
    const auto r = std::from_chars(v.data(), v.data() + v.size(), x);
    if (v.empty() || r.ec != std::errc() || r.ptr != v.data() + v.size() || !std::isfinite(x) || (positive && !(x > 0)))
      throw InputError(file, line,
                       trf("metadata {}: {} is not a {}number", key, quoted(value), positive ? tr("positive ") : ""));
    if (slot && *slot != x)
      throw InputError(file, line,
                       trf("metadata {} given twice with different values ({} and {})", key, quoted(all[key]),
                           quoted(value)));
    slot = x;
    if (!(x >= lo && x <= hi))
      throw InputError(file, line,
                       trf("metadata {}: {} {} is outside the usable range {:g}..{:g} {}", key, quoted(value), unit, lo,
                           hi, unit));
  };
  if (key == "rate_hz") {
    set_known(rate_hz, true, kMinRateHz, kMaxRateHz, "Hz");
    rate_line = line;
  } else if (key == "scale_arcsec_per_pulse") {
    set_known(scale_arcsec, true, kMinScaleArcsec, kMaxScaleArcsec, "arcsec");
  } else if (key == "temperature_c") {
    set_known(temperature_c, false, kMinTemperatureC, kMaxTemperatureC, "deg C");
  } else if (!known && looks_like_rate_key(canonical) && !unread_rate_key) {
    unread_rate_key = {key, line};
  } else if (!known && looks_like_scale_key(canonical) && !unread_scale_key) {
    unread_scale_key = {key, line};
  }
  auto [it, inserted] = all.try_emplace(key, value);
  if (!inserted && it->second != value) it->second += "; " + value;  // nothing is dropped
}

const TimeName* time_unit_of_stamp(double first) {
  const double a = std::abs(first);
  if (a < 1e6) return &kTimeNames[0];  // seconds from near 0 (up to 11 days)
  if (a < 1e8) return nullptr;         // neither near 0 nor epoch-like
  const int decade = a < 1e11 ? 0 : a < 1e14 ? 1 : a < 1e17 ? 2 : 3;
  return &kTimeNames[decade];
}

std::string_view delim_name(Delim d) {
  constexpr std::string_view kNames[] = {"comma", "semicolon", "tab", "blanks"};
  return kNames[static_cast<int>(d)];
}

Delim Layout::detect_delimiter(std::string_view line) {
  if (line.find('\t') != std::string_view::npos) return Delim::Tab;
  if (line.find(';') != std::string_view::npos) return Delim::Semicolon;
  if (line.find(',') == std::string_view::npos) return Delim::Blanks;
  // A comma whose pieces contain blanks is a decimal comma in a blank-separated line ("0,0025 3").
  for (std::size_t start = 0;;) {
    const auto e = line.find(',', start);
    const auto piece = trim(line.substr(start, e == std::string_view::npos ? e : e - start));
    if (piece.find_first_of(" \t") != std::string_view::npos) return Delim::Blanks;
    if (e == std::string_view::npos) return Delim::Comma;
    start = e + 1;
  }
}

void Layout::choose(const ReadOptions& o, std::size_t where, const std::string& file) {
  if (!o.column.empty()) choose_given(o.column, where, file);
  if (header.empty()) {
    // Headerless layouts: [value], [time, value], [time, value, temperature].
    if (o.column.empty()) {
      if (ncols > 3)
        throw InputError(file, where, trf("{} columns and no header row: choose the column with --column", ncols));
      value_col = ncols == 1 ? 0 : 1;
    }
    if ((ncols == 2 || ncols == 3) && value_col == 1) time_col = 0, time_unit = kByMagnitude;
    if (ncols == 3 && value_col == 1) temp_col = 2;
  } else {
    choose_by_name(o, !o.column.empty(), file);
  }
  roles.assign(ncols, Role::Skip);
  roles[value_col] = Role::Value;
  if (time_col) roles[*time_col] = Role::Time;
  if (time2_col) roles[*time2_col] = Role::Time2;
  if (temp_col) roles[*temp_col] = Role::Temperature;
  if (nanosec_col) roles[*nanosec_col] = Role::Nanosec;
}

// --column: a 1-based index, or a header name.
void Layout::choose_given(const std::string& want, std::size_t where, const std::string& file) {
  if (std::all_of(want.begin(), want.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    std::size_t idx = 0;
    std::from_chars(want.data(), want.data() + want.size(), idx);
    if (idx < 1 || idx > ncols)
      throw InputError(file, where,
                       trf("--column {} is out of range: the file has {} column{}", want, ncols,
                           ncols == 1 ? "" : "s"));
    value_col = idx - 1;
    return;
  }
  if (header.empty())
    throw InputError(file, where,
                     trf("--column '{}' names a column but the file has no header row; give a "
                         "1-based index instead",
                         want));
  value_col = named_column(want, "--column", file);
}

std::size_t Layout::named_column(const std::string& want, std::string_view option, const std::string& file) const {
  const auto named = columns_where(header, [&](std::string_view h) { return iequals(h, want); });
  if (named.empty())
    throw InputError(file, header_line,
                     trf("no column named '{}' ({}); the columns are {}", want, option,
                         column_list(all_columns(ncols))));
  if (named.size() > 1)
    throw InputError(file, header_line,
                     trf("{} columns are named '{}' (columns {}); choose one by its index with --column", named.size(),
                         want, column_list(named)));
  return named.front();
}

// The time columns kept: the one --time-column names; of a ROS export's field.header.stamp and
// %time the stamp (said in a note); a ROS 2 stamp split into `…sec` and `…nanosec` as one time.
void Layout::choose_times(const ReadOptions& o, std::vector<std::size_t>& times, const std::string& file) {
  if (!o.time_column.empty()) {
    if (header.empty())
      throw InputError(file, layout_line,
                       trf("--time-column '{}' names a column but the file has no header row", o.time_column));
    const std::size_t t = named_column(o.time_column, "--time-column", file);
    if (t == value_col)
      throw InputError(file, header_line, trf("--time-column '{}' is the column of the samples", o.time_column));
    times = {t};
    return;
  }
  const auto is = [&](std::size_t c, std::string_view name) { return iequals(header[c], name); };
  const auto stamp = std::find_if(times.begin(), times.end(), [&](std::size_t c) { return is(c, kHeaderStamp); });
  const auto receive = std::find_if(times.begin(), times.end(), [&](std::size_t c) { return is(c, kReceiveTime); });
  if (stamp != times.end() && receive != times.end()) {
    notes.push_back(trf("time from '{}' (the sensor's stamp), not '{}' (the receive time; --time receive takes it)",
                        kHeaderStamp, kReceiveTime));
    times.erase(receive);
  }
  if (!times.empty()) return;
  for (std::size_t c = 0; c < header.size(); ++c) {
    const std::string& h = header[c];
    if (h.size() < 7 || !iequals(std::string_view(h).substr(h.size() - 7), "nanosec")) continue;
    const std::string sec = h.substr(0, h.size() - 7) + "sec";
    const auto s = columns_where(header, [&](std::string_view n) { return iequals(n, sec); });
    if (s.size() != 1 || s.front() == value_col || c == value_col) continue;
    times = {s.front()};
    nanosec_col = c;
    notes.push_back(trf("time from '{}' and '{}' (seconds and nanoseconds of one stamp)", sec, h));
    return;
  }
}

// The samples (unless --column chose them), the time column(s) and the temperature column of a
// header row.
void Layout::choose_by_name(const ReadOptions& o, bool value_given, const std::string& file) {
  auto times = columns_where(header, [](std::string_view h) { return time_name(h) != nullptr; });
  auto temps = columns_where(header, [](std::string_view h) { return any_named(h, kTemperatureNames); });
  if (!value_given && ncols == 1) times.clear();  // a lone column named "time" holds the samples
  if (value_given) {
    if (o.column_not_time && time_name(header[value_col]))
      throw InputError(file, header_line,
                       trf("column '{}' ({}) is the time column, not a sensor's samples", header[value_col],
                           value_col + 1));
    std::erase(times, value_col);
    std::erase(temps, value_col);
  } else {
    const InputMode mode = o.mode.value_or(InputMode::Pulses);
    const auto& names = kValueNames[static_cast<int>(mode)];
    const auto named = columns_where(header, [&](std::string_view h) { return any_named(h, names); });
    if (named.size() > 1)
      throw InputError(file, header_line,
                       trf("columns {} could each hold the {} samples; choose one with --column", column_list(named),
                           to_string(mode)));
    std::vector<std::size_t> rest;
    for (std::size_t k = 0; k < ncols; ++k)
      if (std::count(times.begin(), times.end(), k) + std::count(temps.begin(), temps.end(), k) == 0) rest.push_back(k);
    if (named.empty() && rest.size() != 1)
      throw InputError(file, header_line,
                       trf("cannot tell which column holds the {} samples; choose one with --column (the "
                           "columns are {})",
                           to_string(mode), column_list(all_columns(ncols))));
    value_col = named.empty() ? rest.front() : named.front();
  }
  choose_times(o, times, file);
  if (times.size() > 2)
    throw InputError(file, header_line,
                     trf("{} time columns ({}); rwcalc reads one, or two that agree: remove the others", times.size(),
                         column_list(times)));
  if (temps.size() > 1)
    throw InputError(file, header_line,
                     trf("{} temperature columns ({}); rwcalc reports one temperature: remove or rename "
                         "the others",
                         temps.size(), column_list(temps)));
  if (!times.empty()) {
    time_col = times[0];
    time_unit = nanosec_col ? kNanoseconds : time_name(header[times[0]]);
    if (!time_unit) time_unit = kByMagnitude;  // --time-column with a name that says no unit
  }
  if (times.size() == 2) time2_col = times[1], time2_unit = time_name(header[times[1]]);
  if (!temps.empty()) temp_col = temps[0];
}

std::string Layout::column_list(const std::vector<std::size_t>& cols) const {
  std::string s;
  for (const std::size_t c : cols) {
    if (!s.empty()) s += ", ";
    if (s.size() > 200) {
      s += "...";
      break;
    }
    s += header.empty() ? std::to_string(c + 1) : fmt::format("{} ({})", quoted(header[c]), c + 1);
  }
  return s;
}

std::string Layout::describe(Role role) const {
  const auto index = static_cast<std::size_t>(std::find(roles.begin(), roles.end(), role) - roles.begin());
  const std::string_view kind = role == Role::Value         ? "column"
                                : role == Role::Temperature ? "temperature column"
                                                            : "time column";
  return header.empty() ? fmt::format("{} {}", kind, index + 1) : fmt::format("{} '{}'", kind, header[index]);
}

}  // namespace rwcalc::detail

namespace rwcalc::detail {

namespace {

// Unit suffixes of column names (IMU exports): the channel's kind and unit. Longer suffixes first,
// so that `_deg_s` is not taken for `_s` nor `_rad_s` for `_rad`'s neighbours.
struct UnitSuffix {
  std::string_view suffix;
  InputMode mode;
  AngleUnit angle = AngleUnit::Arcsec;
  RateUnit rate = RateUnit::DegPerHour;
};
constexpr UnitSuffix kUnitSuffixes[] = {{"_deg_s", InputMode::Rate, {}, RateUnit::DegPerSecond},
                                        {"_degps", InputMode::Rate, {}, RateUnit::DegPerSecond},
                                        {"_dps", InputMode::Rate, {}, RateUnit::DegPerSecond},
                                        {"_deg_h", InputMode::Rate, {}, RateUnit::DegPerHour},
                                        {"_degph", InputMode::Rate, {}, RateUnit::DegPerHour},
                                        {"_dph", InputMode::Rate, {}, RateUnit::DegPerHour},
                                        {"_rad_s", InputMode::Rate, {}, RateUnit::RadPerSecond},
                                        {"_radps", InputMode::Rate, {}, RateUnit::RadPerSecond},
                                        {"_rads", InputMode::Rate, {}, RateUnit::RadPerSecond},
                                        {"_m_s2", InputMode::Rate, {}, RateUnit::MetrePerSecond2},
                                        {"_mps2", InputMode::Rate, {}, RateUnit::MetrePerSecond2},
                                        {"_ms2", InputMode::Rate, {}, RateUnit::MetrePerSecond2},
                                        {"_mg", InputMode::Rate, {}, RateUnit::MilliG},
                                        {"_ug", InputMode::Rate, {}, RateUnit::MicroG},
                                        {"_g", InputMode::Rate, {}, RateUnit::G},
                                        {"_mps", InputMode::Angle, AngleUnit::MetrePerSecond},
                                        {"_arcsec", InputMode::Angle, AngleUnit::Arcsec},
                                        {"_deg", InputMode::Angle, AngleUnit::Deg},
                                        {"_rad", InputMode::Angle, AngleUnit::Rad}};

bool ends_with_nocase(std::string_view s, std::string_view suffix) {
  return s.size() > suffix.size() && iequals(s.substr(s.size() - suffix.size()), suffix);
}

// sensor_msgs/Imu's fields carry their units by definition: angular_velocity in rad/s,
// linear_acceleration in m/s² ("field.angular_velocity.x" of rostopic, "angular_velocity.x" of ROS 2,
// "/imu/angular_velocity/x" of PlotJuggler).
constexpr UnitSuffix kRosGyro{"angular_velocity", InputMode::Rate, {}, RateUnit::RadPerSecond};
constexpr UnitSuffix kRosAccel{"linear_acceleration", InputMode::Rate, {}, RateUnit::MetrePerSecond2};

const UnitSuffix* ros_field_unit(std::string_view column) {
  const std::size_t n = column.size();
  if (n < 3 || (column[n - 2] != '.' && column[n - 2] != '/')) return nullptr;
  const char axis = static_cast<char>(column[n - 1] | 0x20);
  if (axis != 'x' && axis != 'y' && axis != 'z') return nullptr;
  const std::string_view stem = column.substr(0, n - 2);
  for (const UnitSuffix* u : {&kRosGyro, &kRosAccel})
    if (stem.size() >= u->suffix.size() && iequals(stem.substr(stem.size() - u->suffix.size()), u->suffix) &&
        (stem.size() == u->suffix.size() ||
         std::string_view("./_").find(stem[stem.size() - u->suffix.size() - 1]) != std::string_view::npos))
      return u;
  return nullptr;
}

const UnitSuffix* unit_suffix(std::string_view column) {
  if (const UnitSuffix* ros = ros_field_unit(column)) return ros;
  for (const UnitSuffix& u : kUnitSuffixes)
    if (ends_with_nocase(column, u.suffix)) return &u;
  return nullptr;
}

// The unit of one kind (angle or rate): the option's, else the suffix's, else the default; each
// choice the option did not make is said.
template <class Unit>
Unit choose_unit(std::optional<Unit> given, std::optional<Unit> named, Unit fallback, std::string_view what,
                 std::string_view option, std::string_view column, InputChoice& c) {
  const bool angle = what == "angle";  // a message per kind, so that each translates whole
  if (given && named && *given != *named)
    c.warnings.push_back(trf_either(angle, N_("the column name '{}' says angle in {}, but {} {} is used as given"),
                                    N_("the column name '{}' says rate in {}, but {} {} is used as given"), column,
                                    to_string(*named), option, to_string(*given)));
  if (given) return *given;
  if (named) {
    c.notes.push_back(trf_either(angle, N_("angle unit {} from the column name '{}'"),
                                 N_("rate unit {} from the column name '{}'"), to_string(*named), column));
    return *named;
  }
  c.notes.push_back(
      trf_either(angle, N_("angle unit {} (the default: no {} and no unit suffix such as _dps in the column name)"),
                 N_("rate unit {} (the default: no {} and no unit suffix such as _dps in the column name)"),
                 to_string(fallback), option));
  return fallback;
}

}  // namespace

InputChoice choose_input(const ReadOptions& o, std::string_view column, const std::string& /*file*/,
                         std::size_t /*line*/) {
  InputChoice c;
  const UnitSuffix* u = unit_suffix(column);
  if (o.mode) {
    c.mode = *o.mode;
    if (u && u->mode != c.mode)
      c.warnings.push_back(trf("the column name '{}' says {} input, but --input {} is used as given", column,
                               to_string(u->mode), to_string(c.mode)));
  } else if (u) {
    c.mode = u->mode;
    c.notes.push_back(trf("input {} from the column name '{}' (no --input given)", to_string(c.mode), column));
  }
  const bool angle = c.mode == InputMode::Angle || c.mode == InputMode::Increment, rate = c.mode == InputMode::Rate;
  const bool named_angle = u && u->mode == InputMode::Angle, named_rate = u && u->mode == InputMode::Rate;
  if (angle)
    c.angle_unit = choose_unit(o.angle_unit, named_angle ? std::optional(u->angle) : std::nullopt, AngleUnit::Arcsec,
                               "angle", "--angle-unit", column, c);
  if (rate)
    c.rate_unit = choose_unit(o.rate_unit, named_rate ? std::optional(u->rate) : std::nullopt, RateUnit::DegPerHour,
                              "rate", "--rate-unit", column, c);
  return c;
}

}  // namespace rwcalc::detail
