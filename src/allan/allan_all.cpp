// Overlapping AVAR sums for every cluster size at once (the `--tau all` grid) through FFT
// autocorrelations: O(N log² N) instead of O(N²). See allan_all.hpp.
#include "allan_all.hpp"

#include <algorithm>
#include <complex>
#include <unsupported/Eigen/FFT>

#include "rwcalc/parallel.hpp"

namespace rwcalc::detail {

namespace {

using Cplx = std::complex<double>;

std::size_t pow2_at_least(std::size_t n) {
  std::size_t p = 1;
  while (p < n) p <<= 1;
  return p;
}

/// Full autocorrelation A(L) = Σ_{k<P−L} x_k x_{k+L} for L = 0 … max_lag (one FFT of ≥ 2P points).
std::vector<double> autocorrelation(const std::vector<double>& x, std::size_t max_lag) {
  const std::size_t p = x.size();
  const std::size_t n = pow2_at_least(2 * p);
  Eigen::FFT<double> fft;
  fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
  std::vector<double> buf(n, 0.0);
  std::copy(x.begin(), x.end(), buf.begin());
  std::vector<Cplx> spec(n / 2 + 1);
  fft.fwd(spec.data(), buf.data(), static_cast<Eigen::Index>(n));
  for (Cplx& c : spec) c = std::norm(c);
  fft.inv(buf.data(), spec.data(), static_cast<Eigen::Index>(n));
  buf.resize(std::min(max_lag + 1, p));
  buf.shrink_to_fit();
  return buf;
}

/// Head products H(m) = Σ_{j<m, j+m<P} x_j x_{j+m} for m = 1 … max_m. The triangle {j < m} of the
/// (j, m) plane splits uniquely into dyadic squares j ∈ [2ts, (2t+1)s), m ∈ [(2t+1)s, (2t+2)s)
/// (s = 2^b, b the highest bit where j and m differ); each square is one correlation of a length-s
/// and a length-2s segment of x, done by FFT for s ≥ kDirect and by direct sums below.
std::vector<double> head_products(const std::vector<double>& x, std::size_t max_m) {
  constexpr std::size_t kDirect = 64;
  const std::size_t p = x.size();
  std::vector<double> h(max_m + 1, 0.0);
  auto at = [&](std::size_t i) { return i < p ? x[i] : 0.0; };
  Eigen::FFT<double> fft;
  fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
  std::vector<double> u, v, out;
  std::vector<Cplx> su, sv;
  for (std::size_t s = 1; s <= max_m; s <<= 1) {
    for (std::size_t t = 0;; ++t) {
      const std::size_t j0 = 2 * t * s, m0 = (2 * t + 1) * s;
      if (m0 > max_m || j0 + m0 >= p) break;
      const std::size_t mlen = std::min(s, max_m - m0 + 1);
      const std::size_t v0 = j0 + m0;  // x index of v[0]
      if (s < kDirect) {
        for (std::size_t d = 0; d < mlen; ++d) {
          double acc = 0;
          for (std::size_t i = 0; i < s; ++i) acc += at(j0 + i) * at(v0 + i + d);
          h[m0 + d] += acc;
        }
        continue;
      }
      // c[d] = Σ_{i<s} u_i v_{i+d}, d < s: a circular correlation of length 2s gives it without
      // wrap-around, since u vanishes beyond s and i + d < 2s.
      const std::size_t n = 2 * s;
      u.assign(n, 0.0);
      v.assign(n, 0.0);
      for (std::size_t i = 0; i < s; ++i) u[i] = at(j0 + i);
      for (std::size_t i = 0; i < 2 * s; ++i) v[i] = at(v0 + i);
      su.resize(n / 2 + 1);
      sv.resize(n / 2 + 1);
      fft.fwd(su.data(), u.data(), static_cast<Eigen::Index>(n));
      fft.fwd(sv.data(), v.data(), static_cast<Eigen::Index>(n));
      for (std::size_t i = 0; i < su.size(); ++i) sv[i] *= std::conj(su[i]);
      out.resize(n);
      fft.inv(out.data(), sv.data(), static_cast<Eigen::Index>(n));
      for (std::size_t d = 0; d < mlen; ++d) h[m0 + d] += out[d];
    }
  }
  return h;
}

}  // namespace

std::vector<double> all_oavar_sumsq_fft(std::vector<double> x, std::int64_t max_m_in) {
  const std::size_t p = x.size();
  const auto max_m = static_cast<std::size_t>(std::max<std::int64_t>(max_m_in, 0));
  std::vector<double> sums(max_m + 1, 0.0);
  if (max_m == 0 || p < 3) return sums;
  // Remove the straight line through the end points: a linear term has no second difference, and
  // the cross products then stay small, so the FFT's rounding (relative to Σx²) stays far below S(m).
  const double slope = (x[p - 1] - x[0]) / static_cast<double>(p - 1);
  const double x0 = x[0];
  for (std::size_t k = 0; k < p; ++k) x[k] = (x[k] - x0) - slope * static_cast<double>(k);

  std::vector<double> xr(x.rbegin(), x.rend());
  std::vector<double> acf, head, tail;
  parallel_for(3, [&](std::size_t pass) {  // three independent FFT passes
    if (pass == 0) head = head_products(x, max_m);
    if (pass == 1) tail = head_products(xr, max_m);
    if (pass == 2) acf = autocorrelation(x, 2 * max_m);
  });
  xr.clear();
  xr.shrink_to_fit();
  // Prefix sums of x² in long double.
  std::vector<long double> q(p + 1, 0.0L);
  for (std::size_t k = 0; k < p; ++k) q[k + 1] = q[k] + static_cast<long double>(x[k]) * x[k];
  for (std::size_t m = 1; m <= max_m; ++m) {
    if (2 * m >= p) break;
    const std::size_t t = p - 2 * m;  // terms
    // S = Σx_k² + 4Σx_{k+m}² + Σx_{k+2m}² − 4Σx_k x_{k+m} − 4Σx_{k+m}x_{k+2m} + 2Σx_k x_{k+2m}, k < T;
    // the lag-m sums are A(m) less the m products at the tail and at the head.
    const long double squares = q[t] + 4 * (q[t + m] - q[m]) + (q[p] - q[2 * m]);
    const long double cross = -8.0L * acf[m] + 4.0L * tail[m] + 4.0L * head[m] + 2.0L * acf[2 * m];
    const long double s = squares + cross;
    sums[m] = s > 0 ? static_cast<double>(s) : 0.0;
  }
  return sums;
}

}  // namespace rwcalc::detail
