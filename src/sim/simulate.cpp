// Exact discrete-time simulation of gyro pulse records (noise-models.md §3; docs/simulation.md).
#include "rwcalc/simulate.hpp"
#include "rwcalc/i18n.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>

#include "flicker_circulant.hpp"
#include "real_fft.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/random.hpp"
#include "rwcalc/units.hpp"

namespace rwcalc {

namespace {

// Random stream numbers: one per term, so terms never share draws.
enum Stream : std::uint64_t {
  kArwStream = 1,
  kRrwStream = 2,
  kFlickerStream = 3,
  kReadoutStream = 4,
  kWhiteAngleStream = 5,
  kGaussMarkovStream0 = 16,  // + index of the process
};

// x − 2(1 − e^{−x}) + (1 − e^{−2x})/2 without cancellation (x ≥ 0).
double gm_angle_var_factor(double x) {
  if (x < 0.5) {
    // Series Σ_{n≥3} (−1)^{n+1}(2^{n−1} − 2) xⁿ/n!.
    double sum = 0.0, term = x * x / 2.0;  // x^n/n! for n = 2
    double p2 = 2.0;                       // 2^{n−1} for n = 2
    for (int n = 3; n < 40; ++n) {
      term *= x / n;
      p2 *= 2.0;
      sum += ((n % 2) ? 1.0 : -1.0) * (p2 - 2.0) * term;
      if (std::abs(term * p2) < 1e-18 * std::abs(sum)) break;
    }
    return sum;
  }
  return x - 2.0 * (-std::expm1(-x)) + 0.5 * (-std::expm1(-2.0 * x));
}

inline std::int64_t floor_to_int(double x) noexcept { return static_cast<std::int64_t>(std::floor(x)); }

// Smallest 2^a·3^b·5^c ≥ n that is even (FFTW transforms them with codelets of radices 2, 3, 5).
std::size_t good_fft_size(std::size_t n) {
  std::size_t best = std::numeric_limits<std::size_t>::max();
  for (std::size_t p5 = 1; p5 < 2 * n + 10; p5 *= 5)
    for (std::size_t p35 = p5; p35 < 2 * n + 10; p35 *= 3) {
      std::size_t s = p35;
      while (s < n) s *= 2;
      if (s % 2) s *= 2;
      best = std::min(best, s);
    }
  return best;
}

// Exact discretisation (Van Loan, closed form) of dε = −ε/Tc dt + w dt, dθ = ε dt with w white of
// two-sided PSD qc²: ε' = φε + u1, Δθ = Tc(1−φ)ε + u2, (u1, u2) Gaussian with the Cholesky
// factor below. Used for Gauss–Markov rates and for low-pass-filtered white rate.
struct GmStep {
  double phi = 0.0, gain = 0.0;  // φ, Tc(1−φ)
  double l11 = 0.0, l21 = 0.0, l22 = 0.0;
  double sigma0 = 0.0;  // stationary σ of ε
  GmStep() = default;
  GmStep(double qc2, double tc, double tau0) {
    const double x = tau0 / tc;
    const double one_m_phi = -std::expm1(-x);
    const double one_m_phi2 = -std::expm1(-2.0 * x);
    phi = 1.0 - one_m_phi;
    gain = tc * one_m_phi;
    const double v11 = qc2 * tc / 2.0 * one_m_phi2;
    const double v12 = qc2 * tc * tc * one_m_phi * one_m_phi / 2.0;
    const double v22 = qc2 * tc * tc * tc * gm_angle_var_factor(x);
    l11 = std::sqrt(v11);
    l21 = l11 > 0 ? v12 / l11 : 0.0;
    l22 = std::sqrt(std::max(0.0, v22 - l21 * l21));
    sigma0 = std::sqrt(qc2 * tc / 2.0);
  }
};

// Temperature-driven bias angle at time t, ″.
double temperature_angle(const TemperatureBias& tb, double t, double t_nominal, double record_s) {
  const auto& p = tb.profile;
  const double c = tb.coefficient_deg_per_h_per_c;
  if (p.kind == TemperatureProfile::Kind::Ramp) {
    const double slope = record_s > 0 ? (p.end_c - p.start_c) / record_s : 0.0;
    return c * ((p.start_c - t_nominal) * t + slope * t * t / 2.0);
  }
  const double w = 2.0 * std::numbers::pi / p.period_s;
  return c * p.amp_c * (1.0 - std::cos(w * t)) / w;
}

// First-order low-pass in the output chain (NoiseModel::output_lowpass_tc_s) over counts C_1, C_2, …:
// θ_k = θ_{k−1} + y_k·τ0, y_k = φy_{k−1} + (1 − φ)r_k, r_k = (C_k − C_{k−1})·q/τ0, φ = e^{−τ0/Tf},
// starting in steady state at the record's mean rate y_0 = C_n·q/(n·τ0).
class OutputChainFilter {
 public:
  OutputChainFilter(double tf_s, double tau0_s, double q, std::int64_t last_count, std::size_t n)
      : phi_(std::exp(-tau0_s / tf_s)),
        tau0_(tau0_s),
        q_(q),
        y_(static_cast<double>(last_count) * q / (static_cast<double>(n) * tau0_s)) {}

