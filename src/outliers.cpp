// Outlier detection by the neighbour median, and the remove/replace helpers. See outliers.hpp.
#include "rwcalc/outliers.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>

namespace rwcalc {

namespace {

constexpr std::size_t kMinSamples = 7;
// The scale is estimated from at most this many residuals (an evenly strided subset): the MAD of
// 2e5 values is within ~0.3 % of the whole record's, and it keeps long records fast.
constexpr std::size_t kScaleSamples = 200000;
constexpr double kMadToSigma = 1.482602218505602;  // 1/Φ⁻¹(3/4)

inline void sort2(double& a, double& b) {
  const double lo = std::min(a, b);
  b = std::max(a, b);
  a = lo;
}

// Median of six values: an optimal 12-comparator sorting network (branch-free, vectorisable),
// then the mean of the middle two.
inline double median6(double a, double b, double c, double d, double e, double f) {
  sort2(a, f); sort2(b, d); sort2(c, e);
  sort2(b, c); sort2(d, e);
  sort2(a, d); sort2(c, f);
  sort2(a, b); sort2(c, d); sort2(e, f);
  sort2(b, c); sort2(d, e);
  return 0.5 * (c + d);
}

// Indices of the six samples nearest to i (i excluded), three per side where the record allows.
inline void neighbours(std::size_t i, std::size_t n, std::size_t out[6]) {
  std::size_t first = i >= 3 ? i - 3 : 0;
  if (first + 6 >= n) first = n - 7;  // n ≥ 7
  std::size_t k = 0;
  for (std::size_t j = first; k < 6; ++j)
    if (j != i) out[k++] = j;
}

inline double interior_residual(const double* y, std::size_t i) {
  return y[i] - median6(y[i - 3], y[i - 2], y[i - 1], y[i + 1], y[i + 2], y[i + 3]);
}

// Residual of sample i from the median of its neighbours.
inline double residual(const double* y, std::size_t i, std::size_t n) {
  if (i >= 3 && i + 3 < n) return interior_residual(y, i);
  std::size_t nb[6];
  neighbours(i, n, nb);
  return y[i] - median6(y[nb[0]], y[nb[1]], y[nb[2]], y[nb[3]], y[nb[4]], y[nb[5]]);
}

}  // namespace

OutlierScale outlier_scale(const std::vector<double>& rates) {
  OutlierScale s;
  const std::size_t n = rates.size();
  if (n < kMinSamples) return s;
  const double* y = rates.data();

  // Resolution: the smallest non-zero step (branch-free, vectorisable).
  double res = std::numeric_limits<double>::infinity();
  for (std::size_t i = 1; i < n; ++i) {
    const double d = std::abs(y[i] - y[i - 1]);
    res = std::min(res, d > 0 ? d : std::numeric_limits<double>::infinity());
  }
  s.resolution = std::isfinite(res) ? res : 0.0;

  const std::size_t stride = (n + kScaleSamples - 1) / kScaleSamples;
  std::vector<double> a;
  a.reserve(n / stride + 1);
  for (std::size_t i = 0; i < n; i += stride) a.push_back(std::abs(residual(y, i, n)));
  auto mid = a.begin() + static_cast<std::ptrdiff_t>(a.size() / 2);
  std::nth_element(a.begin(), mid, a.end());
  s.mad_sigma = kMadToSigma * *mid;
  s.scale = std::max(s.mad_sigma, s.resolution);
  return s;
}

std::vector<Outlier> find_outliers(const std::vector<double>& rates, double threshold) {
  return find_outliers(rates, threshold, outlier_scale(rates));
}

std::vector<Outlier> find_outliers(const std::vector<double>& rates, double threshold, const OutlierScale& s) {
  std::vector<Outlier> out;
  const std::size_t n = rates.size();
  if (n < kMinSamples) return out;
  if (!(s.scale > 0)) return out;  // a constant record has no outliers
  const double limit = threshold * s.scale;
  const double* y = rates.data();
  auto test = [&](std::size_t i, std::vector<Outlier>& to) {
    const double r = residual(y, i, n);
    if (std::abs(r) > limit) to.push_back({i, 0, y[i], r / s.scale});
  };
  // Interior in blocks: a branch-free screen the compiler vectorises, then a look at blocks that trip.
  constexpr std::size_t kBlock = 1024;
  auto screen = [&](std::size_t from, std::size_t to_end, std::vector<Outlier>& to) {
    for (std::size_t b = from; b < to_end; b += kBlock) {
      const std::size_t e = std::min(to_end, b + kBlock);
      bool hit = false;
      for (std::size_t i = b; i < e; ++i)
        hit |= std::abs(interior_residual(y, i)) > limit;
      if (hit)
        for (std::size_t i = b; i < e; ++i) test(i, to);
    }
  };
  test(0, out);
  test(1, out);
  test(2, out);
  const std::size_t end = n - 3;
  // Long records: the second half of the interior on another thread (results joined in order).
  constexpr std::size_t kParallelFrom = std::size_t{1} << 20;
  if (end - 3 >= kParallelFrom && std::thread::hardware_concurrency() > 1) {
    const std::size_t mid = 3 + ((end - 3) / 2 / kBlock) * kBlock;
    std::vector<Outlier> second;
    {
      std::jthread worker([&] { screen(mid, end, second); });
      screen(3, mid, out);
    }
    out.insert(out.end(), second.begin(), second.end());
  } else {
    screen(3, end, out);
  }
  test(n - 3, out);
  test(n - 2, out);
  test(n - 1, out);
  return out;
}

std::vector<Outlier> find_outliers(const Recording& recording, double threshold) {
  auto out = find_outliers(recording.rates(), threshold);
  for (auto& o : out) o.line = recording.line_of_rate(o.index);
  return out;
}

namespace {

std::vector<char> outlier_mask(std::size_t n, const std::vector<Outlier>& outliers) {
  std::vector<char> bad(n, 0);
  for (const auto& o : outliers)
    if (o.index < n) bad[o.index] = 1;
  return bad;
}

// Median of the (up to) four nearest non-outlier neighbours of i; NaN when there are none.
double local_median(const std::vector<double>& y, const std::vector<char>& bad, std::size_t i) {
  double v[4];
  std::size_t k = 0;
  const std::size_t n = y.size();
  for (std::size_t d = 1; k < 4 && (d <= i || i + d < n); ++d) {
    if (d <= i && !bad[i - d] && k < 4) v[k++] = y[i - d];
    if (i + d < n && !bad[i + d] && k < 4) v[k++] = y[i + d];
  }
  if (k == 0) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v, v + k);
  return k % 2 ? v[k / 2] : 0.5 * (v[k / 2 - 1] + v[k / 2]);
}

}  // namespace

