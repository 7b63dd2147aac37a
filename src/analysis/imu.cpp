// A whole IMU from one recording (imu.hpp): every channel's analysis, their tables and JSON.
#include "rwcalc/imu.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <iterator>
#include <sstream>
#include <tuple>
#include <utility>

#include "fit_range.hpp"
#include "rwcalc/encode.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/parallel.hpp"
#include "rwcalc/printable.hpp"
#include "rwcalc/progress.hpp"
#include "rwcalc/units.hpp"

namespace rwcalc {

namespace imu_impl {

struct ChannelSpec {
  std::string column;
  SensorKind kind;
};

// The channel's read options: its column, and rate input in the unit given for its kind (else the
// column name's suffix decides, as for analyze).
ReadOptions channel_read(const ImuOptions& o, const ChannelSpec& c) {
  ReadOptions r = o.read;
  r.column = c.column;
  r.column_not_time = true;
  const bool gyro = c.kind == SensorKind::Gyro;
  r.unit_advice = gyro ? tr(" (a gyro column needs its unit: give --gyro-unit deg/h, deg/s, rad/s (or arcsec, deg, rad "
                            "for increments), or name the column with a unit suffix such as gyro_x_dps)")
                       : tr(" (an accelerometer column needs its unit: give --accel-unit m/s^2, g, mg, ug (or m/s for "
                            "increments), or name the column with a unit suffix such as acc_x_g)");
  if (const std::optional<RateUnit> unit = gyro ? o.gyro_unit : o.accel_unit) {
    r.mode = InputMode::Rate;
    r.rate_unit = unit;
  } else if (const std::optional<AngleUnit> inc = gyro ? o.gyro_increment_unit : o.accel_increment_unit) {
    r.mode = InputMode::Increment;
    r.angle_unit = inc;
  }
  return r;
}

// No --gyro or --accel: every column whose name tells a gyro or accelerometer unit (or a ROS Imu
// field), said in `note`.
std::vector<ChannelSpec> channels_by_name(const std::string& path, const ReadOptions& read, std::string& note) {
  const ImuColumnNames names = imu_column_names(path, read);
  std::vector<ChannelSpec> specs;
  for (const auto& c : names.gyro) specs.push_back({c, SensorKind::Gyro});
  for (const auto& c : names.accel) specs.push_back({c, SensorKind::Accelerometer});
  if (specs.empty())
    throw UsageError(
        tr("imu needs at least one column: give --gyro COLS and/or --accel COLS (no column name has a "
           "unit suffix such as _dps or _g, nor is a ROS field such as angular_velocity.x)"));
  const auto list = [](const std::vector<std::string>& v) {
    std::string s;
    for (const auto& c : v) s += (s.empty() ? "" : ", ") + c;
    return s.empty() ? std::string("-") : s;
  };
  note = trf("channels from the column names: gyro {}; accelerometer {} (--gyro and --accel choose others)",
             list(names.gyro), list(names.accel));
  return specs;
}

void check_kind(const Recording& rec, const ChannelSpec& c) {
  const std::optional<SensorKind> read = sensor_kind(rec.phase.kind);
  if (read == c.kind) return;
  const bool gyro = c.kind == SensorKind::Gyro;
  const char* read_as = !read ? N_("clock data") : *read == SensorKind::Gyro ? N_("gyro") : N_("accelerometer");
  throw UsageError(trf("{}: column '{}' is given as {} but was read as {} ({}); give its unit with {}", rec.source,
                       c.column, gyro ? "--gyro" : "--accel", tr(read_as), describe_input(rec),
                       gyro ? "--gyro-unit (deg/h, deg/s, rad/s)" : "--accel-unit (m/s^2, g, mg, ug)"));
}

/// Each channel of its kind and each column once (the reader refuses the time column): a column
/// given twice (by name and by index, or as gyro and accelerometer) would count one sensor's noise
/// twice in the noise file.
void check_channels(const std::vector<Recording>& recs, const std::vector<ChannelSpec>& specs) {
  for (std::size_t i = 0; i < recs.size(); ++i) {
    const ChannelSpec& c = specs[i];
    const auto option = [](const ChannelSpec& s) { return s.kind == SensorKind::Gyro ? "--gyro" : "--accel"; };
    for (std::size_t k = 0; k < i; ++k)
      if (recs[k].column_index == recs[i].column_index)
        throw UsageError(trf("{}: column '{}' is given twice ({} {} and {} {}); give each column once", recs[i].source,
                             recs[i].column_name, option(specs[k]), specs[k].column, option(c), c.column));
    check_kind(recs[i], c);
  }
}

/// Columns on the screen, as fmt counts them when it pads: code points, not bytes (Cyrillic).
std::size_t display_width(std::string_view s) {
  return static_cast<std::size_t>(
      std::count_if(s.begin(), s.end(), [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; }));
}

std::string imu_num(double v, int sig = 4) { return fmt::format("{:.{}g}", v, sig); }

// "2.41 [2.39, 2.43]" or "< 0.031" (unresolved: the 95 % upper bound), "-" when not fitted.
std::string cell(const Coefficient& c, double factor) {
  if (!c.enabled) return "-";
  if (!c.resolved) return fmt::format("< {}", imu_num(c.value * factor, 3));
  return fmt::format("{} [{}, {}]", imu_num(c.value * factor, 4), imu_num(c.low * factor, 3),
                     imu_num(c.high * factor, 3));
}

std::string units_line(const UnitSet& u) {
  return trf("Q {}, N {}, B {}, K {}, R {}; mean and Allan deviation in {}", localized_label(u[Term::Q]),
             localized_label(u[Term::N]), localized_label(u[Term::B]), localized_label(u[Term::K]),
             localized_label(u[Term::R]), localized_label(u.deviation));
}

// Earth rate and class verdict: what was done for this channel, one phrase.
std::string earth_and_verdict(const AnalysisResult& r) {
  if (r.sensor != SensorKind::Gyro) return tr("no Earth rate, no class verdict (accelerometer)");
  const std::string earth = r.earth_rate_applied
                                ? trf("Earth rate {} °/h subtracted", imu_num(r.earth_rate_deg_per_h, 4))
                                : std::string(tr("no Earth rate subtracted"));
  const std::string verdict =
      r.verdict_applies ? trf("class verdict: {}", r.verdict.statement()) : std::string(tr("no class verdict"));
  return fmt::format("{}; {}{}", earth, verdict,
                     r.not_applied_reason.empty()
                         ? ""
                         : tr(" (ask with --vertical or imu --vertical-gyro COL, --limits, --earth-rate)"));
}

}  // namespace imu_impl

using namespace imu_impl;

ImuResult analyze_imu(const std::string& path, const ImuOptions& options) {
  require_valid(options);
  std::vector<ChannelSpec> specs;
  for (const auto& c : options.gyro_columns) specs.push_back({c, SensorKind::Gyro});
  for (const auto& c : options.accel_columns) specs.push_back({c, SensorKind::Accelerometer});
  std::string found;  // the channels the column names gave, when none was given
  if (specs.empty()) specs = channels_by_name(path, options.read, found);
  ImuResult out;
  out.source = path;
  out.gyro_units = output_units(SensorKind::Gyro, options.gyro_output_unit);
  out.accel_units = output_units(SensorKind::Accelerometer, options.accel_output_unit);
  // Every channel is read in one pass over the text and checked before any is analysed: a column
  // given twice is refused before the work, and always the same pair is named.
  std::vector<ReadOptions> reads;
  reads.reserve(specs.size());
  for (const ChannelSpec& c : specs) reads.push_back(channel_read(options, c));
  std::vector<Recording> recs = read_recordings(path, reads);
  check_channels(recs, specs);
  if (!found.empty()) recs.front().notes.push_back(found);
  out.channels.resize(specs.size());
  Progress progress(trf("analysing the channels of {}", printable(path)), specs.size(), options.analysis.progress);
  parallel_for(specs.size(), [&](std::size_t i) {
    const Recording rec = std::move(recs[i]);
    AnalysisOptions a = options.analysis;
    if (!options.vertical_gyro.empty() && specs[i].kind == SensorKind::Gyro &&
        (specs[i].column == options.vertical_gyro || rec.column_name == options.vertical_gyro))
      a.earth_rate = a.verdict_wanted = true;
    try {
      out.channels[i] = {rec.column_name, specs[i].kind, analyze(rec, a)};
    } catch (const Error& e) {  // one channel cannot be analysed: the whole IMU's file would be wrong
      throw Error(trf("column '{}': {}; leave it out of {} to analyse the other columns", rec.column_name, e.what(),
                      specs[i].kind == SensorKind::Gyro ? "--gyro" : "--accel"),
                  e.code());
    }
    progress.advance();
  });
  return out;
}

std::string format_channel(const AnalysisResult& r, const UnitSet& shown) {
  std::string s = trf_either(r.sensor == SensorKind::Gyro, N_("rwcalc gyro: {}, column '{}'\n\n"),
                             N_("rwcalc accelerometer: {}, column '{}'\n\n"), as_typed(r.source), as_typed(r.column));
  s += format_warnings(r.warnings);
  s += trf("Data\n  {} samples at {:g} Hz, {:.1f} s ({:.2f} h); mean {} {}; {}\n", r.samples, r.rate_hz, r.duration_s,
           r.duration_s / 3600.0, imu_num(r.mean_rate_deg_per_h * shown.deviation.factor, 6),
           localized_label(shown.deviation), earth_and_verdict(r));
  s += format_segments(r);
  s += trf("\nAllan deviation ({}, {:g} % bounds)\n  {:>11} {:>12} {:>12} {:>12}\n", to_string(r.allan.estimator),
           100 * r.allan.confidence, tr("tau (s)"), tr("sigma"), tr("low"), tr("high"));
  const double k = shown.deviation.factor;
  for (const auto& p : r.allan.points)
    s += fmt::format("  {:>11.5g} {:>12.5g} {:>12.5g} {:>12.5g}\n", p.tau_s, p.dev * k, p.dev_low * k, p.dev_high * k);
  s +=
      trf("  (in {})\n\nNoise coefficients (fit over tau {:g}..{:g} s; 95 % profile intervals; < : not "
          "resolved, 95 % upper bound)\n",
          localized_label(shown.deviation), r.fit.used.front().tau_s, r.fit.used.back().tau_s);
  const UnitSet si = si_units(r.sensor);
  std::size_t name_width = 26;  // as wide as the longest term name (Russian ones are longer)
  for (const Term t : kAllTerms) name_width = std::max(name_width, display_width(localized_meaning(r.sensor, t)));
  for (const Term t : kAllTerms)
    s += fmt::format("  {} {:<{}} {:<28} {:<12} = {} {}\n", term_name(t), localized_meaning(r.sensor, t), name_width,
                     cell(r.fit[t], shown[t].factor), localized_label(shown[t]), cell(r.fit[t], si[t].factor),
                     localized_label(si[t]));
  s += trf("  chi2/dof = {:.2f} (dof {}, p = {:.3g}); fit range: {}\n", r.fit.chi2_per_dof, r.fit.dof, r.fit.p_value,
           r.fit_range.reason());
  return s;
}

namespace imu_impl {

std::vector<const ImuChannel*> of_kind(const ImuResult& r, SensorKind k) {
  std::vector<const ImuChannel*> out;
  for (const auto& c : r.channels)
    if (c.kind == k) out.push_back(&c);
  return out;
}

// One table per kind: a row per term, a column per axis.
std::string kind_table(const std::vector<const ImuChannel*>& axes, const UnitSet& u) {
  if (axes.empty()) return {};
  const SensorKind kind = axes.front()->kind;
  const UnitSet si = si_units(kind);
  // Columns as wide as their widest cell (the SI N with its interval is the widest).
  std::size_t width = 12;
  for (const auto* a : axes)
    for (const Term t : kAllTerms)
      width = std::max({width, a->column.size(), cell(a->result.fit[t], u[t].factor).size(),
                        cell(a->result.fit[t], si[t].factor).size()});
  const int kWidth = static_cast<int>(width + 2);
  std::string s =
      trf_either(kind == SensorKind::Gyro,
                 N_("Gyro ({} axes; {};\n  95 % profile intervals; < : not resolved, 95 % upper bound)\n"),
                 N_("Accelerometer ({} axes; {};\n  95 % profile intervals; < : not resolved, 95 % upper bound)\n"),
                 axes.size(), units_line(u));
  // The row heads' column fits the longest (the Russian term names are longer than the English).
  std::vector<std::string> heads{tr("mean")};
  for (const Term t : kAllTerms) heads.push_back(fmt::format("{} {}", term_name(t), localized_meaning(kind, t)));
  heads.push_back(trf("N in {}", localized_label(si[Term::N])));
  heads.push_back(trf("K in {}", localized_label(si[Term::K])));
  heads.push_back(tr("fit chi2/dof (p)"));
  heads.push_back(tr("fit tau (s)"));
  std::size_t head_width = 30;
  for (const auto& h : heads) head_width = std::max(head_width, display_width(h) + 2);
  s += fmt::format("  {:<{}}", "", head_width);
  for (const auto* a : axes) s += marked_as_typed(fmt::format("{:<{}}", printable(a->column), kWidth));
  s += "\n";
  std::size_t next_head = 0;
  auto row = [&](auto&& value) {
    s += fmt::format("  {:<{}}", heads.at(next_head++), head_width);
    for (const auto* a : axes) s += fmt::format("{:<{}}", value(a->result), kWidth);
    s += "\n";
  };
  row([&](const AnalysisResult& r) { return imu_num(r.mean_rate_deg_per_h * u.deviation.factor, 6); });
  for (const Term t : kAllTerms) row([&](const AnalysisResult& r) { return cell(r.fit[t], u[t].factor); });
  row([&](const AnalysisResult& r) { return cell(r.fit[Term::N], si[Term::N].factor); });
  row([&](const AnalysisResult& r) { return cell(r.fit[Term::K], si[Term::K].factor); });
  row([](const AnalysisResult& r) { return fmt::format("{:.2f} ({:.2g})", r.fit.chi2_per_dof, r.fit.p_value); });
  row([](const AnalysisResult& r) { return trf("{:g}..{:g}", r.fit.used.front().tau_s, r.fit.used.back().tau_s); });
  for (const auto* a : axes) s += fmt::format("  {}: {}\n", as_typed(a->column), earth_and_verdict(a->result));
  return s + "\n";
}

// Each axis' noise density (N) and random walk (K) in SI, and the value the noise file uses.
struct AxisNoise {
  std::string column;
  Coefficient N, K;          ///< in SI (factor applied)
  double rejected_chi2 = 0;  ///< χ²/dof of a fit the goodness of fit rejected (its intervals scaled), else 0
  std::string lines;         ///< frequencies of the spectral lines taken off the fit's points, Hz ("" none)
};

Coefficient scaled(const Coefficient& c, double f) {
  Coefficient o = c;
  o.estimate *= f, o.value *= f, o.sigma *= f, o.low *= f, o.high *= f;
  return o;
}

std::vector<AxisNoise> axis_noise(const ImuResult& r, SensorKind kind) {
  const UnitSet si = si_units(kind);
  std::vector<AxisNoise> out;
  for (const auto* c : of_kind(r, kind)) {
    std::string lines;
    for (const auto& l : c->result.fit_range.lines) lines += fmt::format("{}{:.4g}", lines.empty() ? "" : ", ", l.f_hz);
    out.push_back({c->column, scaled(c->result.fit[Term::N], si[Term::N].factor),
                   scaled(c->result.fit[Term::K], si[Term::K].factor),
                   c->result.fit_rejected() ? c->result.fit.chi2_per_dof : 0.0, lines});
  }
  return out;
}

// Why an axis' coefficient is left out of the noise file's key ("" when it qualifies): a fit the
// goodness of fit rejects, or a value that is only an upper bound.
std::string left_out_because(const AxisNoise& a, const Coefficient& c) {
  if (a.rejected_chi2 > 0) return fmt::format("its fit is rejected (chi2/dof {:.3g})", a.rejected_chi2);
  if (!c.resolved) return "not resolved (only its 95 % upper bound is known)";
  return {};
}

// The combined value of one coefficient over the axes that qualify (an accepted fit and a resolved
// value; every axis when `all`): the largest, or their mean. When none qualifies, the largest value
// or bound of every axis, marked `fallback`; `bound` when a value used is an upper bound.
struct Combined {
  double value = 0;
  bool bound = false;
  bool fallback = false;  ///< no axis qualified: the largest of all (a bound or a rejected fit's value)
  std::string from;       ///< the worst axis' column
  std::size_t axes = 0;   ///< how many axes the value is taken from
};

Combined combine(const std::vector<AxisNoise>& axes, Coefficient AxisNoise::*which, AxisCombination how,
                 bool all = false) {
  auto qualifies = [&](const AxisNoise& a) { return all || left_out_because(a, a.*which).empty(); };
  Combined c;
  c.fallback = std::none_of(axes.begin(), axes.end(), qualifies);
  double sum = 0;
  bool any_bound = false;
  for (const auto& a : axes) {
    if (!c.fallback && !qualifies(a)) continue;
    const Coefficient& k = a.*which;
    sum += k.value;
    ++c.axes;
    any_bound = any_bound || !k.resolved;
    if (k.value >= c.value) c.value = k.value, c.from = a.column, c.bound = !k.resolved;
  }
  if (how == AxisCombination::Mean && c.axes > 0) {
    c.value = sum / static_cast<double>(c.axes);
    c.bound = any_bound;
  }
  return c;
}

nlohmann::json noise_json(const std::vector<AxisNoise>& axes, SensorKind kind) {
  const UnitSet si = si_units(kind);
  auto coef = [](const Coefficient& c, const ShownUnit& u, const std::string& left_out) {
    return nlohmann::json{{"value", c.value},
                          {"low95", c.low},
                          {"high95", c.high},
                          {"resolved", c.resolved},
                          {"unit", u.ascii},
                          {"in_keys", left_out.empty()},
                          {"left_out_because", left_out.empty() ? nlohmann::json(nullptr) : nlohmann::json(left_out)}};
  };
  nlohmann::json list = nlohmann::json::array();
  for (const auto& a : axes)
    list.push_back({{"column", a.column},
                    {"noise_density", coef(a.N, si[Term::N], left_out_because(a, a.N))},
                    {"random_walk", coef(a.K, si[Term::K], left_out_because(a, a.K))},
                    {"fit_rejected", a.rejected_chi2 > 0}});
  const Combined n = combine(axes, &AxisNoise::N, AxisCombination::Worst);
  const Combined k = combine(axes, &AxisNoise::K, AxisCombination::Worst);
  return {{"axes", std::move(list)},
          {"worst",
           {{"noise_density", n.value},
            {"noise_density_axis", n.from},
            {"noise_density_no_axis_qualifies", n.fallback},
            {"random_walk", k.value},
            {"random_walk_axis", k.from},
            {"random_walk_is_upper_bound", k.bound},
            {"random_walk_no_axis_qualifies", k.fallback},
            {"rule",
             "the worst axis with an accepted fit and a resolved value; when none qualifies, the largest "
             "value or 95 % upper bound of every axis"}}}};
}

}  // namespace imu_impl

nlohmann::json to_json(const ImuResult& r) {
  nlohmann::json channels = nlohmann::json::array();
  for (const auto& c : r.channels)
    channels.push_back(to_json(c.result, c.kind == SensorKind::Gyro ? r.gyro_units : r.accel_units));
  nlohmann::json noise = nlohmann::json::object();
  for (const SensorKind k : {SensorKind::Gyro, SensorKind::Accelerometer})
    if (const auto axes = axis_noise(r, k); !axes.empty()) noise[std::string(to_string(k))] = noise_json(axes, k);
  const auto& first = r.channels.front().result;
  return {{"schema_version", json_input::kResultSchemaVersion},
          {"source", r.source},
          {"input", first.input},
          {"samples", first.samples},
          {"rate_hz", first.rate_hz},
          {"duration_s", first.duration_s},
          {"channels", std::move(channels)},
          {"noise", std::move(noise)},
          {"conventions",
           {{"noise_density", "N, the white-noise level: sigma^2 = N^2/tau (Kalibr's continuous-time noise density)"},
            {"random_walk", "K, the bias random walk: sigma^2 = K^2 tau/3 (Kalibr's random walk)"},
            {"intervals", "95 % profile likelihood; resolved=false: value is the 95 % upper bound"}}}};
}

std::string format_imu(const ImuResult& r) {
  const auto& first = r.channels.front().result;
  std::string s = trf("rwcalc imu: {}\n\n", as_typed(r.source));
  for (const auto& c : r.channels) {
    if (c.result.warnings.empty()) continue;
    s += fmt::format("[{}] ", as_typed(c.column)) + format_warnings(c.result.warnings);
  }
  s += trf("Data\n  {} samples at {:g} Hz (tau0 = {:g} ms), {:.1f} s ({:.2f} h); {} channels\n", first.samples,
           first.rate_hz, 1000.0 / first.rate_hz, first.duration_s, first.duration_s / 3600.0, r.channels.size());
  s += format_segments(first) + "\n";
  s += kind_table(of_kind(r, SensorKind::Gyro), r.gyro_units);
  s += kind_table(of_kind(r, SensorKind::Accelerometer), r.accel_units);
  s +=
      tr("Conventions: IEEE 952 model sigma² = 3Q²/tau² + N²/tau + (2 ln2/π)B² + K²tau/3 + R²tau²/2 per axis;\n"
         "  N is the noise density and K the bias random walk of Kalibr's IMU noise model.\n");
  return s;
}

std::string rostopic_scalar(const std::string& rostopic) {
  const auto quoted = yaml_quoted(rostopic);
  if (!quoted)
    throw UsageError(trf("--rostopic '{}': not UTF-8 text; a YAML file cannot carry these bytes", printable(rostopic)));
  return *quoted;
}

NoiseFormat parse_noise_format(std::string_view name) {
  constexpr std::pair<std::string_view, NoiseFormat> names[] = {{"kalibr", NoiseFormat::Kalibr},
                                                                {"openvins", NoiseFormat::OpenVins},
                                                                {"vins-fusion", NoiseFormat::VinsFusion},
                                                                {"orb-slam3", NoiseFormat::OrbSlam3}};
  for (const auto& [n, f] : names)
    if (n == name) return f;
  throw UsageError(
      trf("--noise-format '{}': unknown; expected kalibr, openvins, vins-fusion or orb-slam3", printable(name)));
}

bool takes_discrete(NoiseFormat format) { return format == NoiseFormat::VinsFusion; }

namespace imu_impl {

std::string yaml_num(double v) { return fmt::format("{:.6e}", v); }  // always a YAML float
// A key's value: every digit a double carries, so the file reads back as the JSON's value.
std::string yaml_key_num(double v) { return fmt::format("{:.16e}", v); }

// One kind's axes in the comments: each axis' N and K with intervals, and why one is left out of the keys.
std::string axes_comments(const std::vector<AxisNoise>& axes, SensorKind kind, bool all) {
  const UnitSet si = si_units(kind);
  std::string s = fmt::format("# {} axes: N [{}], K [{}]\n", to_string(kind), si[Term::N].ascii, si[Term::K].ascii);
  for (const auto& a : axes) {
    auto one = [&](const Coefficient& c) {
      return c.resolved ? fmt::format("{} [{}, {}]", yaml_num(c.value), yaml_num(c.low), yaml_num(c.high))
                        : fmt::format("< {} (not resolved: 95 % upper bound)", yaml_num(c.value));
    };
    s += fmt::format("#   {}: N {}; K {}\n", yaml_comment(a.column), one(a.N), one(a.K));
    for (const auto& [name, c] : {std::pair{"N", &a.N}, std::pair{"K", &a.K}})
      if (const std::string why = left_out_because(a, *c); !why.empty())
        s += all ? fmt::format("#     {} in the keys (--keys-from-all-axes) although {}\n", name, why)
                 : fmt::format("#     {} left out of the keys: {}\n", name, why);
    if (a.rejected_chi2 > 0) s += "#     the five-term model does not describe this axis; see rwcalc diagnose\n";
    if (!a.lines.empty())
      s += fmt::format("#     spectral line(s) at {} Hz: their Allan variance taken off before the fit\n", a.lines);
  }
  return s;
}

// How one consumer names the four noise keys and lays out its file.
struct FormatSpec {
  const char* consumer;
  const char* keys[2][2];  ///< [accelerometer, gyro][N, K]
  const char* indent;      ///< of the keys (OpenVINS nests them under imu0:)
  bool opencv;             ///< read by OpenCV's FileStorage: the %YAML:1.0 header
};

const FormatSpec& spec_of(NoiseFormat f) {
  static const FormatSpec specs[] = {
      {"Kalibr",
       {{"accelerometer_noise_density", "accelerometer_random_walk"},
        {"gyroscope_noise_density", "gyroscope_random_walk"}},
       "",
       false},
      {"OpenVINS (kalibr_imu_chain.yaml)",
       {{"accelerometer_noise_density", "accelerometer_random_walk"},
        {"gyroscope_noise_density", "gyroscope_random_walk"}},
       "  ",
       true},
      {"VINS-Fusion", {{"acc_n", "acc_w"}, {"gyr_n", "gyr_w"}}, "", true},
      {"ORB-SLAM3", {{"IMU.NoiseAcc", "IMU.AccWalk"}, {"IMU.NoiseGyro", "IMU.GyroWalk"}}, "", true}};
  return specs[static_cast<std::size_t>(f)];
}

// The factor from a measured N or K to the value written: --inflate, and for discrete-time values
// σ_d = N·√rate (white noise) and σ_bd = K/√rate (the bias random walk's step).
double written_factor(const NoiseFileOptions& o, Term term, double rate_hz) {
  if (!o.discrete) return o.inflate;
  return o.inflate * (term == Term::N ? std::sqrt(rate_hz) : 1.0 / std::sqrt(rate_hz));
}

// A key's line: the value written, its unit and where it comes from.
std::string key_line(const std::string& key, const Combined& c, double factor, const std::string& unit,
                     const char* term, bool worst) {
  std::string from =
      worst ? fmt::format(" worst axis {}", yaml_comment(c.from)) : fmt::format(" mean of {} axes", c.axes);
  if (c.fallback) from += "; NO AXIS QUALIFIES (see the first lines)";
  if (c.bound) from += fmt::format("; UPPER BOUND: {} not resolved (its 95 % bound used)", term);
  return fmt::format("{}: {}  # [{}]{}\n", key, yaml_key_num(c.value * factor), unit, from);
}

// What the values are: continuous or discrete time, inflated or as measured.
std::string values_comment(const NoiseFileOptions& o, double rate_hz) {
  std::string s =
      o.discrete ? fmt::format(
                       "# values: DISCRETE time at {:g} Hz (--discrete): white noise sigma_d = N*sqrt(rate) [rad/s, "
                       "m/s^2],\n#   bias random walk sigma_bd = K/sqrt(rate) [rad/s, m/s^2 per sample]\n",
                       rate_hz)
                 : std::string("# values: continuous time (noise density N, random walk K)\n");
  s += "# the axes' values in the comments below are as measured (continuous time, not inflated)\n";
  s += o.inflate == 1.0
           ? std::string("# not inflated: the keys hold the measured values (--inflate F multiplies them)\n")
           : fmt::format("# INFLATED: every key's noise value is {:g} x the measured one (--inflate {:g})\n", o.inflate,
                         o.inflate);
  return s;
}

// g_norm: the magnitude of the mean of three accelerometer axes (their biases included), else
// standard gravity.
std::string g_norm_line(const ImuResult& r) {
  const auto accel = of_kind(r, SensorKind::Accelerometer);
  if (accel.size() != 3)
    return fmt::format("g_norm: {}  # [m/s^2] standard gravity (not three accelerometer axes)\n",
                       yaml_key_num(units::standard_gravity));
  const double to_si = output_units(SensorKind::Accelerometer, "m/s^2").deviation.factor;
  double sum = 0;
  for (const auto* c : accel) sum += std::pow(c->result.mean_rate_deg_per_h * to_si, 2);
  return fmt::format("g_norm: {}  # [m/s^2] magnitude of the mean of the three accelerometer axes\n",
                     yaml_key_num(std::sqrt(sum)));
}

// The consumer's keys other than the noise values, before them.
std::string format_keys(const ImuResult& r, const NoiseFileOptions& o) {
  const double rate = r.channels.front().result.rate_hz;
  switch (o.format) {
    case NoiseFormat::Kalibr:
      return fmt::format("rostopic: {}\nupdate_rate: {:.6f}  # Hz\n", rostopic_scalar(o.rostopic), rate);
    case NoiseFormat::OpenVins:
      return fmt::format(
          "imu0:\n  # not measured here: identity extrinsic and intrinsics (model kalibr), no time offset\n"
          "  T_i_b:\n    - [1.0, 0.0, 0.0, 0.0]\n    - [0.0, 1.0, 0.0, 0.0]\n    - [0.0, 0.0, 1.0, 0.0]\n"
          "    - [0.0, 0.0, 0.0, 1.0]\n  model: \"kalibr\"\n"
          "  Tw:\n    - [1.0, 0.0, 0.0]\n    - [0.0, 1.0, 0.0]\n    - [0.0, 0.0, 1.0]\n"
          "  R_IMUtoGYRO:\n    - [1.0, 0.0, 0.0]\n    - [0.0, 1.0, 0.0]\n    - [0.0, 0.0, 1.0]\n"
          "  Ta:\n    - [1.0, 0.0, 0.0]\n    - [0.0, 1.0, 0.0]\n    - [0.0, 0.0, 1.0]\n"
          "  R_IMUtoACC:\n    - [1.0, 0.0, 0.0]\n    - [0.0, 1.0, 0.0]\n    - [0.0, 0.0, 1.0]\n"
          "  Tg:\n    - [0.0, 0.0, 0.0]\n    - [0.0, 0.0, 0.0]\n    - [0.0, 0.0, 0.0]\n"
          "  rostopic: {}\n  time_offset: 0.0\n  update_rate: {:.6f}  # Hz\n",
          rostopic_scalar(o.rostopic), rate);
    case NoiseFormat::VinsFusion: return fmt::format("imu_topic: {}\n", rostopic_scalar(o.rostopic)) + g_norm_line(r);
    case NoiseFormat::OrbSlam3: return fmt::format("IMU.Frequency: {:.6f}  # Hz\n", rate);
  }
  return {};
}

// The unit of a value written: SI densities, or per-sample deviations for discrete values.
std::string written_unit(SensorKind kind, Term term, bool discrete) {
  if (discrete) return kind == SensorKind::Gyro ? "rad/s" : "m/s^2";
  return si_units(kind)[term].ascii;
}

}  // namespace imu_impl

std::string noise_file(const ImuResult& r, const NoiseFileOptions& options) {
  require_valid(options);
  const auto& first = r.channels.front().result;
  const FormatSpec& spec = spec_of(options.format);
  const bool worst = options.combine == AxisCombination::Worst;
  std::string head = fmt::format(
      "{}# IMU noise parameters for {}, from the Allan variance of a static recording.\n"
      "# file: {} (SHA-256 {}), {} samples at {:g} Hz\n"
      "# noise_density = N (white noise, continuous time; sigma^2 = N^2/tau), random_walk = K (bias random\n"
      "# walk; sigma^2 = K^2 tau/3), each axis fitted with 95 % intervals; the values used are the {} of {}.\n",
      spec.opencv ? "%YAML:1.0\n" : "", spec.consumer, yaml_comment(r.source),
      first.input.value("sha256", std::string()), first.samples, first.rate_hz,
      worst ? "worst axis' (the largest)" : "mean",
      options.all_axes ? "every axis (--keys-from-all-axes)" : "the axes with an accepted fit and a resolved value");
  head += values_comment(options, first.rate_hz);
  std::string body, keys = format_keys(r, options);
  for (const SensorKind kind : {SensorKind::Accelerometer, SensorKind::Gyro}) {
    const auto axes = axis_noise(r, kind);
    const int k = kind == SensorKind::Gyro ? 1 : 0;
    if (axes.empty()) {
      body += fmt::format("# no {} channel was analysed: its keys are left out\n", to_string(kind));
      continue;
    }
    body += axes_comments(axes, kind, options.all_axes);
    for (const auto& [t, which, term] :
         {std::tuple{0, &AxisNoise::N, Term::N}, std::tuple{1, &AxisNoise::K, Term::K}}) {
      const Combined c = combine(axes, which, options.combine, options.all_axes);
      const char* name = term == Term::N ? "N" : "K";
      if (c.fallback)
        head += fmt::format(
            "# WARNING: no {} axis has an accepted fit and a resolved {}: {} is the {} of every axis, {}.\n",
            to_string(kind), name, spec.keys[k][t], worst ? "largest" : "mean",
            c.bound ? "an upper bound, not a measured value" : "from a fit the goodness of fit rejects");
      keys += spec.indent + key_line(spec.keys[k][t], c, written_factor(options, term, first.rate_hz),
                                     written_unit(kind, term, options.discrete), name, worst);
    }
  }
  return head + body + keys;
}

}  // namespace rwcalc