  // The angles θ of the next `len` counts (they follow the previous call's).
  void apply(const std::int64_t* counts, std::size_t len, double* angles) {
    for (std::size_t j = 0; j < len; ++j) {
      const auto d =
          static_cast<std::int64_t>(static_cast<std::uint64_t>(counts[j]) - static_cast<std::uint64_t>(prev_));
      const double r = static_cast<double>(d) * q_ / tau0_;
      y_ = phi_ * y_ + (1.0 - phi_) * r;
      theta_ += y_ * tau0_;
      angles[j] = theta_;
      prev_ = counts[j];
    }
  }

 private:
  double phi_, tau0_, q_, y_;
  double theta_ = 0.0;
  std::int64_t prev_ = 0;
};

}  // namespace

std::size_t flicker_decimation(double rate_hz) {
  if (!(rate_hz >= 20.0) || !std::isfinite(rate_hz)) return 1;
  return static_cast<std::size_t>(std::floor(rate_hz / 10.0));
}

double fast_flicker_avar(double b, std::size_t m, std::size_t decimation) {
  if (m == 0) return 0.0;
  const std::size_t d = std::max<std::size_t>(decimation, 1);
  if (m > 256 * d) return flicker_avar(b, m);
  // Structure function of the decimated Kasdin rate, D_x(h) = (4B²/π)·Σ_{j=1}^{h} 1/(2j−1)
  // (the discrete PSD B²τd/(2 sin πfτd) integrated against 4 sin²(πfhτd); the j-th step is
  // ∫_0^{π/2} sin((2j−1)u) du).
  const std::size_t blocks = 2 * m / d + 3;
  std::vector<double> sf(blocks + 1, 0.0);
  for (std::size_t h = 1; h <= blocks; ++h) sf[h] = sf[h - 1] + 1.0 / (2.0 * static_cast<double>(h) - 1.0);
  std::vector<double> c(blocks);
  double total = 0.0;
  for (std::size_t phase = 0; phase < d; ++phase) {
    // Weights of the held blocks in (second window − first window), in samples.
    std::fill(c.begin(), c.end(), 0.0);
    for (std::size_t k = 0; k < 2 * m; ++k) c[(phase + k) / d] += k < m ? -1.0 : 1.0;
    // E[(Σ c_j x_j)²] = −½ Σ_i Σ_j c_i c_j D_x(i − j) since Σ c_j = 0.
    double sum = 0.0;
    for (std::size_t i = 0; i < blocks; ++i) {
      if (c[i] == 0.0) continue;
      for (std::size_t j = i + 1; j < blocks; ++j) sum += c[i] * c[j] * sf[j - i];
    }
    total += -sum;  // −½·2·Σ_{i<j}
  }
  const double md = static_cast<double>(m);
  return (4.0 * b * b / std::numbers::pi) * total / static_cast<double>(d) / (2.0 * md * md);
}

// A simulator that draws many short records (the direct-N bootstrap: 64 of a few thousand bins)
// keeps its bins' standard deviations rather than compute each eigenvalue (about 40 ns) again for
// every record; a long record's flicker, drawn once, computes them as it goes (a table would be as
// large as the transform's buffer). 2^20 bins: 8 MiB.
constexpr std::size_t kTabledBins = std::size_t{1} << 20;

struct Simulator::Impl {
  NoiseModel model;
  SimulationSettings settings;
  SimulationPath path = SimulationPath::Exact;
  std::size_t n = 0;             // samples
  std::size_t flicker_n = 0;     // samples of the flicker rate (n, or ceil(n/D) when decimated)
  std::size_t flicker_hold = 1;  // samples each flicker rate value is held for (D)
  double tau0 = 0.0;
  double q = 0.0;
  // Flicker: one buffer for the drawn spectrum, its transform (the increments) and the rates of unit
  // B (floats; flicker_rates() below).
  std::size_t fft_size = 0;
  std::unique_ptr<detail::RealInverseFft> flicker_fft;
  std::vector<double> bin_sd;  // bin_sd_of every bin, when the table is short (kTabledBins)
  double level_sd = 0.0;       // standard deviation of the first flicker rate per B
  std::vector<GmStep> gm_steps;
  // Sinusoids: cos and sin of (j + 1)·ωτ0 for j < kBlock, per line (deterministic_block).
  struct LineSteps {
    std::vector<double> c, s;
  };
  std::vector<LineSteps> line_steps;
  std::vector<std::vector<double>> warmup_steps;  // e^{−jτ0/Tc} for j < kBlock, per warm-up
  GmStep lowpass_arw;

