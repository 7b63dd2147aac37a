// The diagnosis's slow-line detection beside a reference test written here, independently of
// src/diagnose: a generalised likelihood-ratio test of a line on the 10-s block means of the same
// records, with its own covariance (the Kasdin flicker's structure function summed directly), its
// own whitening (one generalised eigen-decomposition) and the noise profiled (overall scale and the
// flicker's share). Its threshold is its own 99 % quantile on clean records, so that both tests work
// at a 1 % false-alarm rate. Records: GL-2D-like (N 0.001 °/√h, B 0.005 °/h) at 10 Hz with the
// white read-out, whose noise is exactly the model's. 200 clean records for the reference's quantile
// and 6 records per amplitude (48 under RWCALC_ACCEPTANCE=1, tests/support/population.hpp).
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <vector>

#include "population.hpp"
#include "rwcalc/diagnose.hpp"
#include "rwcalc/simulate.hpp"

namespace {

using namespace rwcalc;

constexpr double kT = 7200, kRate = 10, kTb = 10, kQ = 0.92, kN = 0.001, kB = 0.005;
constexpr double kFloor = 0.6643 * kB;  ///< the flicker floor 0.6643·B, °/h
constexpr int kPer = static_cast<int>(kRate * kTb);

NoiseModel gl2d() {
  NoiseModel m;
  m.arw_deg_per_sqrt_h = kN;
  m.bias_instability_deg_per_h = kB;
  m.earth_rate_deg_per_h = 12.43;
  m.readout = ReadoutMode::White;
  return m;
}

PhaseSeries record(const NoiseModel& m, std::uint64_t seed) {
  SimulationSettings s;
  s.duration_s = kT;
  s.rate_hz = kRate;
  s.scale_arcsec = kQ;
  s.seed = seed;
  return simulate(m, s);
}

/// z_i = y_{i+2} − 2y_{i+1} + y_i of the 10-s block-mean rates (″/s = °/h).
Eigen::VectorXd second_diff_of_blocks(const PhaseSeries& x) {
  const std::size_t nb = (x.points() - 1) / kPer;
  std::vector<double> y(nb);
  for (std::size_t i = 0; i < nb; ++i) y[i] = x.diff((i + 1) * kPer, i * kPer) / kTb;
  Eigen::VectorXd z(static_cast<Eigen::Index>(nb - 2));
  for (std::size_t i = 0; i + 2 < nb; ++i) z(static_cast<Eigen::Index>(i)) = y[i + 2] - 2 * y[i + 1] + y[i];
  return z;
}

/// The reference: covariances of z from first principles, the white part (white rate N and the
/// read-out's white angle error q²/6 at every sample) and the flicker at B = 1, and the whitening
/// z̃ = Uᵀ L⁻¹ z under which Cov z̃ = s·(I + ρΛ).
struct Reference {
  Eigen::MatrixXd whiten;  ///< Uᵀ L⁻¹
  Eigen::VectorXd lambda;
  std::vector<double> freqs;
  std::vector<Eigen::MatrixXd> cols;  ///< whitened [cos, sin] block-mean columns per frequency