std::vector<double> remove_outliers(const std::vector<double>& rates, const std::vector<Outlier>& outliers) {
  const auto bad = outlier_mask(rates.size(), outliers);
  std::vector<double> out;
  out.reserve(rates.size());
  for (std::size_t i = 0; i < rates.size(); ++i)
    if (!bad[i]) out.push_back(rates[i]);
  return out;
}

std::vector<double> replace_outliers(const std::vector<double>& rates, const std::vector<Outlier>& outliers) {
  const auto bad = outlier_mask(rates.size(), outliers);
  std::vector<double> out = rates;
  for (const auto& o : outliers) {
    if (o.index >= rates.size()) continue;
    const double m = local_median(rates, bad, o.index);
    if (!std::isnan(m)) out[o.index] = m;
  }
  return out;
}

PhaseSeries apply_outliers(const PhaseSeries& phase, const std::vector<Outlier>& outliers, OutlierAction action) {
  if (action == OutlierAction::Keep || outliers.empty()) return phase;
  PhaseSeries out = phase;
  const std::size_t m = phase.points() > 0 ? phase.points() - 1 : 0;  // increments
  const auto bad = outlier_mask(m, outliers);
  if (phase.exact()) {
    // Work on the integer increments (modular differences, as PhaseSeries::diff).
    std::vector<double> inc(m);
    std::vector<std::int64_t> c(m);
    for (std::size_t i = 0; i < m; ++i) {
      c[i] = static_cast<std::int64_t>(static_cast<std::uint64_t>(phase.counts[i + 1]) -
                                       static_cast<std::uint64_t>(phase.counts[i]));
      inc[i] = static_cast<double>(c[i]);
    }
    if (action == OutlierAction::Replace)
      for (const auto& o : outliers)
        if (o.index < m) {
          const double med = local_median(inc, bad, o.index);
          if (!std::isnan(med)) c[o.index] = static_cast<std::int64_t>(std::llround(med));
        }
    out.counts.assign(1, 0);
    std::uint64_t acc = 0;
    for (std::size_t i = 0; i < m; ++i) {
      if (action == OutlierAction::Remove && bad[i]) continue;
      acc += static_cast<std::uint64_t>(c[i]);
      out.counts.push_back(static_cast<std::int64_t>(acc));
    }
    return out;
  }
  std::vector<double> inc(m);
  for (std::size_t i = 0; i < m; ++i) inc[i] = phase.values[i + 1] - phase.values[i];
  if (action == OutlierAction::Replace)
    for (const auto& o : outliers)
      if (o.index < m) {
        const double med = local_median(inc, bad, o.index);
        if (!std::isnan(med)) inc[o.index] = med;
      }
  out.values.assign(1, phase.values.empty() ? 0.0 : phase.values.front());
  long double acc = out.values.front();
  for (std::size_t i = 0; i < m; ++i) {
    if (action == OutlierAction::Remove && bad[i]) continue;
    acc += inc[i];
    out.values.push_back(static_cast<double>(acc));
  }
  return out;
}

}  // namespace rwcalc