  Impl(NoiseModel m, SimulationSettings s, SimulationPath p) : model(std::move(m)), settings(s), path(p) {
    validate(model, settings);
    n = settings.samples();
    flicker_n = n;
    if (path == SimulationPath::Ensemble) {
      flicker_hold = std::min(flicker_decimation(settings.rate_hz), n);
      flicker_n = (n + flicker_hold - 1) / flicker_hold;
    }
    tau0 = settings.tau0_s();
    q = settings.scale_arcsec;
    if (model.bias_instability_deg_per_h > 0) prepare_flicker();
    for (const auto& l : model.sinusoids) {
      LineSteps t;
      const double w = 2.0 * std::numbers::pi * l.f_hz;
      for (std::size_t j = 0; j < kBlock; ++j) {
        const double b = w * static_cast<double>(j + 1) * tau0;
        t.c.push_back(std::cos(b));
        t.s.push_back(std::sin(b));
      }
      line_steps.push_back(std::move(t));
    }
    for (const auto& w : model.warmups) {
      std::vector<double> e(kBlock);
      for (std::size_t j = 0; j < kBlock; ++j) e[j] = std::exp(-static_cast<double>(j) * tau0 / w.tc_s);
      warmup_steps.push_back(std::move(e));
    }
    for (const auto& g : model.gauss_markov)
      gm_steps.emplace_back(2.0 * g.sigma_deg_per_h * g.sigma_deg_per_h / g.tc_s, g.tc_s, tau0);
    if (model.lowpass_tc_s > 0 && model.arw_deg_per_sqrt_h > 0) {
      // Low-passed white rate u (PSD N²) is y with dy = (u − y)/τf dt: a Gauss–Markov process
      // with Tc = τf and qc = N/τf, whose exact angle is the (ε, ∫ε) pair.
      const double n_s = units::sqrt_s_per_sqrt_h * model.arw_deg_per_sqrt_h;
      lowpass_arw = GmStep(n_s * n_s / (model.lowpass_tc_s * model.lowpass_tc_s), model.lowpass_tc_s, tau0);
    }
  }

