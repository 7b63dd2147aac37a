// A simulated six-axis IMU record (imu_simulate.hpp): six independent exact simulator records, one
// per axis, read out in whole output steps and written side by side as rate columns.
#include "rwcalc/imu_simulate.hpp"

#include <fmt/format.h>

#include <cmath>
#include <vector>

#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/output.hpp"
#include "rwcalc/printable.hpp"
#include "rwcalc/progress.hpp"
#include "rwcalc/random.hpp"
#include "rwcalc/simulate.hpp"
#include "rwcalc/units.hpp"
#include "rwcalc/version.hpp"

namespace rwcalc {

namespace {

constexpr std::array<const char*, 3> kAxes{"x", "y", "z"};
// Stream numbers of the six axes, far from the per-term streams of one record and the ensembles'.
constexpr std::uint64_t kAxisStream = 0x696d752d61786973ULL;  // "imu-axis"
// 1 g as the simulator's accelerometer rate unit: (1/3600 m/s)/s, i.e. m/s/h.
constexpr double kMpsPerHPerG = units::standard_gravity * 3600.0;
// Text is handed to the output in pieces of about this size.
constexpr std::size_t kFlushBytes = std::size_t{1} << 20;

bool is_gyro(std::size_t axis) { return axis < 3; }

/// One output step of the axis in the column's unit (°/s, g or m/s²).
double column_step(const ImuLayout& l, std::size_t axis) {
  if (is_gyro(axis)) return l.gyro_lsb_dps;
  const double g = l.accel_lsb_mg * 1e-3;
  return l.accel_unit == AccelColumnUnit::G ? g : g * units::standard_gravity;
}

/// Decimals that write every multiple of `step` exactly: those of the step itself when it has few
/// (0.05 → 2, 0.00333 → 5), else six significant digits of the step.
int decimals_of(double step) {
  for (int d = 0; d <= 9; ++d) {
    const double scaled = step * std::pow(10.0, d);
    if (std::abs(scaled - std::round(scaled)) <= 1e-9 * scaled) return d;
  }
  return std::max(0, 5 - static_cast<int>(std::floor(std::log10(step))));
}

}  // namespace

Violation ImuLayout::validate() const {
  auto ok = [](double v) { return std::isfinite(v) && v >= 0; };
  for (const auto* kind : {&gyro, &accel})
    for (const auto& a : *kind)
      if (!ok(a.n) || !ok(a.b) || !ok(a.k)) return tr("the IMU layout's noise terms must be finite and >= 0");
  if (!(std::isfinite(gyro_lsb_dps) && gyro_lsb_dps > 0) || !(std::isfinite(accel_lsb_mg) && accel_lsb_mg > 0))
    return tr("the IMU layout's output steps must be finite and > 0");
  return std::nullopt;
}

ImuLayout adis16405_like_layout() {
  ImuLayout l;
  l.gyro = {AxisNoise{2.40, 31.0, 150.0}, AxisNoise{2.52, 35.0, 130.0}, AxisNoise{2.31, 24.0, 200.0}};
  l.accel = {AxisNoise{0.26, 350.0, 100.0}, AxisNoise{0.21, 260.0, 85.0}, AxisNoise{0.27, 270.0, 55.0}};
  l.gyro_bias_dps = {0.40, -0.42, -0.29};
  l.accel_bias_g = {-0.007, 0.0, -1.016};
  return l;
}

std::array<std::string, 6> imu_columns(const ImuLayout& l) {
  const char* accel_suffix = l.accel_unit == AccelColumnUnit::G ? "g" : "mps2";
  std::array<std::string, 6> c;
  for (std::size_t i = 0; i < 3; ++i) {
    c[i] = fmt::format("gyro_{}_dps", kAxes[i]);
    c[i + 3] = fmt::format("acc_{}_{}", kAxes[i], accel_suffix);
  }
  return c;
}

NoiseModel imu_axis_model(const ImuLayout& l, std::size_t axis) {
  NoiseModel m;
  m.readout = ReadoutMode::White;  // a dithered converter: the step's error is white
  if (is_gyro(axis)) {
    const AxisNoise& a = l.gyro[axis];
    m.arw_deg_per_sqrt_h = a.n;
    m.bias_instability_deg_per_h = a.b;
    m.rrw_deg_per_h_per_sqrt_h = a.k;
    m.bias_deg_per_h = l.gyro_bias_dps[axis] * 3600.0;
  } else {
    // m/s/√h, m/s/h and m/s/h/√h are the simulator's °/√h, °/h and °/h/√h (units.hpp).
    const AxisNoise& a = l.accel[axis - 3];
    m.arw_deg_per_sqrt_h = a.n;
    m.bias_instability_deg_per_h = a.b * 1e-6 * kMpsPerHPerG;
    m.rrw_deg_per_h_per_sqrt_h = a.k;
    m.bias_deg_per_h = l.accel_bias_g[axis - 3] * kMpsPerHPerG;
  }
  return m;
}

SimulationSettings imu_axis_settings(const ImuLayout& l, std::size_t axis, const SimulationSettings& settings) {
  SimulationSettings s = settings;
  // One step per sample as an angle (velocity) increment: step rate × τ0, in ″ (1/3600 m/s).
  const double step_rate = is_gyro(axis) ? l.gyro_lsb_dps * 3600.0 : l.accel_lsb_mg * 1e-3 * kMpsPerHPerG;
  s.scale_arcsec = step_rate * settings.tau0_s();
  s.seed = derive_seed(settings.seed, kAxisStream + axis);
  return s;
}

std::size_t imu_memory_bytes(const ImuLayout& l, const SimulationSettings& settings) {
  std::size_t flicker = 0;
  for (std::size_t i = 0; i < 6; ++i)
    flicker = std::max(flicker, Simulator::memory_bytes(imu_axis_model(l, i), imu_axis_settings(l, i, settings)));
  return 6 * sizeof(std::int64_t) * (settings.samples() + 1) + flicker;
}

Metadata imu_metadata(const ImuLayout& l, const SimulationSettings& s) {
  Metadata md;
  md.emplace_back("generator", fmt::format("rwcalc simulate --layout imu {}", RWCALC_VERSION));
  md.emplace_back("rate_hz", fmt::format("{}", s.rate_hz));
  md.emplace_back("seed", fmt::format("{}", s.seed));
  md.emplace_back("samples", fmt::format("{}", s.samples()));
  md.emplace_back("duration_s", fmt::format("{}", s.duration_s));
  const auto columns = imu_columns(l);
  for (std::size_t i = 0; i < 6; ++i) {
    const bool gyro = is_gyro(i);
    const AxisNoise& a = gyro ? l.gyro[i] : l.accel[i - 3];
    md.emplace_back(columns[i],
                    gyro ? fmt::format("N={} deg/sqrt(h) B={} deg/h K={} deg/h/sqrt(h) bias={} deg/s step={} deg/s",
                                       a.n, a.b, a.k, l.gyro_bias_dps[i], l.gyro_lsb_dps)
                         : fmt::format("N={} m/s/sqrt(h) B={} ug K={} m/s/h/sqrt(h) bias={} g step={} mg", a.n, a.b,
                                       a.k, l.accel_bias_g[i - 3], l.accel_lsb_mg));
  }
  return md;
}

void write_imu_record(const ImuLayout& l, const SimulationSettings& settings, const Metadata& metadata,
                      const std::string& path, bool force, std::FILE* progress) {
  require_valid(l);
  const std::size_t n = settings.samples();
  // Each axis' output steps per sample: the differences of its counts.
  std::array<std::vector<std::int64_t>, 6> steps;
  {
    Progress p(trf("simulating {}", printable(path == "-" ? "<stdout>" : path)), 6, progress);
    PhaseSeries series;
    for (std::size_t i = 0; i < 6; ++i) {
      Simulator sim(imu_axis_model(l, i), imu_axis_settings(l, i, settings));
      sim.run(imu_axis_settings(l, i, settings).seed, series);
      steps[i] = pulse_increments(series);
      p.advance();
    }
  }
  AtomicOutput out(path, force);
  std::string text;
  for (const auto& [key, value] : metadata) text += "# " + key + ": " + value + "\n";
  const auto columns = imu_columns(l);
  text += fmt::format("{}\n", fmt::join(columns, ","));
  std::array<double, 6> step{};
  std::array<int, 6> decimals{};
  for (std::size_t i = 0; i < 6; ++i) {
    step[i] = column_step(l, i);
    decimals[i] = decimals_of(step[i]);
  }
  for (std::size_t k = 0; k < n; ++k) {
    for (std::size_t i = 0; i < 6; ++i)
      fmt::format_to(std::back_inserter(text), "{}{:.{}f}", i ? "," : "", static_cast<double>(steps[i][k]) * step[i],
                     decimals[i]);
    text += '\n';
    if (text.size() >= kFlushBytes) {
      out.write(text);
      text.clear();
    }
  }
  out.write(text);
  out.commit();
}

}  // namespace rwcalc
