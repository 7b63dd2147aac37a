// Power spectra of real sequences: kissfft for small transforms, four steps for long ones.
#include "rwcalc/fft.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <unsupported/Eigen/FFT>

namespace rwcalc::detail {

namespace {

using cd = std::complex<double>;

/// e^{−2πi e/N} for 0 ≤ e ≤ N as the product of two table values, e = hi·L + lo: a coarse table of
/// N/L + 1 values and a fine one of L, each entry computed directly (a few ulps in all).
class Twiddles {
 public:
  Twiddles() = default;
  explicit Twiddles(std::size_t n) {
    const double step = -2.0 * std::numbers::pi / static_cast<double>(n);
    lo_.resize(kL);
    for (std::size_t i = 0; i < kL; ++i) lo_[i] = std::polar(1.0, step * static_cast<double>(i));
    hi_.resize(n / kL + 1);
    for (std::size_t i = 0; i < hi_.size(); ++i) hi_[i] = std::polar(1.0, step * static_cast<double>(i * kL));
  }
  [[nodiscard]] cd operator()(std::size_t e) const noexcept { return hi_[e / kL] * lo_[e % kL]; }

 private:
  static constexpr std::size_t kL = 2048;
  std::vector<cd> lo_, hi_;
};

}  // namespace

struct RealPowerSpectrum::Impl {
  std::size_t nfft = 0;
  Eigen::FFT<double> fft;
  // Small transforms: kissfft's real transform (half spectrum).
  std::vector<double> buf;
  std::vector<cd> spec;
  // Four steps: the complex transform of M = nfft/2 points z_t = x_{2t} + i·x_{2t+1}, as an
  // M1 × M2 matrix (z[t1·M2 + t2]): transforms of the columns, twiddles, transforms of the rows.
  std::size_t m = 0, m1 = 0, m2 = 0;
  std::vector<cd> z, zn, col_in, col_out;
  Twiddles tw;  // e^{−2πi e/nfft}

  explicit Impl(std::size_t n) : nfft(n) {
    if (nfft < 4 || (nfft & (nfft - 1)) != 0)
      throw std::invalid_argument("RealPowerSpectrum: nfft must be a power of two >= 4");
    if (nfft < kFourStepFrom) {
      fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
      buf.assign(nfft, 0.0);
      return;
    }
    m = nfft / 2;
    int bits = 0;
    while ((std::size_t{1} << bits) < m) ++bits;
    m1 = std::size_t{1} << (bits / 2);
    m2 = m / m1;
    z.resize(m);
    zn.resize(m);
    col_in.resize(kCols * m1);
    col_out.resize(kCols * std::max(m1, m2));
    tw = Twiddles(nfft);
  }

  static constexpr std::size_t kCols = 8;  // columns (or rows) taken together: whole cache lines

  void add(const double* x, std::size_t n, double* P) {
    if (n > nfft) throw std::invalid_argument("RealPowerSpectrum: more samples than the transform");
    if (m == 0) {
      std::copy(x, x + n, buf.begin());
      std::fill(buf.begin() + static_cast<std::ptrdiff_t>(n), buf.end(), 0.0);
      fft.fwd(spec, buf);
      for (std::size_t k = 0; k <= nfft / 2 && k < spec.size(); ++k) P[k] += std::norm(spec[k]);
      return;
    }
    // z_t = x_{2t} + i·x_{2t+1}, zero beyond n.
    for (std::size_t t = 0; t < m; ++t) {
      const double re = 2 * t < n ? x[2 * t] : 0.0;
      const double im = 2 * t + 1 < n ? x[2 * t + 1] : 0.0;
      z[t] = cd(re, im);
    }
    // Columns: B[k1][t2] = e^{−2πi k1·t2/M} Σ_{t1} z[t1·M2 + t2] e^{−2πi t1·k1/M1}, kCols at a time.
    for (std::size_t t2 = 0; t2 < m2; t2 += kCols) {
      const std::size_t w = std::min(kCols, m2 - t2);
      for (std::size_t t1 = 0; t1 < m1; ++t1)
        for (std::size_t c = 0; c < w; ++c) col_in[c * m1 + t1] = z[t1 * m2 + t2 + c];
      for (std::size_t c = 0; c < w; ++c)
        fft.fwd(col_out.data() + c * m1, col_in.data() + c * m1, static_cast<Eigen::Index>(m1));
      for (std::size_t k1 = 0; k1 < m1; ++k1)
        for (std::size_t c = 0; c < w; ++c) z[k1 * m2 + t2 + c] = col_out[c * m1 + k1] * tw(2 * k1 * (t2 + c));
    }
    // Rows: Z[k1 + M1·k2] = Σ_{t2} B[k1][t2] e^{−2πi t2·k2/M2}, written in natural order.
    for (std::size_t k1 = 0; k1 < m1; k1 += kCols) {
      const std::size_t w = std::min(kCols, m1 - k1);
      for (std::size_t c = 0; c < w; ++c)
        fft.fwd(col_out.data() + c * m2, z.data() + (k1 + c) * m2, static_cast<Eigen::Index>(m2));
      for (std::size_t k2 = 0; k2 < m2; ++k2)
        for (std::size_t c = 0; c < w; ++c) zn[k1 + c + m1 * k2] = col_out[c * m2 + k2];
    }
    // The real transform from the complex one: with E_k = (Z_k + Z*_{M−k})/2 and
    // O_k = (Z_k − Z*_{M−k})/(2i), X_k = E_k + e^{−2πi k/nfft}·O_k, k = 0 … M (Z_M = Z_0).
    for (std::size_t k = 0; k <= m; ++k) {
      const cd a = zn[k % m], b = std::conj(zn[(m - k) % m]);
      const cd e = 0.5 * (a + b);
      const cd o = cd(0.0, -0.5) * (a - b);
      P[k] += std::norm(e + tw(k) * o);
    }
  }
};

RealPowerSpectrum::RealPowerSpectrum(std::size_t nfft) : impl_(std::make_unique<Impl>(nfft)) {}
RealPowerSpectrum::~RealPowerSpectrum() = default;

void RealPowerSpectrum::add(const double* x, std::size_t n, double* P) { impl_->add(x, n, P); }

}  // namespace rwcalc::detail