  void prepare_flicker() {
    // The rate's increments d_k = y_k − y_{k−1} of the infinite Kasdin filter are stationary with
    // PSD 2B²·sin(πfτd) and autocovariance γ(0) = 4B²/π, γ(h) = −4B²/(π(4h² − 1)). Their
    // circulant embedding of length L ≥ 2n has eigenvalues λ ≥ 0 (all γ(h ≠ 0) < 0, Craigmile
    // 2003), so filtering white noise by √λ gives increments with exactly that covariance
    // (Davies–Harte). A filter cut at the record length instead adds a spurious rate random walk
    // (AV +7 % at τ = T/4, +18 % at T/2). The eigenvalues are computed bin by bin as the spectrum
    // is drawn (detail::FlickerCirculant), so only the transform's buffer is held.
    fft_size = good_fft_size(2 * flicker_n);
    flicker_fft = std::make_unique<detail::RealInverseFft>(fft_size);
    if (fft_size / 2 + 1 <= kTabledBins) {
      const detail::FlickerCirculant circulant(fft_size);
      for (std::size_t k = 0; k <= fft_size / 2; ++k) bin_sd.push_back(bin_sd_of(circulant, k));
    }
    // Level of the first rate value: the spread a Kasdin filter of n taps gives it (Σ h_k²).
    double hk = 1.0;
    level_sd = 1.0;
    for (std::size_t k = 1; k < flicker_n; ++k) {
      hk *= (static_cast<double>(k) - 0.5) / static_cast<double>(k);
      level_sd += hk * hk;
    }
    level_sd = std::sqrt(level_sd);
  }

  // Standard deviation of bin k's real (and imaginary) part, of unit B with the transform's 1/L
  // folded in: L·λ_k/L² for the real bins 0 and L/2, half of it for each part of the others.
  [[nodiscard]] double bin_sd_of(const detail::FlickerCirculant& circulant, std::size_t k) const {
    const double parts = k == 0 || k == fft_size / 2 ? 1.0 : 2.0;
    return std::sqrt(std::max(circulant.eigenvalue(k), 0.0) / (parts * static_cast<double>(fft_size)));
  }

  // Flicker rate samples of unit B (″/s per °/h of B), by filtering white noise whose DFT is drawn directly
  // (independent complex normal bins) into the rate's increments, summed. On the Ensemble path the Kasdin sequence is
  // at τd = D·τ0 (Q_d = B² keeps the low-frequency PSD B²/(πf)), each value held over D samples.
  //
  // The spectrum and its transform are single precision: the transform's rounding error is white,
  // about 1e-13 of the increments' mean power (float's 6e-8, squared, times the FFT's log L growth),
  // far below the smallest eigenvalue that shapes the flicker (λ_1 ≈ π/H: 1.5e-7 for 6 h at 1 kHz),
  // so the covariance stays exact to well within the statistics of any record. The eigenvalues
  // themselves are computed in double (FlickerCirculant), and the rates summed in double.
  void make_flicker(std::uint64_t seed) {
    Rng rng(seed, kFlickerStream);
    const detail::FlickerCirculant circulant(fft_size);
    const auto sd = [&](std::size_t k) { return bin_sd.empty() ? bin_sd_of(circulant, k) : bin_sd[k]; };
    const std::size_t half = fft_size / 2;
    flicker_fft->set_spectrum([&](std::size_t k) {
      const double s = sd(k);
      if (k == 0 || k == half) return std::complex<float>(static_cast<float>(s * rng.normal()), 0.0F);
      const double re = rng.normal(), im = rng.normal();
      return std::complex<float>(static_cast<float>(s * re), static_cast<float>(s * im));
    });
    flicker_fft->run();
    // Rates from the increments (the first one's increment is not used), summed in double.
    float* rates = flicker_fft->values();
    double rate = level_sd * rng.normal();
    rates[0] = static_cast<float>(rate);
    for (std::size_t k = 1; k < flicker_n; ++k) {
      rate += rates[k];
      rates[k] = static_cast<float>(rate);
    }
  }

