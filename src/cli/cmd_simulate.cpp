// 'rwcalc simulate': write simulated gyro pulse records (docs/simulation.md).
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "numeric_options.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/imu_simulate.hpp"
#include "rwcalc/output.hpp"
#include "rwcalc/printable.hpp"
#include "rwcalc/progress.hpp"
#include "rwcalc/pulse_writer.hpp"
#include "rwcalc/simulate.hpp"
#include "rwcalc/units.hpp"

namespace rwcalc::cli {

namespace {

struct SimulateArgs {
  std::string output;
  std::string truth;
  std::string from;
  bool upper_bounds = false;
  double duration_s = 7200.0;
  double rate_hz = units::gl2d_rate_hz;
  double scale_arcsec = units::gl2d_arcsec_per_pulse;
  std::uint64_t seed = 1;
  std::optional<double> temperature_c;
  bool force = false;
  int runs = 1;
  double arw = 0, bi = 0, rrw = 0, ramp = 0, bias = 0;
  double latitude = units::moscow_latitude_deg;
  bool no_earth_rate = false;
  std::vector<std::string> sinusoids, gauss_markov, bias_steps, warmups;
  double lowpass = 0.0;
  double output_lowpass = 0.0;
  bool white_readout = false;
  double white_angle = 0.0;
  std::optional<double> temp_bias;
  std::string temp_profile;
  std::string max_memory;
  std::string layout = "pulses";
  std::vector<std::string> gyro_noise, accel_noise;
  double gyro_lsb = 0.05, accel_lsb_mg = 3.33;
  std::string accel_unit = "m/s^2";
};

// "a:b[:c]" as numbers, `min_n`..`max_n` of them; errors name the option and the form.
std::vector<double> fields(const std::string& option, const std::string& text, std::size_t min_n, std::size_t max_n,
                           const char* form) {
  std::vector<double> v;
  for (std::size_t start = 0;;) {
    const std::size_t colon = std::min(text.find(':', start), text.size());
    double x = 0.0;
    const auto [ptr, ec] = std::from_chars(text.data() + start, text.data() + colon, x);
    if (colon == start || ec != std::errc() || ptr != text.data() + colon || !std::isfinite(x)) break;
    v.push_back(x);
    if (colon == text.size()) {
      if (v.size() >= min_n && v.size() <= max_n) return v;
      break;
    }
    start = colon + 1;
  }
  throw UsageError(trf("{}: '{}' is not of the form {}", option, text, form));
}

// FILE with _001 inserted before the extension (everything from the first dot of the name).
std::string numbered(const std::string& path, int index, int runs) {
  const std::filesystem::path p(path);
  const std::string name = p.filename().string();
  std::size_t dot = name.find('.', 1);
  if (dot == std::string::npos) dot = name.size();
  const int width = std::max(3, static_cast<int>(std::to_string(runs).size()));
  const std::string numbered_name = fmt::format("{}_{:0{}}{}", name.substr(0, dot), index, width, name.substr(dot));
  return (p.parent_path() / numbered_name).string();
}

std::string g(double v) { return fmt::format("{}", v); }

Metadata metadata_of(const NoiseModel& m, const SimulationSettings& s) {
  Metadata md;
  md.emplace_back("generator", fmt::format("rwcalc simulate {}", RWCALC_VERSION));
  md.emplace_back("rate_hz", g(s.rate_hz));
  md.emplace_back("scale_arcsec_per_pulse", g(s.scale_arcsec));
  if (s.temperature_c) md.emplace_back("temperature_c", g(*s.temperature_c));
  md.emplace_back("seed", fmt::format("{}", s.seed));
  md.emplace_back("samples", fmt::format("{}", s.samples()));
  md.emplace_back("duration_s", g(s.duration_s));
  md.emplace_back("readout", m.readout == ReadoutMode::White ? "white" : "counting");
  auto term = [&](const char* key, double v) {
    if (v != 0.0) md.emplace_back(key, g(v));
  };
  term("arw_deg_per_sqrt_h", m.arw_deg_per_sqrt_h);
  term("bias_instability_deg_per_h", m.bias_instability_deg_per_h);
  term("rrw_deg_per_h_per_sqrt_h", m.rrw_deg_per_h_per_sqrt_h);
  term("ramp_deg_per_h2", m.ramp_deg_per_h2);
  term("bias_deg_per_h", m.bias_deg_per_h);
  term("earth_rate_deg_per_h", m.earth_rate_deg_per_h);
  term("white_angle_arcsec", m.white_angle_arcsec);
  term("lowpass_tc_s", m.lowpass_tc_s);
  term("output_lowpass_tc_s", m.output_lowpass_tc_s);
  for (const auto& x : m.sinusoids)
    md.emplace_back("sinusoid", fmt::format("frequency_hz={} amplitude_deg_per_h={} phase_rad={}", x.f_hz,
                                            x.amp_deg_per_h, x.phase_rad));
  for (const auto& x : m.gauss_markov)
    md.emplace_back("gauss_markov", fmt::format("sigma_deg_per_h={} correlation_time_s={}", x.sigma_deg_per_h, x.tc_s));
  for (const auto& x : m.bias_steps)
    md.emplace_back("bias_step", fmt::format("time_s={} size_deg_per_h={}", x.t_s, x.size_deg_per_h));
  for (const auto& x : m.warmups)
    md.emplace_back("warmup", fmt::format("amplitude_deg_per_h={} time_constant_s={}", x.amp_deg_per_h, x.tc_s));
  if (m.temperature_bias) {
    const auto& tb = *m.temperature_bias;
    const auto& p = tb.profile;
    md.emplace_back("temperature_bias",
                    p.kind == TemperatureProfile::Kind::Ramp
                        ? fmt::format("coefficient_deg_per_h_per_c={} profile=ramp start_c={} end_c={}",
                                      tb.coefficient_deg_per_h_per_c, p.start_c, p.end_c)
                        : fmt::format("coefficient_deg_per_h_per_c={} profile=cycle amplitude_c={} period_s={}",
                                      tb.coefficient_deg_per_h_per_c, p.amp_c, p.period_s));
  }
  return md;
}

// Generate one record and write it block by block as it is generated, so that memory does not
// grow with its length; the file appears only when it is complete (PulseFileWriter).
void write_record(Simulator& sim, const SimulationSettings& sr, const std::string& path, bool force, Io& io) {
  const bool angle = sim.model().output_lowpass_tc_s > 0;
  PulseFileWriter out(path, metadata_of(sim.model(), sr),
                      angle ? PulseFileWriter::Column::Angle : PulseFileWriter::Column::Pulses, force);
  Progress progress(trf("simulating {}", printable(path == "-" ? "<stdout>" : path)), sr.samples(), io.progress,
                    Progress::Measure::Percent);
  sim.stream(sr.seed, [&](const RecordBlock& block) {
    if (angle)
      out.add_angles(block.angles);
    else
      out.add_counts(block.counts);
    progress.advance(angle ? block.angles.size() : block.counts.size());
  });
  out.commit();
}

// Most pulses a record may count: the count is an int64 and the quantizer's floor is exact below
// 2^62; 2^60 leaves room for the random excursions the bound below does not cover.
constexpr double kMaxPulses = 1152921504606846976.0;  // 2^60
// Most samples a record may have (2^40: about 30 days at 400 kHz).
constexpr double kMaxSamples = 1099511627776.0;

// One term's share of the bound on |angle|, arcsec, named by the option that sets it.
struct AngleTerm {
  const char* option;
  double arcsec;
};

// A generous bound of |angle| over the record, term by term: every rate term at its largest for
// the whole duration, random terms at ten standard deviations.
std::vector<AngleTerm> angle_bound_terms(const NoiseModel& m, const SimulationSettings& s) {
  const double T = s.duration_s;
  const double h = 1.0;  // deg/h -> arcsec/s (3600 arcsec per 3600 s)
  std::vector<AngleTerm> t{{"--bias", std::abs(m.bias_deg_per_h) * h * T},
                           {"--latitude", std::abs(m.earth_rate_deg_per_h) * h * T},
                           {"--ramp", std::abs(m.ramp_deg_per_h2) * T / 3600.0 * h * T},
                           {"--bias-instability", 10.0 * m.bias_instability_deg_per_h * h * T},
                           {"--arw", 10.0 * m.arw_deg_per_sqrt_h * units::sqrt_s_per_sqrt_h *
                                         std::sqrt(T)},  // deg/sqrt(h) = 60 arcsec/sqrt(s)
                           {"--rrw", 10.0 * m.rrw_deg_per_h_per_sqrt_h / units::sqrt_s_per_sqrt_h * T * std::sqrt(T)},
                           {"--white-angle", 10.0 * m.white_angle_arcsec}};
  auto add = [&](const char* option, double deg_per_h) { t.push_back({option, deg_per_h * h * T}); };
  for (const auto& x : m.sinusoids) add("--sinusoid", std::abs(x.amp_deg_per_h));
  for (const auto& x : m.gauss_markov) add("--gauss-markov", 10.0 * x.sigma_deg_per_h);
  for (const auto& x : m.bias_steps) add("--bias-step", std::abs(x.size_deg_per_h));
  for (const auto& x : m.warmups) add("--warmup", std::abs(x.amp_deg_per_h));
  if (m.temperature_bias) {
    const auto& p = m.temperature_bias->profile;
    const double swing =
        std::abs(p.start_c) + std::abs(p.end_c) + std::abs(p.amp_c) + std::abs(s.temperature_c.value_or(0.0));
    add("--temp-bias", std::abs(m.temperature_bias->coefficient_deg_per_h_per_c) * swing);
  }
  return t;
}

// Refuse a record whose angle the pulse counts cannot carry, before anything is written; the
// message names the option whose term is largest.
void check_record_range(const NoiseModel& m, const SimulationSettings& s) {
  if (!(s.duration_s * s.rate_hz <= kMaxSamples))
    throw UsageError(trf("--duration {:g} s at --rate {:g} Hz gives {:g} samples, more than the {:g} a record may have",
                         s.duration_s, s.rate_hz, s.duration_s * s.rate_hz, kMaxSamples));
  for (const auto& x : m.bias_steps)
    if (x.t_s > s.duration_s)
      throw UsageError(trf("--bias-step: the time {:g} s is beyond the record's end ({:g} s)", x.t_s, s.duration_s));
  const std::vector<AngleTerm> terms = angle_bound_terms(m, s);
  double angle = 0;
  for (const auto& t : terms) angle += t.arcsec;
  if (angle / s.scale_arcsec <= kMaxPulses) return;
  const auto largest = std::max_element(terms.begin(), terms.end(),
                                        [](const AngleTerm& a, const AngleTerm& b) { return a.arcsec < b.arcsec; });
  throw UsageError(
      trf("{}: the record's angle may reach {:g} arcsec over {:g} s (rate terms at their largest, random terms at ten "
          "sigma), {:g} pulses of {:g} arcsec: beyond the {:g} (2^60) pulses a record can count. Lower {}, shorten "
          "--duration or raise --scale",
          largest->option, angle, s.duration_s, angle / s.scale_arcsec, s.scale_arcsec, kMaxPulses, largest->option));
}

using Take = std::function<bool(const char*)>;

/// The record's settings from the options taken (`s` holds those of --from, if any).
void apply_settings(const SimulateArgs& a, const Take& take, SimulationSettings& s) {
  if (take("--duration")) s.duration_s = a.duration_s;
  if (take("--rate")) s.rate_hz = a.rate_hz;
  if (take("--scale")) s.scale_arcsec = a.scale_arcsec;
  if (a.temperature_c) s.temperature_c = a.temperature_c;
  s.seed = a.seed;
  require_valid(s);  // the library's rules, before the model is checked against the record's range
}

TemperatureBias temperature_bias(double coefficient, const std::string& profile) {
  TemperatureBias tb;
  tb.coefficient_deg_per_h_per_c = coefficient;
  const auto colon = profile.find(':');
  const std::string kind = profile.substr(0, colon);
  const std::string rest = colon == std::string::npos ? "" : profile.substr(colon + 1);
  if (kind == "ramp") {
    const auto v = fields("--temp-profile", rest, 2, 2, "ramp:START_C:END_C");
    for (const double c : v)
      if (c < kMinTemperatureC || c > kMaxTemperatureC)
        throw UsageError(
            trf("--temp-profile: {:g} deg C is outside {:g}..{:g} deg C", c, kMinTemperatureC, kMaxTemperatureC));
    tb.profile = {TemperatureProfile::Kind::Ramp, v[0], v[1], 0.0, 0.0};
  } else if (kind == "cycle") {
    const auto v = fields("--temp-profile", rest, 2, 2, "cycle:AMP_C:PERIOD_S");
    if (!(v[1] >= 1.0 / kMaxRateHz))
      throw UsageError(trf("--temp-profile: the cycle period must be >= {:g} s", 1.0 / kMaxRateHz));
    tb.profile = {TemperatureProfile::Kind::Cycle, 0.0, 0.0, v[0], v[1]};
  } else {
    throw UsageError(trf("--temp-profile: '{}' is neither ramp:START_C:END_C nor cycle:AMP_C:PERIOD_S", profile));
  }
  return tb;
}

/// The extended terms (repeatable options) added to `m`.
void add_extended_terms(const SimulateArgs& a, NoiseModel& m) {
  for (const auto& t : a.sinusoids) {
    const auto v = fields("--sinusoid", t, 2, 3, "F_HZ:AMP_DEG_PER_H[:PHASE_RAD]");
    if (v[0] <= 0 || v[0] > kMaxRateHz)
      throw UsageError(trf("--sinusoid: the frequency must be in (0, {:g}] Hz in '{}'", kMaxRateHz, t));
    m.sinusoids.push_back({v[0], v[1], v.size() > 2 ? v[2] : 0.0});
  }
  for (const auto& t : a.gauss_markov) {
    const auto v = fields("--gauss-markov", t, 2, 2, "SIGMA_DEG_PER_H:TC_S");
    if (v[0] < 0 || v[1] <= 0) throw UsageError(trf("--gauss-markov: need sigma >= 0 and TC_S > 0 in '{}'", t));
    m.gauss_markov.push_back({v[0], v[1]});
  }
  for (const auto& t : a.bias_steps) {
    const auto v = fields("--bias-step", t, 2, 2, "T_S:SIZE_DEG_PER_H");
    if (v[0] < 0) throw UsageError(trf("--bias-step: the time must be >= 0 s in '{}'", t));
    m.bias_steps.push_back({v[0], v[1]});
  }
  for (const auto& t : a.warmups) {
    const auto v = fields("--warmup", t, 2, 2, "AMP_DEG_PER_H:TC_S");
    if (v[1] <= 0) throw UsageError(trf("--warmup: the time constant must be > 0 s in '{}'", t));
    m.warmups.push_back({v[0], v[1]});
  }
  if (a.temp_bias) {
    if (!std::isfinite(*a.temp_bias)) throw UsageError(tr("--temp-bias must be finite"));
    if (a.temp_profile.empty())
      throw UsageError(tr("--temp-bias needs --temp-profile ramp:START_C:END_C or cycle:AMP_C:PERIOD_S"));
    m.temperature_bias = temperature_bias(*a.temp_bias, a.temp_profile);
  } else if (!a.temp_profile.empty()) {
    throw UsageError(tr("--temp-profile needs --temp-bias COEF_DEG_PER_H_PER_C"));
  }
}

/// The noise model from the options taken (`m` holds that of --from, if any).
void apply_model(const SimulateArgs& a, const Take& take, NoiseModel& m) {
  // The options' ranges are checked as they are parsed (numeric_options.hpp), the whole model below.
  if (take("--arw")) m.arw_deg_per_sqrt_h = a.arw;
  if (take("--bias-instability")) m.bias_instability_deg_per_h = a.bi;
  if (take("--rrw")) m.rrw_deg_per_h_per_sqrt_h = a.rrw;
  if (take("--ramp")) m.ramp_deg_per_h2 = a.ramp;
  if (take("--bias")) m.bias_deg_per_h = a.bias;
  if (take("--latitude") || take("--no-earth-rate"))
    m.earth_rate_deg_per_h = a.no_earth_rate ? 0.0 : earth_rate_at(a.latitude);
  if (a.white_readout) m.readout = ReadoutMode::White;
  if (take("--white-angle")) m.white_angle_arcsec = a.white_angle;
  if (take("--lowpass")) m.lowpass_tc_s = a.lowpass;
  if (take("--output-lowpass")) m.output_lowpass_tc_s = a.output_lowpass;
  add_extended_terms(a, m);
  require_valid(m);
}

void write_truth(const std::string& path, const NoiseModel& m, const SimulationSettings& sr, const std::string& record,
                 bool force) {
  nlohmann::json t;
  t["model"] = m;
  t["settings"] = sr;
  t["seed"] = sr.seed;
  t["pulse_file"] = std::filesystem::path(record).filename().string();
  t["quantization_q_arcsec"] = readout_q_arcsec(m.readout, sr.scale_arcsec);
  write_file_atomic(path, t.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n", force);
}

/// The flicker term holds an FFT over twice the record: a record whose memory would pass the
/// ceiling is refused before anything is written.
void check_memory(const NoiseModel& m, const SimulationSettings& s, const std::string& max_memory) {
  const auto need = static_cast<double>(Simulator::memory_bytes(m, s));
  const MemoryCeiling ceiling = memory_ceiling_of(max_memory);
  if (need <= static_cast<double>(ceiling.bytes)) return;
  throw UsageError(
      trf("--bias-instability: a record of {} samples with bias instability needs about {} of memory "
          "(its flicker rate is one FFT over twice the record, {:.0f} bytes per sample), more than the "
          "memory ceiling of {} ({}); shorten --duration, lower --rate, or give {} SIZE if the machine "
          "has the memory",
          s.samples(), format_memory(need), need / static_cast<double>(s.samples()),
          format_memory(static_cast<double>(ceiling.bytes)), ceiling.origin, kMaxMemoryOption));
}

/// The options of a single gyro's record, which the IMU layout does not take.
constexpr std::array<const char*, 22> kPulseOnlyOptions{
    "--temp-profile",   "--from",         "--upper-bounds",     "--truth",         "--scale",
    "--temperature",    "--arw",          "--bias-instability", "--rrw",           "--ramp",
    "--bias",           "--latitude",     "--no-earth-rate",    "--white-readout", "--white-angle",
    "--sinusoid",       "--gauss-markov", "--bias-step",        "--warmup",        "--lowpass",
    "--output-lowpass", "--temp-bias"};

/// One kind's three axes from "N:B:K" given once (every axis) or three times (x, y, z).
std::array<AxisNoise, 3> axis_noise(const char* option, const std::vector<std::string>& given,
                                    const std::array<AxisNoise, 3>& preset) {
  if (given.empty()) return preset;
  if (given.size() != 1 && given.size() != 3)
    throw UsageError(trf("{}: give N:B:K once (every axis) or three times, comma-separated (x, y, z); got {}", option,
                         given.size()));
  std::array<AxisNoise, 3> noise{};
  for (std::size_t i = 0; i < 3; ++i) {
    const auto v = fields(option, given[given.size() == 1 ? 0 : i], 3, 3, "N:B:K");
    for (const double x : v)
      if (x < 0) throw UsageError(trf("{}: every term must be >= 0 in '{}'", option, given[i]));
    noise[i] = {v[0], v[1], v[2]};
  }
  return noise;
}

/// `simulate --layout imu`: one six-axis record (or --runs of them) from the layout's options.
int run_simulate_imu(const SimulateArgs& a, const CLI::App& sub, Io& io) {
  for (const char* name : kPulseOnlyOptions)
    if (sub.count(name) > 0)
      throw UsageError(
          trf("{} is an option of the pulse layout; --layout imu takes --gyro-noise, --accel-noise, "
              "--gyro-step, --accel-step and --accel-unit",
              name));
  ImuLayout layout = adis16405_like_layout();
  layout.gyro = axis_noise("--gyro-noise", a.gyro_noise, layout.gyro);
  layout.accel = axis_noise("--accel-noise", a.accel_noise, layout.accel);
  layout.gyro_lsb_dps = a.gyro_lsb;
  layout.accel_lsb_mg = a.accel_lsb_mg;
  layout.accel_unit = a.accel_unit == "g" ? AccelColumnUnit::G : AccelColumnUnit::MetrePerSecond2;
  SimulationSettings s;
  apply_settings(
      a, [](const char*) { return true; }, s);
  if (a.output == "-" && a.runs > 1) throw UsageError(tr("--runs > 1 needs a file name for -o"));
  const MemoryCeiling ceiling = memory_ceiling_of(a.max_memory);
  if (const auto need = static_cast<double>(imu_memory_bytes(layout, s)); need > static_cast<double>(ceiling.bytes))
    throw UsageError(
        trf("--layout imu: a record of {} samples needs about {} of memory, more than the memory ceiling "
            "of {} ({}); shorten --duration, lower --rate, or give {} SIZE if the machine has the memory",
            s.samples(), format_memory(need), format_memory(static_cast<double>(ceiling.bytes)), ceiling.origin,
            kMaxMemoryOption));
  auto path_of = [&](int r) { return a.runs > 1 ? numbered(a.output, r, a.runs) : a.output; };
  std::vector<OutputTarget> targets;
  for (int r = 1; r <= a.runs; ++r) targets.push_back({"-o", path_of(r)});
  check_output_targets(targets, a.force);
  for (int r = 1; r <= a.runs; ++r) {
    SimulationSettings sr = s;
    sr.seed = s.seed + static_cast<std::uint64_t>(r - 1);
    const std::string path = path_of(r);
    write_imu_record(layout, sr, imu_metadata(layout, sr), path, a.force, io.progress);
    if (path != "-")
      io.out << trf("wrote {} (six IMU axes, {} samples, {} s at {} Hz, seed {})\n", printable(path), sr.samples(),
                    sr.duration_s, sr.rate_hz, sr.seed);
  }
  return 0;
}

int run_simulate(const SimulateArgs& a, const CLI::App& sub, Io& io) {
  if (a.layout == "imu") return run_simulate_imu(a, sub, io);
  if (!a.gyro_noise.empty() || !a.accel_noise.empty() || sub.count("--gyro-step") || sub.count("--accel-step") ||
      sub.count("--accel-unit"))
    throw UsageError(tr("--gyro-noise, --accel-noise, --gyro-step, --accel-step and --accel-unit need --layout imu"));
  // Without --from every option counts (its default included); with it, only those given.
  const Take take = [&](const char* name) { return a.from.empty() || sub.count(name) > 0; };
  SimulationSettings s;
  NoiseModel m;
  if (!a.from.empty()) {
    s.scale_arcsec = a.scale_arcsec;
    std::vector<std::string> notes;
    m = model_from_analysis_file(a.from, s, a.upper_bounds, &notes);
    for (const auto& n : notes) print_message(io.err, fmt::format("--from {}: {}", a.from, n));
  } else if (a.upper_bounds) {
    throw UsageError(tr("--upper-bounds needs --from"));
  }
  apply_settings(a, take, s);
  apply_model(a, take, m);
  if (a.runs < 1) throw UsageError(trf("--runs must be >= 1, got {}", a.runs));
  check_record_range(m, s);
  check_memory(m, s, a.max_memory);
  if (a.output == "-" && a.runs > 1) throw UsageError(tr("--runs > 1 needs a file name for -o"));

  auto path_of = [&](const std::string& p, int r) { return a.runs > 1 ? numbered(p, r, a.runs) : p; };
  // Refuse before writing anything when any target exists or two name the same file (no
  // half-written set of runs, no truth written over its record).
  std::vector<OutputTarget> targets;
  for (int r = 1; r <= a.runs; ++r) {
    targets.push_back({"-o", path_of(a.output, r)});
    if (!a.truth.empty()) targets.push_back({"--truth", path_of(a.truth, r)});
  }
  check_output_targets(targets, a.force);
  Simulator sim(m, s);
  for (int r = 1; r <= a.runs; ++r) {
    SimulationSettings sr = s;
    sr.seed = s.seed + static_cast<std::uint64_t>(r - 1);
    const std::string path = path_of(a.output, r);
    write_record(sim, sr, path, a.force, io);
    if (!a.truth.empty()) write_truth(path_of(a.truth, r), m, sr, path, a.force);
    if (path != "-")
      io.out << trf("wrote {} ({} samples, {} s at {} Hz, seed {})\n", printable(path), sr.samples(), sr.duration_s,
                    sr.rate_hz, sr.seed);
  }
  return 0;
}

}  // namespace

namespace {

/// The record: its length, rate, pulse weight, seed, metadata and layout.
void add_record_options(CLI::App* sub, SimulateArgs& a) {
  sub->add_option("--duration", a.duration_s, tr("Record length, s"))
      ->check(real_in(0.0, 1e9, "s", Ends::OpenLow))
      ->capture_default_str()
      ->group(tr("Record"));
  sub->add_option("--rate", a.rate_hz, tr("Sample rate, Hz"))
      ->check(real_in(kMinRateHz, kMaxRateHz, "Hz"))
      ->capture_default_str()
      ->group(tr("Record"));
  sub->add_option("--scale", a.scale_arcsec, tr("Pulse weight q, arcsec per pulse"))
      ->check(real_in(kMinScaleArcsec, kMaxScaleArcsec, "arcsec"))
      ->capture_default_str()
      ->group(tr("Record"));
  sub->add_option("--seed", a.seed, tr("Seed of the random streams (same seed, same file)"))
      ->check(whole_in(0, UINT64_MAX))
      ->capture_default_str()
      ->group(tr("Record"));
  sub->add_option("--temperature", a.temperature_c, tr("Nominal temperature written as metadata, deg C"))
      ->check(real_in(kMinTemperatureC, kMaxTemperatureC, "deg C"))
      ->group(tr("Record"));
  sub->add_flag("--force", a.force, tr("Overwrite existing files"))->group(tr("Record"));
  add_memory_option(*sub, a.max_memory)->group(tr("Record"));
  sub->add_option("--runs", a.runs, tr("Write K realisations FILE_001… with seeds seed, seed+1, …"))
      ->check(whole_in(1, 100000))
      ->capture_default_str()
      ->group(tr("Record"));
  sub->add_option("--layout", a.layout,
                  tr("What the file holds: pulses (one gyro's pulse counts) or imu (a six-axis MEMS-like IMU: "
                     "gyro_x_dps ... and acc_x_mps2 ... or acc_x_g ... columns, ADIS16405-like levels unless "
                     "--gyro-noise and --accel-noise say otherwise; docs/simulation.md)"))
      ->check(CLI::IsMember({"pulses", "imu"}))
      ->capture_default_str()
      ->group(tr("Record"));
}

/// --layout imu: the six axes' noise levels, output steps and accelerometer unit.
void add_imu_layout_options(CLI::App* sub, SimulateArgs& a) {
  sub->add_option("--gyro-noise", a.gyro_noise,
                  tr("--layout imu: the gyros' N:B:K (deg/sqrt(h), deg/h, deg/h/sqrt(h)), once for every axis or "
                     "three times for x,y,z"))
      ->delimiter(',')
      ->group(tr("IMU layout"));
  sub->add_option("--accel-noise", a.accel_noise,
                  tr("--layout imu: the accelerometers' N:B:K (m/s/sqrt(h), ug, m/s/h/sqrt(h)), once for every axis "
                     "or three times for x,y,z"))
      ->delimiter(',')
      ->group(tr("IMU layout"));
  sub->add_option("--gyro-step", a.gyro_lsb, tr("--layout imu: the gyro output step (LSB), deg/s"))
      ->check(real_in(1e-9, 1e6, "deg/s"))
      ->capture_default_str()
      ->group(tr("IMU layout"));
  sub->add_option("--accel-step", a.accel_lsb_mg, tr("--layout imu: the accelerometer output step (LSB), mg"))
      ->check(real_in(1e-9, 1e6, "mg"))
      ->capture_default_str()
      ->group(tr("IMU layout"));
  sub->add_option("--accel-unit", a.accel_unit,
                  tr("--layout imu: the accelerometer columns' unit, m/s^2 (acc_x_mps2 ...) or g (acc_x_g ...)"))
      ->check(CLI::IsMember({"m/s^2", "g"}))
      ->capture_default_str()
      ->group(tr("IMU layout"));
}

/// The five-term model, the bias, the Earth rate and the read-out.
void add_noise_term_options(CLI::App* sub, SimulateArgs& a) {
  sub->add_option("--arw", a.arw, tr("Angle random walk N, deg/sqrt(h)"))
      ->check(real_in(0.0, kMaxRateDegPerH, "deg/sqrt(h)"))
      ->group(tr("Noise terms"));
  sub->add_option("--bias-instability", a.bi, tr("Bias instability B (flicker rate noise), deg/h"))
      ->check(real_in(0.0, kMaxRateDegPerH, "deg/h"))
      ->group(tr("Noise terms"));
  sub->add_option("--rrw", a.rrw, tr("Rate random walk K, deg/h/sqrt(h)"))
      ->check(real_in(0.0, kMaxRateDegPerH, "deg/h/sqrt(h)"))
      ->group(tr("Noise terms"));
  sub->add_option("--ramp", a.ramp, tr("Rate ramp R, deg/h^2"))
      ->check(real_in(-kMaxRateDegPerH, kMaxRateDegPerH, "deg/h^2"))
      ->group(tr("Noise terms"));
  sub->add_option("--bias", a.bias, tr("Constant bias, deg/h"))
      ->check(real_in(-kMaxRateDegPerH, kMaxRateDegPerH, "deg/h"))
      ->group(tr("Noise terms"));
  sub->add_option("--latitude", a.latitude, tr("Latitude for the vertical Earth rate 15.041*sin(lat) deg/h, deg"))
      ->check(real_in(-90.0, 90.0, "deg"))
      ->capture_default_str()
      ->group(tr("Noise terms"));
  sub->add_flag("--no-earth-rate", a.no_earth_rate, tr("Do not add the Earth rate"))->group(tr("Noise terms"));
  sub->add_flag("--white-readout", a.white_readout,
                tr("Dither-like read-out: a fresh uniform phase per sample makes count errors white (Q = q/sqrt(6)); "
                   "default: counting with sawtooth errors"))
      ->group(tr("Noise terms"));
  sub->add_option("--white-angle", a.white_angle, tr("Extra white angle noise before counting, rms arcsec"))
      ->check(real_in(0.0, 1e12, "arcsec"))
      ->group(tr("Noise terms"));
}

/// The effects beyond the five-term model (the diagnosis' extended terms).
void add_extended_term_options(CLI::App* sub, SimulateArgs& a) {
  sub->add_option("--sinusoid", a.sinusoids,
                  tr("Sinusoidal rate F_HZ:AMP_DEG_PER_H[:PHASE_RAD] (Hz, deg/h, rad); repeatable"))
      ->group(tr("Extended terms"));
  sub->add_option("--gauss-markov", a.gauss_markov, tr("Gauss-Markov rate SIGMA_DEG_PER_H:TC_S (deg/h, s); repeatable"))
      ->group(tr("Extended terms"));
  sub->add_option("--bias-step", a.bias_steps, tr("Bias step T_S:SIZE_DEG_PER_H (s from start, deg/h); repeatable"))
      ->group(tr("Extended terms"));
  sub->add_option("--warmup", a.warmups,
                  tr("Warm-up transient AMP_DEG_PER_H:TC_S, rate amp*exp(-t/tc) (deg/h, s); repeatable"))
      ->group(tr("Extended terms"));
  sub->add_option("--lowpass", a.lowpass,
                  tr("First-order low-pass of the sensed rate inside the sensor, time constant s"))
      ->check(real_in(0.0, 1e9, "s"))
      ->group(tr("Extended terms"));
  sub->add_option(
         "--output-lowpass", a.output_lowpass,
         tr("First-order low-pass of the counted rate in the output chain, time constant s; the file then holds "
            "the filtered angle in arcsec (column 'angle', read with --input angle)"))
      ->check(real_in(0.0, 1e9, "s"))
      ->group(tr("Extended terms"));
  sub->add_option("--temp-bias", a.temp_bias,
                  tr("Temperature-driven bias coefficient, deg/h per deg C (needs --temp-profile)"))
      ->check(real_in(-kMaxRateDegPerH, kMaxRateDegPerH, "deg/h per deg C"))
      ->group(tr("Extended terms"));
  sub->add_option(
         "--temp-profile", a.temp_profile,
         tr("Temperature during the record: ramp:START_C:END_C (linear) or cycle:AMP_C:PERIOD_S (about --temperature); "
            "bias = coef*(T(t) - T_nominal), T_nominal = --temperature (ramp: else START_C; cycle: else 0)"))
      ->group(tr("Extended terms"));
}

}  // namespace

void register_simulate(CLI::App& app, Runner& runner) {
  auto args = std::make_shared<SimulateArgs>();
  auto* sub = app.add_subcommand(
      "simulate",
      tr("Simulate a gyro pulse record (exact discrete-time noise terms, counted in whole pulses) and write it as a "
         "GL-2D pulse file (.gz compresses). Rates are in deg/h (= arcsec/s)."));
  auto& a = *args;
  sub->add_option("-o,--output", a.output, tr("Output pulse file (FILE.csv or FILE.csv.gz; - for stdout)"))
      ->check(output_name())
      ->required();
  sub->add_option("--truth", a.truth, tr("Also write the ground truth (model JSON, seed, settings) to this file"))
      ->check(output_name());
  sub->add_option("--from", a.from,
                  tr("Take the model from 'rwcalc analyze --json' or 'rwcalc diagnose --json' output: the fitted model "
                     "(terms at their estimates; terms the fit left out or did not resolve are left out)"));
  sub->add_flag("--upper-bounds", a.upper_bounds,
                tr("With --from: put the terms the fit did not resolve in at their 95 % upper bounds (a pessimistic "
                   "model, not the fitted one)"));
  add_record_options(sub, a);
  add_imu_layout_options(sub, a);
  add_noise_term_options(sub, a);
  add_extended_term_options(sub, a);
  sub->callback(
      [&runner, args, sub] { runner = [args, sub](Io& io) -> int { return run_simulate(*args, *sub, io); }; });
}

}  // namespace rwcalc::cli
