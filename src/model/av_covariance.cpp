// The covariance of overlapping Allan-variance estimates under the five-term model, for Gaussian
// noise (fit.hpp, av_covariance): what the fit's weights and the per-τ EDF are computed from.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "rwcalc/fit.hpp"
#include "rwcalc/parallel.hpp"
#include "rwcalc/structure_function.hpp"

namespace rwcalc {

namespace {

constexpr std::array<double, 3> kTap{1.0, -2.0, 1.0};  // weights of a second difference's taps

/// Two overlapping-AV points: cluster sizes and numbers of terms.
struct PointPair {
  std::int64_t ma, mb;
  double na, nb;
  /// The lag k·ma − l·mb at which tap k of a's second differences meets tap l of b's.
  [[nodiscard]] std::int64_t kink(int k, int l) const { return k * ma - l * mb; }
  /// Pairs (z^a_i, z^b_{i+h}) of terms at lag h.
  [[nodiscard]] double count(double h) const { return std::max(0.0, std::min(na, nb - h) - std::max(0.0, -h)); }
};

/// Structure function of the continuous terms (N, B, K; structure_function.hpp), ″², at lag u
/// samples (S(0) = 0).
struct Structure {
  double tau0;
  std::array<double, 5> c;  // only N, B, K: white angle noise is added at its exact lags
  [[nodiscard]] double operator()(double u) const { return structure_function(c, u * tau0); }
};

/// Cov(z^a_i, z^b_{i+h}) of the continuous terms: −½ Σ a_k b_l S(|o_k − h − p_l|).
double gamma_continuous(const PointPair& pp, const Structure& s, double h) {
  double g = 0;
  for (int k = 0; k < 3; ++k)
    for (int l = 0; l < 3; ++l)
      g += kTap[static_cast<std::size_t>(k)] * kTap[static_cast<std::size_t>(l)] *
           s(std::abs(static_cast<double>(pp.kink(k, l)) - h));
  return -0.5 * g;
}

/// Σ_h count(h)·γ(h)² over the integer lags: γ is smooth between its kinks, so each stretch is
/// summed in blocks (length × summand at the centre) that grow geometrically away from the kinks.
double graded_gamma_sq_sum(const PointPair& pp, const Structure& s) {
  const std::int64_t mx = std::max(pp.ma, pp.mb);
  std::array<std::int64_t, 11> knots{-(2 * pp.mb + 4 * mx), 2 * pp.ma + 4 * mx + 1};
  for (int q = 0; q < 9; ++q) knots[2 + static_cast<std::size_t>(q)] = pp.kink(q / 3, q % 3);
  std::sort(knots.begin(), knots.end());
  const std::int64_t s0 = std::max<std::int64_t>(1, std::min(pp.ma, pp.mb) / 16);
  double total = 0;
  auto block = [&](std::int64_t start, std::int64_t len) {
    const double hc = static_cast<double>(start) + 0.5 * static_cast<double>(len - 1);
    const double wc = static_cast<double>(len) * pp.count(hc);
    if (wc > 0) {
      const double g = gamma_continuous(pp, s, hc);
      total += wc * g * g;
    }
  };
  for (std::size_t q = 0; q + 1 < knots.size(); ++q) {
    const std::int64_t left = knots[q], right = knots[q + 1];
    const std::int64_t mid = left + (right - left) / 2;  // lags left … right − 1, graded to both ends
    for (std::int64_t h = left, len = 0; h < mid; h += len) {
      len = std::min(mid - h, std::max(s0, (h - left) / 4));
      block(h, len);
    }
    for (std::int64_t h = right, len = 0; h > mid; h -= len) {
      len = std::min(h - mid, std::max(s0, (right - h) / 4));
      block(h - len, len);
    }
  }
  return total;
}

/// White angle noise (Q², coefficient cq): exact additions to `total` at the few lags where sample
/// indices coincide (each distinct kink once); the graded sum already holds (about) γ_c² there, so
/// the cross and Q² terms.
void add_white_angle_terms(const PointPair& pp, const Structure& s, double cq, double& total) {
  for (int q = 0; q < 9; ++q) {
    const std::int64_t h = pp.kink(q / 3, q % 3);
    double gq = 0;
    bool seen = false;
    for (int r = 0; r < 9; ++r)
      if (pp.kink(r / 3, r % 3) == h) {
        seen = seen || r < q;
        gq += kTap[static_cast<std::size_t>(r / 3)] * kTap[static_cast<std::size_t>(r % 3)];
      }
    if (seen) continue;
    gq *= cq;
    const auto hd = static_cast<double>(h);
    const double gc = gamma_continuous(pp, s, hd);
    total += pp.count(hd) * (2.0 * gc * gq + gq * gq);
  }
}

/// Cov(σ̂²_a, σ̂²_b) of two overlapping-AV points.
double point_pair_covariance(const FitPoint& a, const FitPoint& b, const Structure& s, double cq) {
  if (a.m <= 0 || b.m <= 0 || a.terms <= 0 || b.terms <= 0) return 0.0;
  const PointPair pp{a.m, b.m, static_cast<double>(a.terms), static_cast<double>(b.terms)};
  double total = graded_gamma_sq_sum(pp, s);
  if (cq > 0) add_white_angle_terms(pp, s, cq, total);
  return 2.0 * total / (4.0 * a.tau_s * a.tau_s * b.tau_s * b.tau_s * pp.na * pp.nb);
}

}  // namespace

Eigen::MatrixXd av_covariance(std::span<const FitPoint> pts, const Eigen::Matrix<double, kTermCount, 1>& c,
                              bool diagonal_only) {
  const auto j = static_cast<Eigen::Index>(pts.size());
  Eigen::MatrixXd cov = Eigen::MatrixXd::Zero(j, j);
  if (j == 0) return cov;
  const Structure s{pts[0].tau_s / static_cast<double>(pts[0].m), {0.0, c[1], c[2], c[3], 0.0}};
  // Row a of the upper triangle and its mirror: rows write disjoint entries.
  parallel_for(static_cast<std::size_t>(j), [&](std::size_t a) {
    const std::size_t end = diagonal_only ? a + 1 : pts.size();
    for (std::size_t b = a; b < end; ++b) {
      const double v = point_pair_covariance(pts[a], pts[b], s, c[0]);
      cov(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b)) = v;
      cov(static_cast<Eigen::Index>(b), static_cast<Eigen::Index>(a)) = v;
    }
  });
  return cov;
}

}  // namespace rwcalc