  // A realisation is generated in blocks of kBlock samples: each term adds its angle increments
  // (″; x[j] is that of interval b + j + 1) in a fixed order, its state carried from block to
  // block, and the read-out counts the block's pulses. Every term draws from its own stream.
  static constexpr std::size_t kBlock = 256;
  struct Pass {
    Rng arw, rrw, readout, white;
    std::vector<Rng> gm;
    std::vector<double> gm_eps;
    double rrw_omega = 0.0;
    double lp_y = 0.0, lp_arw_eps = 0.0;
    Rng lp_arw;
    double phase0 = 0.0, wa = 0.0, inv_q = 0.0;
    std::int64_t whole = 0;
    double frac = 0.0;
    bool dither = false;
    explicit Pass(std::uint64_t seed)
        : arw(seed, kArwStream),
          rrw(seed, kRrwStream),
          readout(seed, kReadoutStream),
          white(seed, kWhiteAngleStream),
          lp_arw(seed, kGaussMarkovStream0 + std::numeric_limits<std::uint32_t>::max()) {}
  };

  void run(std::uint64_t seed, PhaseSeries& out) {
    out.kind = PhaseKind::Gyro;
    out.tau0_s = tau0;
    out.arcsec_per_count = q;
    out.values.clear();
    out.counts.resize(n + 1);
    out.counts[0] = 0;
    generate(seed, [&](std::size_t first, const std::int64_t* c, std::size_t len) {
      std::copy_n(c, len, out.counts.data() + first);
    });
    if (!(model.output_lowpass_tc_s > 0)) return;
    OutputChainFilter filter(model.output_lowpass_tc_s, tau0, q, out.counts[n], n);
    out.values.resize(n + 1);
    out.values[0] = 0.0;
    filter.apply(out.counts.data() + 1, n, out.values.data() + 1);
    out.counts.clear();
  }

  void stream(std::uint64_t seed, const std::function<void(const RecordBlock&)>& sink) {
    if (!(model.output_lowpass_tc_s > 0)) {
      generate(seed, [&](std::size_t first, const std::int64_t* c, std::size_t len) {
        sink(RecordBlock{first, {c, len}, {}});
      });
      return;
    }
    // The filter starts at the mean rate: a first pass finds C_n, the second filters.
    std::int64_t last = 0;
    generate(seed, [&](std::size_t, const std::int64_t* c, std::size_t len) { last = c[len - 1]; });
    OutputChainFilter filter(model.output_lowpass_tc_s, tau0, q, last, n);
    double angles[kBlock];
    generate(seed, [&](std::size_t first, const std::int64_t* c, std::size_t len) {
      filter.apply(c, len, angles);
      sink(RecordBlock{first, {}, {angles, len}});
    });
  }

  // Generate one realisation and hand its counts C_k to `sink(first, counts, len)` block by block.
  template <class Sink>
  void generate(std::uint64_t seed, Sink&& sink) {
    if (model.bias_instability_deg_per_h > 0) make_flicker(seed);
    Pass st(seed);
    for (std::size_t i = 0; i < gm_steps.size(); ++i) {
      st.gm.emplace_back(seed, kGaussMarkovStream0 + i);
      st.gm_eps.push_back(st.gm.back().normal() * gm_steps[i].sigma0);  // stationary start
    }
    if (model.lowpass_tc_s > 0 && model.arw_deg_per_sqrt_h > 0) st.lp_arw_eps = lowpass_arw.sigma0 * st.lp_arw.normal();
    start_quantize(st);
    double x[kBlock];
    std::int64_t counts[kBlock];
    for (std::size_t b = 0; b < n; b += kBlock) {
      const std::size_t len = std::min(kBlock, n - b);
      deterministic_block(b, len, x);
      if (model.rrw_deg_per_h_per_sqrt_h > 0) rrw_block(st, len, x);
      if (model.bias_instability_deg_per_h > 0) flicker_block(b, len, x);
      for (std::size_t i = 0; i < gm_steps.size(); ++i)
        if (model.gauss_markov[i].sigma_deg_per_h > 0) gm_block(st.gm[i], st.gm_eps[i], gm_steps[i], len, x);
      if (model.lowpass_tc_s > 0) lowpass_block(st, b == 0, len, x);
      if (model.arw_deg_per_sqrt_h > 0) {
        if (model.lowpass_tc_s > 0) {
          gm_block(st.lp_arw, st.lp_arw_eps, lowpass_arw, len, x);
        } else {
          const double s = units::sqrt_s_per_sqrt_h * model.arw_deg_per_sqrt_h * std::sqrt(tau0);
          double z[kBlock];
          st.arw.fill_normal(z, len, s);
          for (std::size_t j = 0; j < len; ++j) x[j] += z[j];
        }
      }
      quantize_block(st, b, len, x, counts);
      sink(b + 1, counts, len);
    }
  }