  explicit Reference(Eigen::Index n) {
    const double n2 = std::pow(kN * 60.0, 2);  // white rate: block mean variance n2/tb
    const double qa = kQ * kQ / 6.0;           // white angle error, ″²
    // Flicker: the Kasdin rate's structure function D(h) = (4/π)Σ_{j≤h} 1/(2j−1) (B = 1) and the
    // weights of z over the samples of three blocks; Cov(z_0, z_m) = −½ Σ_l a(l) D(|l + m·d|).
    const std::size_t span = 3 * kPer, hmax = static_cast<std::size_t>(n) * kPer + span;
    std::vector<double> d(hmax + 1, 0.0);
    for (std::size_t h = 1; h <= hmax; ++h) d[h] = d[h - 1] + 4.0 / std::numbers::pi / (2.0 * double(h) - 1.0);
    std::vector<double> c(span);
    for (std::size_t k = 0; k < span; ++k) c[k] = (k < kPer || k >= 2 * kPer ? 1.0 : -2.0) / kPer;
    std::vector<double> a(2 * span - 1, 0.0);  // a[l + span − 1] = Σ_i c_i c_{i+l}
    for (std::size_t i = 0; i < span; ++i)
      for (std::size_t j = 0; j < span; ++j) a[j - i + span - 1] += c[i] * c[j];
    std::vector<double> fl(static_cast<std::size_t>(n), 0.0);
    for (std::size_t m = 0; m < fl.size(); ++m)
      for (std::size_t l = 0; l < a.size(); ++l) {
        const long shift = static_cast<long>(l) - static_cast<long>(span - 1) + static_cast<long>(m * kPer);
        fl[m] += -0.5 * a[l] * d[static_cast<std::size_t>(std::labs(shift))];
      }
    const double white[4] = {6 * n2 / kTb + 20 * qa / (kTb * kTb), -4 * n2 / kTb - 15 * qa / (kTb * kTb),
                             n2 / kTb + 6 * qa / (kTb * kTb), -qa / (kTb * kTb)};
    Eigen::MatrixXd sw = Eigen::MatrixXd::Zero(n, n), sf(n, n);
    for (Eigen::Index i = 0; i < n; ++i)
      for (Eigen::Index j = 0; j < n; ++j) {
        const auto lag = static_cast<std::size_t>(std::abs(i - j));
        if (lag < 4) sw(i, j) = white[lag];
        sf(i, j) = fl[lag];
      }
    const Eigen::MatrixXd linv = sw.llt().matrixL().solve(Eigen::MatrixXd::Identity(n, n));
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(linv * sf * linv.transpose());
    lambda = es.eigenvalues().cwiseMax(0.0);
    whiten = es.eigenvectors().transpose() * linv;
    // The slow band searched as rwcalc searches it, 2.5 to 12 cycles, 16 frequencies per cycle.
    for (double f = 2.5 / kT; f <= 12.0 / kT; f += 1.0 / (16 * kT)) {
      Eigen::MatrixXd x(n + 2, 2);
      for (Eigen::Index i = 0; i < n + 2; ++i) {
        const double w = 2 * std::numbers::pi * f, t0 = double(i) * kTb, t1 = t0 + kTb;
        x(i, 0) = (std::sin(w * t1) - std::sin(w * t0)) / (w * kTb);
        x(i, 1) = (std::cos(w * t0) - std::cos(w * t1)) / (w * kTb);
      }
      const Eigen::MatrixXd xz = x.topRows(n) - 2 * x.middleRows(1, n) + x.bottomRows(n);
      freqs.push_back(f);
      cols.push_back(whiten * xz);
    }
  }

  /// −2 ln L (constants dropped) with the scale profiled, at flicker share ρ, with columns X.
  double m2ll(const Eigen::VectorXd& zt, const Eigen::MatrixXd* x, double rho, Eigen::Vector2d* beta) const {
    const Eigen::ArrayXd w = 1.0 / (1.0 + rho * lambda.array());
    double rss = (zt.array().square() * w).sum();
    if (x) {
      const Eigen::MatrixXd xw = x->array().colwise() * w.sqrt();
      const Eigen::VectorXd zw = zt.array() * w.sqrt();
      const Eigen::Vector2d b = (xw.transpose() * xw).ldlt().solve(xw.transpose() * zw);
      rss = (zw - xw * b).squaredNorm();
      if (beta) *beta = b;
    }
    const double nn = double(zt.size());
    return nn * std::log(rss / nn) - w.log().sum();
  }

  /// The flicker share profiled: golden section over ln ρ around B² relative to the white part.
  double profiled(const Eigen::VectorXd& zt, const Eigen::MatrixXd* x, Eigen::Vector2d* beta) const {
    double lo = std::log(kB * kB) - 9, hi = std::log(kB * kB) + 5;
    const double g = 0.3819660112501051;
    auto f = [&](double l) { return m2ll(zt, x, std::exp(l), nullptr); };
    double x1 = lo + g * (hi - lo), x2 = hi - g * (hi - lo), f1 = f(x1), f2 = f(x2);
    for (int i = 0; i < 40; ++i) {
      if (f1 < f2)
        hi = x2, x2 = x1, f2 = f1, x1 = lo + g * (hi - lo), f1 = f(x1);
      else
        lo = x1, x1 = x2, f1 = f2, x2 = hi - g * (hi - lo), f2 = f(x2);
    }
    const double best = f1 < f2 ? x1 : x2;
    return m2ll(zt, x, std::exp(best), beta);
  }

  struct Result {
    double lr = 0, f = 0, amp = 0;
  };
  /// The largest LR over the band, the line's frequency and amplitude there.
  Result test(const PhaseSeries& rec) const {
    const Eigen::VectorXd zt = whiten * second_diff_of_blocks(rec);
    const double null = profiled(zt, nullptr, nullptr);
    Result r;
    for (std::size_t k = 0; k < freqs.size(); ++k) {
      Eigen::Vector2d b;
      const double lr = null - profiled(zt, &cols[k], &b);
      if (lr > r.lr) r = {lr, freqs[k], b.norm()};
    }
    return r;
  }
};

double spread(int i) { return i * 0.6180339887498949 - std::floor(i * 0.6180339887498949); }

/// The amplitude (× floor) where a detection fraction rising over `mults` crosses 90 %.
double ninety(const std::vector<double>& mults, const std::vector<double>& frac) {
  for (std::size_t i = 0; i < mults.size(); ++i)
    if (frac[i] >= 0.9)
      return i == 0 ? mults[0]
                    : mults[i - 1] + (0.9 - frac[i - 1]) / (frac[i] - frac[i - 1]) * (mults[i] - mults[i - 1]);
  return 2 * mults.back();
}

}  // namespace

