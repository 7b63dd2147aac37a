// λ_k of the flicker increments' circulant in closed form (flicker_circulant.hpp).
//
// Why not an FFT of γ: λ_1 ≈ π/H is 1.4e-7 for 6 h at 1 kHz while λ ~ 1 at high k, so it needs an
// FFT in double, an L-point double array and its plan (24 bytes a point), more than the flicker
// it filters. Each λ_k is instead the infinite sum minus the tail beyond the circulant's reach:
//   Σ_{h∈ℤ} γ(h)·cos(hθ) = 2|sin(θ/2)|                      (θ = 2πk/L; the increments' PSD)
//   λ_k = 2 sin(θ/2) − (−1)^k·[γ(H) + 2F],  F = Re Σ_{j≥1} γ(H + j)·z^j,  z = e^{iθ},
// since cos((H + j)θ) = (−1)^k cos(jθ) and the h = H term counts once in the circulant, twice in
// the infinite sum. With γ(h) = −(1/π)[1/(h − ½) − 1/(h + ½)] the tail is two Lerch sums
// Φ(z, 1, v) = Σ_{j≥0} z^j/(v + j), and Φ(v) = 1/v + zΦ(v + 1) leaves one:
//   Σ_{j≥1} γ(H' + j)·z^j = −(z/π)·[1/(H' + ½) − (1 − z)·Φ(z, 1, H' + 3/2)].
// Φ(z, 1, w) = ∫₀^∞ e^{−wt}/(1 − e^{−s}) dt with s = t − iθ, and 1/(1 − e^{−s}) = 1/s + P(s), P
// analytic for |s| < 2π: the 1/s part is g(x) + i·f(x), the auxiliary functions of the sine and
// cosine integrals at x = wθ, and the P part Σ_m P^(m)(−iθ)/w^{m+1} (Watson's lemma; its terms
// fall by at least 1/(πw), so four of them leave < 1e-13 once w ≥ 256). F's error reaches λ_k
// through (1 − z) ≈ θ ≤ π·λ_k, so Φ to 1e-13 absolute gives λ_k to about 1e-13 relative.
#include "flicker_circulant.hpp"

#include <cmath>
#include <complex>
#include <numbers>

namespace rwcalc::detail {

namespace {

using cplx = std::complex<double>;

// Below this lag the tail is summed term by term (short records only: H < kAsymptoticLag).
constexpr std::size_t kAsymptoticLag = 256;

double gamma_at(double h) { return 4.0 / (std::numbers::pi * (1.0 - 4.0 * h * h)); }

// e^{a}E1(a) at a = −ix, x ≥ π: g(x) + i·f(x) = ∫₀^∞ e^{iu}/(u + x) du.
cplx exp_e1_imaginary(double x) {
  if (x >= 32.0) {
    // Asymptotic series Σ (−1)^m m!/a^{m+1}, a^{−1} = i/x: f gets the even m, g the odd ones; the
    // smallest term at x ≥ 32 is below 1e-14.
    const double inv_x = 1.0 / x;
    double f = 0.0, g = 0.0, term = inv_x;
    for (int m = 0; m < 64 && term > 1e-17 * inv_x; ++m) {
      const double signed_term = (m / 2) % 2 == 0 ? term : -term;
      (m % 2 == 0 ? f : g) += signed_term;
      if (m + 1 > x) break;  // the terms would grow from here
      term *= (m + 1) * inv_x;
    }
    return {g, f};
  }
  // Continued fraction e^{a}E1(a) = 1/(a + 1 − 1²/(a + 3 − 2²/(a + 5 − …))), modified Lentz.
  const cplx a(0.0, -x);
  cplx b = a + 1.0, c = 1e300, d = 1.0 / b, h = d;
  for (int i = 1; i < 1000; ++i) {
    const double an = -static_cast<double>(i) * i;
    b += 2.0;
    d = 1.0 / (an * d + b);
    c = b + an / c;
    const cplx step = c * d;
    h *= step;
    if (std::abs(step - 1.0) < 1e-16) break;
  }
  return h;
}

// Φ(z, 1, w) for z = e^{iθ}, 0 < θ ≤ π, w ≥ kAsymptoticLag; s_half, c_half: sin, cos of θ/2.
cplx lerch_phi(double w, double theta, double s_half, double c_half) {
  // P^(m)(−iθ) of P(s) = 1/(1 − e^{−s}) − 1/s, from its derivatives in sinh(s/2), cosh(s/2).
  const double is = 1.0 / s_half, it = 1.0 / theta;
  const double is2 = is * is, it2 = it * it, cot = c_half * is;
  const cplx p0(0.5, 0.5 * cot - it);
  const double p1 = 0.25 * is2 - it2;
  const cplx p2(0.0, 2.0 * it2 * it - 0.25 * cot * is2);
  const double p3 = -0.125 * is2 * (1.0 + 3.0 * cot * cot) + 6.0 * it2 * it2;
  const double iw = 1.0 / w;
  return exp_e1_imaginary(w * theta) + iw * (p0 + iw * (p1 + iw * (p2 + iw * p3)));
}

}  // namespace

FlickerCirculant::FlickerCirculant(std::size_t size)
    : size_(size), half_(size / 2), direct_(half_ < kAsymptoticLag ? kAsymptoticLag - half_ : 0) {}

double FlickerCirculant::eigenvalue(std::size_t k) const {
  const double big_h = static_cast<double>(half_);
  // k = 0: the tail Σ_{h≥H} γ(h) telescopes to −1/(π(H − ½)).
  if (k == 0) return 2.0 / (std::numbers::pi * (big_h - 0.5)) + gamma_at(big_h);
  const double half_angle = std::numbers::pi * static_cast<double>(k) / static_cast<double>(size_);
  const double s_half = std::sin(half_angle), c_half = std::cos(half_angle);
  const double theta = 2.0 * half_angle;
  const cplx z(1.0 - 2.0 * s_half * s_half, 2.0 * s_half * c_half);
  const cplx one_minus_z = 2.0 * s_half * cplx(s_half, -c_half);  // no cancellation at small θ
  // Σ_{j=1}^{J} γ(H + j)·z^j one by one, then z^J times the tail from H' = H + J.
  cplx tail = 0.0, zj = 1.0;
  for (std::size_t j = 1; j <= direct_; ++j) {
    zj *= z;
    tail += gamma_at(big_h + static_cast<double>(j)) * zj;
  }
  const double h_prime = big_h + static_cast<double>(direct_);
  const cplx phi = lerch_phi(h_prime + 1.5, theta, s_half, c_half);
  tail += zj * (-z / std::numbers::pi) * (1.0 / (h_prime + 0.5) - one_minus_z * phi);
  const double sign = k % 2 == 0 ? 1.0 : -1.0;
  return 2.0 * s_half - sign * (gamma_at(big_h) + 2.0 * tail.real());
}

}  // namespace rwcalc::detail