  // Flicker values held over flicker_hold samples each: the one at b for the rest of its hold,
  // then whole holds.
  void flicker_block(std::size_t b, std::size_t len, double* x) const {
    const float* rates = flicker_fft->values();
    const double unit_step = model.bias_instability_deg_per_h * tau0;
    std::size_t v = b / flicker_hold, left = flicker_hold - b % flicker_hold;
    for (std::size_t j = 0; j < len; ++v, left = flicker_hold) {
      const double step = unit_step * rates[v];
      for (const std::size_t end = std::min(len, j + left); j < end; ++j) x[j] += step;
    }
  }

  // The rate terms known in closed form, each as the difference of its angle at the interval's
  // ends where it has one.
  void deterministic_block(std::size_t b, std::size_t len, double* x) const {
    const double omega = model.bias_deg_per_h + model.earth_rate_deg_per_h;  // ″/s
    const double r_s = model.ramp_deg_per_h2 / units::seconds_per_hour;      // ″/s²
    const double ramp_unit = 0.5 * r_s * tau0 * tau0;
    const double base = omega * tau0;
    for (std::size_t j = 0; j < len; ++j) x[j] = base + ramp_unit * (2.0 * static_cast<double>(b + j) + 1.0);
    // A sinusoid's angle a·sin(ωt + φ) from its phase α at the block's start:
    // sin(α + β_j) = sin α cos β_j + cos α sin β_j, β_j = (j + 1)ωτ0 from the tables.
    for (std::size_t i = 0; i < model.sinusoids.size(); ++i) {
      const auto& l = model.sinusoids[i];
      const double a = l.amp_deg_per_h / (2.0 * std::numbers::pi * l.f_hz);
      const double alpha = 2.0 * std::numbers::pi * l.f_hz * (static_cast<double>(b) * tau0) + l.phase_rad;
      const double sa = a * std::sin(alpha), ca = a * std::cos(alpha);
      const double* tc = line_steps[i].c.data();
      const double* ts = line_steps[i].s.data();
      double prev = sa;
      for (std::size_t j = 0; j < len; ++j) {
        const double cur = sa * tc[j] + ca * ts[j];
        x[j] += cur - prev;
        prev = cur;
      }
    }
    for (const auto& st : model.bias_steps) {
      const auto first = static_cast<std::size_t>(std::max(0.0, std::floor(st.t_s / tau0)));
      for (std::size_t j = first > b ? first - b : 0; j < len; ++j) {
        const double t1 = static_cast<double>(b + j) * tau0, t2 = t1 + tau0;
        x[j] += st.size_deg_per_h * (t2 - std::max(t1, st.t_s));
      }
    }
    // A warm-up's rate A·e^{−t/Tc} over interval k: A·Tc·e^{−kτ0/Tc}(1 − e^{−τ0/Tc}), e^{−kτ0/Tc} as
    // the block start's value times e^{−jτ0/Tc} from the table.
    for (std::size_t i = 0; i < model.warmups.size(); ++i) {
      const auto& w = model.warmups[i];
      const double decay = -std::expm1(-tau0 / w.tc_s);
      const double start = w.amp_deg_per_h * w.tc_s * std::exp(-static_cast<double>(b) * tau0 / w.tc_s) * decay;
      if (start == 0.0) continue;
      const double* e = warmup_steps[i].data();
      for (std::size_t j = 0; j < len; ++j) x[j] += start * e[j];
    }
    if (model.temperature_bias) {
      const auto& tb = *model.temperature_bias;
      const double nominal =
          settings.temperature_c.value_or(tb.profile.kind == TemperatureProfile::Kind::Ramp ? tb.profile.start_c : 0.0);
      const double record = static_cast<double>(n) * tau0;
      double prev = temperature_angle(tb, static_cast<double>(b) * tau0, nominal, record);
      for (std::size_t j = 0; j < len; ++j) {
        const double cur = temperature_angle(tb, static_cast<double>(b + j + 1) * tau0, nominal, record);
        x[j] += cur - prev;
        prev = cur;
      }
    }
  }

