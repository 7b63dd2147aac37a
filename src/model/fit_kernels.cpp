// Hot loop of the AV-point covariance: γ(h)² summed over blocks of lags, eight blocks per AVX-512
// vector with a vector natural logarithm, or one at a time with std::log.
#include "model/fit_kernels.hpp"

#include <cmath>
#include <numbers>

#include "allan/x86_dispatch.hpp"

namespace rwcalc::detail {

namespace {

/// The smallest t whose logarithm is taken: S(0) = 0 exactly, and t²·ln t underflows to 0 here.
constexpr double kTinyT = 1e-300;

inline double structure(const GammaPair& g, double u) noexcept {
  const double t = std::max(u * g.tau0, kTinyT);
  return t * (g.c1 - t * (g.c2 / std::numbers::pi * std::log(t) + g.c3 * t / 6.0));
}

#if RWCALC_X86_DISPATCH
RWCALC_AVX512_WARNINGS_OFF
#define RWCALC_AVX512 __attribute__((target("avx512f")))

/// ln x for x > 0 (normal numbers), eight lanes: x = m·2^e with m in [√½, √2), ln m =
/// 2·atanh(s) = 2s·Σ z^k/(2k+1), s = (m − 1)/(m + 1), z = s² ≤ 0.0295; eleven terms leave a
/// truncation below 2^−56 relative, and e·ln 2 is added in two parts.
RWCALC_AVX512 inline __attribute__((always_inline)) __m512d log_pd(__m512d x) noexcept {
  __m512d e = _mm512_getexp_pd(x);
  __m512d m = _mm512_getmant_pd(x, _MM_MANT_NORM_1_2, _MM_MANT_SIGN_zero);
  const __mmask8 big = _mm512_cmp_pd_mask(m, _mm512_set1_pd(std::numbers::sqrt2), _CMP_GT_OQ);
  m = _mm512_mask_mul_pd(m, big, m, _mm512_set1_pd(0.5));
  e = _mm512_mask_add_pd(e, big, e, _mm512_set1_pd(1.0));
  const __m512d one = _mm512_set1_pd(1.0);
  const __m512d s = _mm512_div_pd(_mm512_sub_pd(m, one), _mm512_add_pd(m, one));
  const __m512d z = _mm512_mul_pd(s, s);
  __m512d p = _mm512_set1_pd(1.0 / 21.0);
  for (int k = 9; k >= 0; --k) p = _mm512_fmadd_pd(p, z, _mm512_set1_pd(1.0 / (2.0 * k + 1.0)));
  const __m512d lm = _mm512_mul_pd(_mm512_add_pd(s, s), p);
  constexpr double kLn2Hi = 6.93147180369123816490e-01, kLn2Lo = 1.90821492927058770002e-10;
  return _mm512_fmadd_pd(e, _mm512_set1_pd(kLn2Hi), _mm512_fmadd_pd(e, _mm512_set1_pd(kLn2Lo), lm));
}

/// γ(h) at eight block centres.
RWCALC_AVX512 inline __attribute__((always_inline)) __m512d gamma_pd(const GammaPair& g, __m512d hv) noexcept {
  const __m512d tau0 = _mm512_set1_pd(g.tau0), tiny = _mm512_set1_pd(kTinyT);
  const __m512d c1 = _mm512_set1_pd(g.c1), c2 = _mm512_set1_pd(g.c2 / std::numbers::pi),
                c3 = _mm512_set1_pd(g.c3 / 6.0);
  __m512d sum = _mm512_setzero_pd();
  for (std::size_t q = 0; q < g.d.size(); ++q) {
    if (g.w[q] == 0) continue;
    const __m512d u = _mm512_abs_pd(_mm512_sub_pd(_mm512_set1_pd(g.d[q]), hv));
    const __m512d t = _mm512_max_pd(_mm512_mul_pd(u, tau0), tiny);
    const __m512d inner = _mm512_fmadd_pd(c2, log_pd(t), _mm512_mul_pd(c3, t));
    const __m512d s = _mm512_mul_pd(t, _mm512_fnmadd_pd(t, inner, c1));
    sum = _mm512_fmadd_pd(_mm512_set1_pd(g.w[q]), s, sum);
  }
  return _mm512_mul_pd(sum, _mm512_set1_pd(-0.5));
}

RWCALC_AVX512 double gamma_sq_sum_avx512(const GammaPair& g, const double* h, const double* weight,
                                         std::size_t n) noexcept {
  __m512d acc = _mm512_setzero_pd();
  std::size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    const __m512d gv = gamma_pd(g, _mm512_loadu_pd(h + i));
    acc = _mm512_fmadd_pd(_mm512_loadu_pd(weight + i), _mm512_mul_pd(gv, gv), acc);
  }
  if (i < n) {
    const auto k = static_cast<__mmask8>((1u << (n - i)) - 1u);
    const __m512d gv = gamma_pd(g, _mm512_mask_loadu_pd(_mm512_set1_pd(1.0), k, h + i));
    acc = _mm512_fmadd_pd(_mm512_maskz_loadu_pd(k, weight + i), _mm512_mul_pd(gv, gv), acc);
  }
  return _mm512_reduce_add_pd(acc);
}
#undef RWCALC_AVX512
RWCALC_AVX512_WARNINGS_ON
#endif

}  // namespace

double gamma_sq_sum_scalar(const GammaPair& g, const double* h, const double* weight, std::size_t n) noexcept {
  double total = 0;
  for (std::size_t i = 0; i < n; ++i) {
    double s = 0;
    for (std::size_t q = 0; q < g.d.size(); ++q)
      if (g.w[q] != 0) s += g.w[q] * structure(g, std::abs(g.d[q] - h[i]));
    const double gv = -0.5 * s;
    total += weight[i] * gv * gv;
  }
  return total;
}

double gamma_sq_sum(const GammaPair& g, const double* h, const double* weight, std::size_t n) noexcept {
#if RWCALC_X86_DISPATCH
  static const bool avx512 = __builtin_cpu_supports("avx512f");
  if (avx512) return gamma_sq_sum_avx512(g, h, weight, n);
#endif
  return gamma_sq_sum_scalar(g, h, weight, n);
}

}  // namespace rwcalc::detail