// Slow lines (3–5 cycles) at 3–4.5× the flicker floor: rwcalc's 90 % amplitude for naming the line
// (frequency within 0.5/T, amplitude within 30 %) beside the reference's at the same 1 %
// false-alarm rate, and no line named a Gauss–Markov term. Measured on the acceptance's 48 records
// per amplitude: reference 3.35×, rwcalc 3.65× (ratio 1.090), and 1.15 is asserted there. One
// record in 16 moves a 90 % point by a third of a step (16 per amplitude gave 1.12 and 1.17 in two
// measurements); the default 6 records per amplitude resolve it to about a step: 1.3 is asserted.
// rwcalc is not run at 3×, where it names fewer than 90 % in every measurement so far: if it ever
// names 90 % at 3.5×, 3.5× is taken as its 90 % amplitude, an upper bound, so the assertion can
// only be stricter for it.
TEST(DiagnoseReference, SlowLinesWithinFifteenPercentOfTheReferenceAmplitude) {
  const Reference ref(static_cast<Eigen::Index>(kT / kTb) - 2);
  // The reference's threshold: its 99 % quantile over 200 clean records.
  std::vector<double> clean;
  for (std::uint64_t s = 0; s < 200; ++s) clean.push_back(ref.test(record(gl2d(), 9000 + s)).lr);
  std::sort(clean.begin(), clean.end());
  const double threshold = 0.5 * (clean[197] + clean[198]);
  const std::vector<double> mults = {3.0, 3.5, 4.0, 4.5};
  const int n = test::population("RWCALC_REFERENCE_LINES", 6, 48);
  constexpr double kRwcalcFrom = 3.5;
  std::vector<double> ref_frac, rw_frac, rw_mults;
  int gauss_markov = 0;
  for (const double mult : mults) {
    int ref_named = 0, rw_named = 0;
    for (int i = 0; i < n; ++i) {
      NoiseModel m = gl2d();
      const double f = (3.0 + 2.0 * spread(i)) / kT, amp = mult * kFloor;
      m.sinusoids.push_back({f, amp, 6.283 * spread(i + 11)});
      const PhaseSeries x = record(m, 9500 + static_cast<std::uint64_t>(i));
      const auto r = ref.test(x);
      ref_named += r.lr > threshold && std::abs(r.f - f) < 0.5 / kT && std::abs(r.amp / amp - 1) < 0.3;
      if (mult < kRwcalcFrom) continue;
      Recording rec;
      rec.source = "reference-case";
      rec.phase = x;
      rec.rate_hz = kRate;
      rec.samples = x.points() - 1;
      const DiagnoseResult d = diagnose(rec, DiagnoseOptions{});
      for (const auto& fd : d.findings) {
        gauss_markov += fd.effect == Effect::GaussMarkov;
        if (fd.effect != Effect::Sinusoid) continue;
        const double fh = fd.parameter("frequency").value, ah = fd.parameter("amplitude").value;
        rw_named += std::abs(fh - f) < 0.5 / kT && std::abs(ah / amp - 1) < 0.3;
      }
    }
    ref_frac.push_back(double(ref_named) / n);
    if (mult < kRwcalcFrom) {
      std::cout << fmt::format("{:.1f}x floor: reference {}/{}\n", mult, ref_named, n);
      continue;
    }
    rw_mults.push_back(mult);
    rw_frac.push_back(double(rw_named) / n);
    std::cout << fmt::format("{:.1f}x floor: reference {}/{}, rwcalc {}/{}\n", mult, ref_named, n, rw_named, n);
  }
  const double a_ref = ninety(mults, ref_frac), a_rw = ninety(rw_mults, rw_frac);
  std::cout << fmt::format(
      "reference threshold {:.2f} (99 % of 200 clean records); 90 % amplitude: reference {:.2f}x, rwcalc {:.2f}x "
      "(ratio {:.3f}); Gauss-Markov named in {} line records\n",
      threshold, a_ref, a_rw, a_rw / a_ref, gauss_markov);
  EXPECT_LE(a_rw, (n >= 16 ? 1.15 : 1.3) * a_ref);
  EXPECT_EQ(gauss_markov, 0);
}