  void rrw_block(Pass& st, std::size_t len, double* x) const {
    // Exact two-state step: Ω' = Ω + w1, Δθ = Ωτ0 + w2, Cov = K²[[τ0, τ0²/2], [τ0²/2, τ0³/3]].
    const double k_s = model.rrw_deg_per_h_per_sqrt_h / units::sqrt_s_per_sqrt_h;
    const double l11 = k_s * std::sqrt(tau0);
    const double l21 = k_s * tau0 * std::sqrt(tau0) / 2.0;
    const double l22 = k_s * tau0 * std::sqrt(tau0) / std::sqrt(12.0);
    double omega = st.rrw_omega;
    for (std::size_t j = 0; j < len; ++j) {
      const double z1 = st.rrw.normal(), z2 = st.rrw.normal();
      x[j] += omega * tau0 + l21 * z1 + l22 * z2;
      omega += l11 * z1;
    }
    st.rrw_omega = omega;
  }

  static void gm_block(Rng& rng, double& state, const GmStep& st, std::size_t len, double* x) {
    double eps = state;
    for (std::size_t j = 0; j < len; ++j) {
      const double z1 = rng.normal(), z2 = rng.normal();
      x[j] += st.gain * eps + st.l21 * z1 + st.l22 * z2;
      eps = st.phi * eps + st.l11 * z1;
    }
    state = eps;
  }

  // First-order low-pass of the sensed rate, exact for a rate constant over each sample:
  // y_k = φy_{k−1} + (1−φ)r_k and ∫y = r_kτ0 − τf(y_k − y_{k−1}). Starts in steady state.
  void lowpass_block(Pass& st, bool first, std::size_t len, double* x) const {
    const double tf = model.lowpass_tc_s;
    const double phi = std::exp(-tau0 / tf);
    double y = first ? x[0] / tau0 : st.lp_y;
    for (std::size_t j = 0; j < len; ++j) {
      const double r = x[j] / tau0;
      const double y_new = phi * y + (1.0 - phi) * r;
      x[j] = r * tau0 - tf * (y_new - y);
      y = y_new;
    }
    st.lp_y = y;
  }

  // The angle is carried as whole pulses plus a fraction in [0, 1): no loss as the count grows.
  void start_quantize(Pass& st) const {
    st.dither = model.readout == ReadoutMode::White;
    st.wa = model.white_angle_arcsec / q;
    st.inv_q = 1.0 / q;
    st.phase0 = st.readout.uniform();
    // The first count: angle 0, its own read-out draw (and white angle noise).
    const double e0 = st.wa > 0 ? st.wa * st.white.normal() : 0.0;
    const double a0 = (st.dither ? st.readout.uniform() : st.phase0) + e0;
    if (!countable(a0)) throw_uncountable(0, a0, tau0, q);
    const std::int64_t c0 = floor_to_int(a0);
    st.whole = -c0;
    st.frac = 0.0;
  }

  // Tested before the conversion to an integer (out of range it would wrap); NaN fails too.
  static bool countable(double pulses) noexcept { return std::abs(pulses) < kMaxSimulatedPulses; }

