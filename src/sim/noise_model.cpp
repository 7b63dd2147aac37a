// The noise model's own facts: its checks and the Allan variance its terms have in theory.
#include "rwcalc/noise_model.hpp"
#include "rwcalc/i18n.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <mutex>
#include <numbers>
#include <unordered_map>

#include "rwcalc/error.hpp"
#include "rwcalc/units.hpp"

namespace rwcalc {

namespace {

// 1 − (3 − 4e^{−x} + e^{−2x})/(2x) without cancellation (x > 0).
double gm_avar_factor(double x) {
  if (x < 0.5) {
    double sum = 0.0, term = x;  // x^n/n! for n = 1
    double p2 = 2.0;             // 2^n
    for (int n = 2; n < 40; ++n) {
      term *= x / n;
      p2 *= 2.0;
      if (n < 3) continue;
      sum += -((n % 2) ? -1.0 : 1.0) * (p2 - 4.0) * term / (2.0 * x);
      if (std::abs(term * p2) < 1e-18 * std::abs(sum) * x) break;
    }
    return sum;
  }
  return 1.0 - (3.0 - 4.0 * std::exp(-x) + std::exp(-2.0 * x)) / (2.0 * x);
}

constexpr double kUnbounded = std::numeric_limits<double>::infinity();

Violation finite_nonneg(const char* what, double v) { return check_in(what, v, 0.0, kUnbounded, "", Ends::OpenHigh); }
Violation finite(const char* what, double v) { return check_in(what, v, -kUnbounded, kUnbounded, "", Ends::Open); }
Violation positive(const char* what, double v) { return check_in(what, v, 0.0, kUnbounded, "", Ends::Open); }

}  // namespace

std::size_t SimulationSettings::samples() const {
  const double n = std::round(duration_s * rate_hz);
  return n > 0 && std::isfinite(n) ? static_cast<std::size_t>(n) : 0;
}

double earth_rate_at(double latitude_deg) {
  return units::earth_rate_deg_per_h * std::sin(latitude_deg * std::numbers::pi / 180.0);
}

double readout_q_arcsec(ReadoutMode mode, double scale_arcsec) {
  return mode == ReadoutMode::White ? scale_arcsec / std::sqrt(6.0) : scale_arcsec / std::sqrt(12.0);
}

Violation SimulationSettings::validate() const {
  if (Violation v = first_of({positive("duration_s", duration_s), positive("rate_hz", rate_hz),
                              positive("scale_arcsec", scale_arcsec),
                              temperature_c ? finite("temperature_c", *temperature_c) : std::nullopt}))
    return v;
  if (samples() < 2)
    return trf("the record must hold at least 2 samples (duration {} s at {} Hz)", duration_s, rate_hz);
  if (samples() > (std::size_t{1} << 31)) return tr("the record is too long (more than 2^31 samples)");
  return std::nullopt;
}

Violation NoiseModel::validate() const {
  if (Violation v = first_of({finite_nonneg("arw_deg_per_sqrt_h", arw_deg_per_sqrt_h),
                              finite_nonneg("bias_instability_deg_per_h", bias_instability_deg_per_h),
                              finite_nonneg("rrw_deg_per_h_per_sqrt_h", rrw_deg_per_h_per_sqrt_h),
                              finite("ramp_deg_per_h2", ramp_deg_per_h2), finite("bias_deg_per_h", bias_deg_per_h),
                              finite("earth_rate_deg_per_h", earth_rate_deg_per_h),
                              finite_nonneg("white_angle_arcsec", white_angle_arcsec),
                              finite_nonneg("lowpass_tc_s", lowpass_tc_s),
                              finite_nonneg("output_lowpass_tc_s", output_lowpass_tc_s)}))
    return v;
  for (const auto& x : sinusoids)
    if (Violation v = first_of({positive("sinusoid frequency_hz", x.f_hz),
                                finite("sinusoid amplitude_deg_per_h", x.amp_deg_per_h),
                                finite("sinusoid phase_rad", x.phase_rad)}))
      return v;
  for (const auto& x : gauss_markov)
    if (Violation v = first_of({finite_nonneg("gauss_markov sigma_deg_per_h", x.sigma_deg_per_h),
                                positive("gauss_markov correlation_time_s", x.tc_s)}))
      return v;
  for (const auto& x : bias_steps)
    if (Violation v =
            first_of({finite_nonneg("bias_step time_s", x.t_s), finite("bias_step size_deg_per_h", x.size_deg_per_h)}))
      return v;
  for (const auto& x : warmups)
    if (Violation v = first_of(
            {finite("warmup amplitude_deg_per_h", x.amp_deg_per_h), positive("warmup time_constant_s", x.tc_s)}))
      return v;
  if (!temperature_bias) return std::nullopt;
  const auto& tb = *temperature_bias;
  return first_of({finite("temperature_bias coefficient_deg_per_h_per_c", tb.coefficient_deg_per_h_per_c),
                   finite("temperature profile start_c", tb.profile.start_c),
                   finite("temperature profile end_c", tb.profile.end_c),
                   finite("temperature profile amp_c", tb.profile.amp_c),
                   tb.profile.kind == TemperatureProfile::Kind::Cycle
                       ? positive("temperature profile period_s", tb.profile.period_s)
                       : std::nullopt});
}

void validate(const NoiseModel& model, const SimulationSettings& settings) {
  require_valid(settings);
  require_valid(model);
}

namespace {

/// ∫_0^{π/2} sin⁴(mu)/sin³(u) du by 8-point Gauss–Legendre on 8m panels (the integrand has about m
/// oscillations): 128·m sines.
double kasdin_flicker_integral(std::size_t m) {
  static constexpr double kX[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290, -0.1834346424956498,
                                   0.1834346424956498,  0.5255324099163290,  0.7966664774136267,  0.9602898564975363};
  static constexpr double kW[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066378926775, 0.3626837833783620,
                                   0.3626837833783620, 0.3137066378926775, 0.2223810344533745, 0.1012285362903763};
  const double md = static_cast<double>(m);
  const std::size_t panels = 8 * m;
  const double h = (std::numbers::pi / 2.0) / static_cast<double>(panels);
  double sum = 0.0;
  for (std::size_t p = 0; p < panels; ++p) {
    const double mid = (static_cast<double>(p) + 0.5) * h;
    for (int i = 0; i < 8; ++i) {
      const double u = mid + 0.5 * h * kX[i];
      const double s = std::sin(md * u);
      const double su = std::sin(u);
      sum += kW[i] * (s * s * s * s) / (su * su * su);
    }
  }
  return sum * 0.5 * h;
}

/// The integral depends on m alone, and the diagnosis asks for the same few m thousands of times
/// (each at up to 8 M sines): each m is integrated once per process.
double kasdin_flicker_integral_once(std::size_t m) {
  static std::mutex mutex;
  static std::unordered_map<std::size_t, double> known;
  {
    const std::lock_guard lock(mutex);
    if (const auto it = known.find(m); it != known.end()) return it->second;
  }
  const double value = kasdin_flicker_integral(m);
  const std::lock_guard lock(mutex);
  known.emplace(m, value);
  return value;
}

}  // namespace

double flicker_avar(double b, std::size_t m) {
  // AV(m) = (2B²/(π m²)) ∫_0^{π/2} sin⁴(mu)/sin³(u) du: the discrete Kasdin spectrum
  // B²τ0/(2 sin πfτ0) through the Allan transfer function of m-sample means.
  const double floor = 2.0 * b * b * std::numbers::ln2 / std::numbers::pi;
  if (m > (std::size_t{1} << 16)) return floor;
  const double md = static_cast<double>(m);
  return 2.0 * b * b / (std::numbers::pi * md * md) * kasdin_flicker_integral_once(m);
}

double theoretical_avar(const NoiseModel& model, double tau0, double q, std::size_t m) {
  const double tau = static_cast<double>(m) * tau0;
  const double n_s = units::sqrt_s_per_sqrt_h * model.arw_deg_per_sqrt_h;        // ″/√s
  const double k_s = model.rrw_deg_per_h_per_sqrt_h / units::sqrt_s_per_sqrt_h;  // ″/s/√s
  const double r_s = model.ramp_deg_per_h2 / units::seconds_per_hour;            // ″/s²
  double av = n_s * n_s / tau + k_s * k_s * tau / 3.0 + r_s * r_s * tau * tau / 2.0;
  if (model.bias_instability_deg_per_h > 0) av += flicker_avar(model.bias_instability_deg_per_h, m);
  for (const auto& s : model.sinusoids) {
    const double x = std::numbers::pi * s.f_hz * tau;
    const double v = std::sin(x) * std::sin(x) / x;
    av += s.amp_deg_per_h * s.amp_deg_per_h * v * v;
  }
  for (const auto& g : model.gauss_markov) {
    const double qc2 = 2.0 * g.sigma_deg_per_h * g.sigma_deg_per_h / g.tc_s;
    const double x = tau / g.tc_s;
    av += qc2 * g.tc_s * gm_avar_factor(x) / x;
  }
  double white_angle2 = model.white_angle_arcsec * model.white_angle_arcsec;
  if (model.readout == ReadoutMode::White) white_angle2 += q * q / 6.0;
  av += 3.0 * white_angle2 / (tau * tau);
  return av;
}

}  // namespace rwcalc
