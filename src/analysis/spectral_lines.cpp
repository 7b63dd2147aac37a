// Spectral lines of a rate record and their Allan variance (spectral_lines.hpp).
#include "spectral_lines.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "rwcalc/fft.hpp"

namespace rwcalc {

namespace {

constexpr std::size_t kMaxWindow = std::size_t{1} << 16;
constexpr std::size_t kMinWindow = 256;
constexpr std::size_t kMinWindows = 15;
/// A bin is a line's when its Welch estimate (≈ χ²_ν/ν with ν ≥ 25 from 15 windows) is this many
/// times the local level: far beyond any noise fluctuation, and beyond the change of a smooth
/// spectrum over an octave (a K-led f⁻² spectrum varies ≈ 1.6× against its local median).
constexpr double kLineRatio = 10;
/// The lowest bin searched: below it the windows' mean removal and leakage of the lowest
/// frequencies shape the estimate.
constexpr std::size_t kFirstBin = 16;
/// Bins each side of a line kept with it: the Hann window's main lobe.
constexpr std::size_t kLobeBins = 2;

/// Records that hold this many whole windows take exactly this many, without overlap, spread
/// evenly from the record's start to its end: Hann windows without overlap give ν = 2 per window
/// (half-overlapping ones about 1.9 per window, at twice the transforms), so ν = 128, far above
/// the ν ≥ 25 the threshold is set for (a noise bin reaches 10× its level with a chance below
/// 10⁻²⁰), and a day-long record no longer pays a transform for every 2^16 samples. A feature
/// near 10× may fall on either side, as it may between two records of one sensor.
constexpr std::size_t kSpreadWindows = 64;

std::size_t window_length(std::size_t n) {
  std::size_t w = kMaxWindow;
  while (w >= kMinWindow && (n < w || (n - w) / (w / 2) + 1 < kMinWindows)) w /= 2;
  return w;
}

/// One-sided Welch PSD of the rate, Hann windows of `w` samples, each less its mean, half
/// overlapping (kSpreadWindows spread over a record that holds that many whole windows).
std::vector<double> welch_rate_psd(const PhaseSeries& x, std::size_t w) {
  const std::size_t n = x.points() - 1;
  const bool spread = n / w >= kSpreadWindows;
  const std::size_t count = spread ? kSpreadWindows : (n - w) / (w / 2) + 1;
  std::vector<double> hann(w), seg(w), psd(w / 2 + 1, 0.0);
  double u = 0;
  for (std::size_t i = 0; i < w; ++i) {
    hann[i] = 0.5 - 0.5 * std::cos(2 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(w));
    u += hann[i] * hann[i];
  }
  detail::RealPowerSpectrum fft(w);
  for (std::size_t window = 0; window < count; ++window) {
    const std::size_t start = spread ? spread_run_start(window, kSpreadWindows, n, w) : window * (w / 2);
    double mean = 0;
    for (std::size_t i = 0; i < w; ++i) mean += (seg[i] = x.rate(start + i));
    mean /= static_cast<double>(w);
    for (std::size_t i = 0; i < w; ++i) seg[i] = (seg[i] - mean) * hann[i];
    fft.add(seg.data(), w, psd.data());
  }
  const double fs = 1.0 / x.tau0_s;
  for (double& s : psd) s *= 2.0 / (fs * u * static_cast<double>(count));
  return psd;
}

/// The local level at every bin: the median over [k/2, 2k], taken at eight bins per octave and
/// held between them.
std::vector<double> local_level(const std::vector<double>& psd) {
  std::vector<double> level(psd.size(), 0.0), buf;
  const std::size_t last = psd.size() - 1;
  for (double c = kFirstBin; c <= static_cast<double>(last); c *= std::pow(2.0, 1.0 / 8)) {
    const auto k = static_cast<std::size_t>(c);
    const std::size_t lo = std::max<std::size_t>(1, k / 2), hi = std::min(last, 2 * k);
    buf.assign(psd.begin() + static_cast<std::ptrdiff_t>(lo), psd.begin() + static_cast<std::ptrdiff_t>(hi) + 1);
    std::nth_element(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(buf.size() / 2), buf.end());
    const std::size_t to = std::min(last, static_cast<std::size_t>(c * std::pow(2.0, 1.0 / 8)) + 1);
    for (std::size_t i = k; i <= to; ++i) level[i] = buf[buf.size() / 2];
  }
  return level;
}

}  // namespace

std::vector<SpectralLineFound> find_spectral_lines(const PhaseSeries& x) {
  if (x.points() < 2) return {};
  const std::size_t w = window_length(x.points() - 1);
  if (w < kMinWindow) return {};
  const std::vector<double> psd = welch_rate_psd(x, w);
  const std::vector<double> level = local_level(psd);
  const double df = 1.0 / (static_cast<double>(w) * x.tau0_s);
  std::vector<SpectralLineFound> lines;
  const std::size_t last = psd.size() - 2;  // the Nyquist bin is not doubled: left out
  for (std::size_t k = kFirstBin; k <= last; ++k) {
    if (!(psd[k] > kLineRatio * level[k])) continue;
    std::size_t end = k;  // the line's bins above the threshold, gaps of up to a lobe bridged
    for (std::size_t j = k + 1; j <= std::min(last, end + kLobeBins); ++j)
      if (psd[j] > kLineRatio * level[j]) end = j;
    const std::size_t from = std::max(kFirstBin, k - std::min(k, kLobeBins));
    const std::size_t to = std::min(last, end + kLobeBins);
    SpectralLineFound line;
    for (std::size_t j = from; j <= to; ++j) {
      const double e = std::max(0.0, psd[j] - level[j]) * df;
      line.f.push_back(static_cast<double>(j) * df);
      line.excess.push_back(e);
      line.power += e;
      if (psd[j] / level[j] > line.peak_ratio) {
        line.peak_ratio = psd[j] / level[j];
        line.f_hz = static_cast<double>(j) * df;
      }
    }
    lines.push_back(std::move(line));
    k = to;
  }
  return lines;
}

double spectral_lines_avar(const std::vector<SpectralLineFound>& lines, double tau_s) {
  double v = 0;
  for (const auto& line : lines)
    for (std::size_t i = 0; i < line.f.size(); ++i) {
      const double a = std::numbers::pi * line.f[i] * tau_s, s = std::sin(a);
      v += line.excess[i] * 2.0 * s * s * s * s / (a * a);
    }
  return v;
}

}  // namespace rwcalc