  [[noreturn]] static void throw_uncountable(std::size_t k, double pulses, double tau0, double q) {
    const std::string what = std::isfinite(pulses) ? fmt::format("is {:.6g} pulses", pulses) : "is not finite";
    throw UsageError(
        trf("the simulated angle at sample {} (t = {:.6g} s) {}, beyond the +-{:.6g} pulses a record can count, so the "
            "record cannot be written; the model's terms (deg/h, arcsec) are too large for the pulse weight q = {:.6g} "
            "arcsec",
            k, static_cast<double>(k) * tau0, what, kMaxSimulatedPulses, q));
  }

  void quantize_block(Pass& st, std::size_t b, std::size_t len, double* x, std::int64_t* c) const {
    double acc = st.frac;
    for (std::size_t j = 0; j < len; ++j) {
      acc += x[j] * st.inv_q;
      x[j] = acc;
    }
    // Read-out offsets (dither or the fixed phase) plus white angle noise, in pulses.
    double extra[kBlock];
    if (st.dither) {
      for (std::size_t j = 0; j < len; ++j) extra[j] = st.readout.uniform();
    } else {
      std::fill_n(extra, len, st.phase0);
    }
    if (st.wa > 0)
      for (std::size_t j = 0; j < len; ++j) extra[j] += st.wa * st.white.normal();
    const double whole = static_cast<double>(st.whole);
    for (std::size_t j = 0; j < len; ++j)
      if (!countable(x[j]) || !countable(x[j] + extra[j]) || !countable(whole + x[j] + extra[j]))
        throw_uncountable(b + j + 1, whole + x[j] + extra[j], tau0, q);
    for (std::size_t j = 0; j < len; ++j) c[j] = st.whole + floor_to_int(x[j] + extra[j]);
    const std::int64_t fl = floor_to_int(acc);
    st.whole += fl;
    st.frac = acc - static_cast<double>(fl);
  }
};

Simulator::Simulator(NoiseModel model, SimulationSettings settings, SimulationPath path)
    : impl_(std::make_unique<Impl>(std::move(model), settings, path)) {}
Simulator::~Simulator() = default;
Simulator::Simulator(Simulator&&) noexcept = default;
Simulator& Simulator::operator=(Simulator&&) noexcept = default;

void Simulator::run(std::uint64_t seed, PhaseSeries& out) { impl_->run(seed, out); }
void Simulator::stream(std::uint64_t seed, const std::function<void(const RecordBlock&)>& sink) {
  impl_->stream(seed, sink);
}
const NoiseModel& Simulator::model() const noexcept { return impl_->model; }

std::size_t Simulator::memory_bytes(const NoiseModel& model, const SimulationSettings& settings, SimulationPath path) {
  if (!(model.bias_instability_deg_per_h > 0)) return 0;
  std::size_t n = settings.samples();
  if (path == SimulationPath::Ensemble) {
    const std::size_t hold = std::min(flicker_decimation(settings.rate_hz), n);
    n = (n + hold - 1) / hold;
  }
  // The one buffer of the flicker's spectrum, increments and rates, FFTW's plan, and a short
  // transform's table of bin standard deviations.
  const std::size_t size = good_fft_size(2 * n), bins = size / 2 + 1;
  return detail::RealInverseFft::memory_bytes(size) + (bins <= kTabledBins ? bins * sizeof(double) : 0);
}

PhaseSeries simulate(const NoiseModel& model, const SimulationSettings& settings) {
  Simulator sim(model, settings);
  PhaseSeries out;
  sim.run(settings.seed, out);
  return out;
}

std::vector<std::int64_t> pulse_increments(const PhaseSeries& series) {
  std::vector<std::int64_t> c;
  if (!series.exact() || series.points() < 2) return c;
  c.resize(series.points() - 1);
  for (std::size_t k = 0; k + 1 < series.points(); ++k)
    c[k] = static_cast<std::int64_t>(static_cast<std::uint64_t>(series.count(k + 1)) -
                                     static_cast<std::uint64_t>(series.count(k)));
  return c;
}

}  // namespace rwcalc
