#pragma once
// Hot loop of the AV-point covariance (av_covariance in fit.cpp): the sum over blocks of lags of
// weight·γ(h)², γ the covariance of two second differences of the continuous noise terms at lag
// h. Internal to the library.
#include <array>
#include <cstddef>

namespace rwcalc::detail {

/// One pair of cluster sizes: γ(h) = −½ Σ_q w_q S(|d_q − h|), S the generalized structure
/// function of the continuous terms at lag u samples, S(u) = c1·t − (c2/π)·t²·ln t − c3·t³/6 with
/// t = u·τ0 (S(0) = 0).
struct GammaPair {
  std::array<double, 9> d{};  ///< offsets o_k − p_l, samples
  std::array<double, 9> w{};  ///< weights a_k·b_l
  double tau0 = 0, c1 = 0, c2 = 0, c3 = 0;
};

/// Σ_i weight[i]·γ(h[i])² over n blocks (centre lag h, weight = block length × overlap count).
/// AVX-512 where the processor has it (a vector logarithm: the sum agrees with the scalar one to
/// ~1e-15 relative), scalar otherwise.
double gamma_sq_sum(const GammaPair& g, const double* h, const double* weight, std::size_t n) noexcept;

/// The same, scalar only (std::log): the reference the vector path is tested against.
double gamma_sq_sum_scalar(const GammaPair& g, const double* h, const double* weight, std::size_t n) noexcept;

}  // namespace rwcalc::detail
