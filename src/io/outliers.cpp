// Outlier detection by the neighbour median, and the remove/replace helpers. See outliers.hpp.
#include "rwcalc/outliers.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <type_traits>

#include "rwcalc/parallel.hpp"

namespace rwcalc {

namespace {

constexpr std::size_t kMinSamples = 7;
// The scale is estimated from at most this many residuals (an evenly strided subset): the MAD of
// 2e5 values is within ~0.3 % of the whole record's, and it keeps long records fast.
constexpr std::size_t kScaleSamples = 200000;
constexpr double kMadToSigma = 1.482602218505602;  // 1/Φ⁻¹(3/4)
// Samples per stretch of the record that parallel_for hands out. Fixed, so that the stretches,
// and thus every result, do not depend on the number of threads.
constexpr std::size_t kChunk = std::size_t{1} << 16;

template <class T>
inline void sort2(T& a, T& b) {
  const T lo = std::min(a, b);
  b = std::max(a, b);
  a = lo;
}

// The middle pair of six values, left in c and d: a 12-comparator sorting network (branch-free, so
// the compiler can vectorise the screen).
template <class T>
inline void middle_pair6(T& a, T& b, T& c, T& d, T& e, T& f) {
  sort2(a, f), sort2(b, d), sort2(c, e);
  sort2(b, c), sort2(d, e);
  sort2(a, d), sort2(c, f);
  sort2(a, b), sort2(c, d), sort2(e, f);
  sort2(b, c), sort2(d, e);
}

// Median of six values: the mean of the middle two.
inline double median6(double a, double b, double c, double d, double e, double f) {
  middle_pair6(a, b, c, d, e, f);
  return 0.5 * (c + d);
}

// The rates of a record, read through windows: from a vector, or computed from a phase series
// by PhaseSeries::rate, as Recording::rates() computes them (no copy of the whole record), so both
// give the same doubles, whatever the phase's rate offset. Pulse counts take few values: their
// rates come from a table of the small ones (the same doubles).
struct RateSource {
  static constexpr std::int64_t kTabled = 64;  // counts per sample tabled either side of 0
  const std::vector<double>* vector = nullptr;
  const PhaseSeries* phase = nullptr;
  std::size_t n = 0;
  std::vector<double> count_rate;  // PhaseSeries::rate of an increment of c counts, |c| ≤ kTabled

  void fill(std::size_t from, std::size_t to, double* out) const {
    if (vector) {
      std::copy(vector->begin() + static_cast<std::ptrdiff_t>(from), vector->begin() + static_cast<std::ptrdiff_t>(to),
                out);
    } else if (phase->exact()) {
      const std::int64_t* c = phase->counts.data();
      for (std::size_t i = from; i < to; ++i) {
        const auto d =
            static_cast<std::int64_t>(static_cast<std::uint64_t>(c[i + 1]) - static_cast<std::uint64_t>(c[i]));
        out[i - from] =
            d >= -kTabled && d <= kTabled ? count_rate[static_cast<std::size_t>(d + kTabled)] : phase->rate(i);
      }
    } else {  // PhaseSeries::rate, its rate offset's part the same for every sample
      const double* v = phase->values.data();
      const double offset = phase->offset_phase(1.0), tau0 = phase->tau0_s;
      for (std::size_t i = from; i < to; ++i) out[i - from] = (v[i + 1] - v[i] + offset) / tau0;
    }
  }
};

RateSource source_of(const std::vector<double>& rates) { return {&rates, nullptr, rates.size(), {}}; }
RateSource source_of(const PhaseSeries& phase) {
  RateSource src{nullptr, &phase, phase.points() > 0 ? phase.points() - 1 : 0, {}};
  if (phase.exact())
    for (std::int64_t d = -RateSource::kTabled; d <= RateSource::kTabled; ++d)  // as PhaseSeries::diff and rate
      src.count_rate.push_back(static_cast<double>(d) * phase.arcsec_per_count / phase.tau0_s);
  return src;
}

// The rates of samples [lo, hi), enough to compute the residual of every sample of [from, to):
// three neighbours either side, the first or the last seven at the ends of the record (n ≥ 7).
struct Window {
  std::size_t lo = 0, hi = 0, n = 0;
  std::vector<double> y;
  Window(const RateSource& src, std::size_t from, std::size_t to) : n(src.n) {
    lo = from >= 3 ? std::min(from - 3, n - kMinSamples) : 0;
    hi = std::max(std::min(n, to + 3), kMinSamples);
    y.resize(hi - lo);
    src.fill(lo, hi, y.data());
  }
  [[nodiscard]] double at(std::size_t i) const { return y[i - lo]; }
  // Residual of sample i from the median of its six nearest neighbours, three per side where the
  // record allows.
  [[nodiscard]] double residual(std::size_t i) const {
    if (i >= 3 && i + 3 < n) return at(i) - median6(at(i - 3), at(i - 2), at(i - 1), at(i + 1), at(i + 2), at(i + 3));
    std::size_t first = i >= 3 ? i - 3 : 0;
    if (first + 6 >= n) first = n - 7;
    double v[6];
    for (std::size_t j = first, k = 0; k < 6; ++j)
      if (j != i) v[k++] = at(j);
    return at(i) - median6(v[0], v[1], v[2], v[3], v[4], v[5]);
  }
};

// The strided subset's samples (every i divisible by `stride`) in [0, to).
std::size_t strided_below(std::size_t to, std::size_t stride) { return (to + stride - 1) / stride; }

// What one stretch [from, to) of the record contributes to the scale: the smallest non-zero step
// |y_i − y_{i−1}| (returned) and the |residuals| of the strided subset, written from `out` on.
double scale_part(const RateSource& src, std::size_t from, std::size_t to, std::size_t stride, double* out) {
  const Window w(src, from, to);
  double resolution = std::numeric_limits<double>::infinity();
  for (std::size_t i = std::max<std::size_t>(from, 1); i < to; ++i) {
    const double d = std::abs(w.at(i) - w.at(i - 1));
    resolution = std::min(resolution, d > 0 ? d : std::numeric_limits<double>::infinity());
  }
  for (std::size_t i = strided_below(from, stride) * stride; i < to; i += stride) *out++ = std::abs(w.residual(i));
  return resolution;
}

std::size_t chunks_of(std::size_t n) { return (n + kChunk - 1) / kChunk; }

OutlierScale scale_of(const RateSource& src) {
  OutlierScale s;
  if (src.n < kMinSamples) return s;
  const std::size_t stride = (src.n + kScaleSamples - 1) / kScaleSamples;
  std::vector<double> part_resolution(chunks_of(src.n));
  std::vector<double> residuals(strided_below(src.n, stride));  // in record order, each chunk its own stretch
  parallel_for(part_resolution.size(), [&](std::size_t c) {
    const std::size_t from = c * kChunk;
    part_resolution[c] =
        scale_part(src, from, std::min(src.n, from + kChunk), stride, residuals.data() + strided_below(from, stride));
  });
  const double resolution = *std::min_element(part_resolution.begin(), part_resolution.end());
  // The median |residual|: the value of rank size/2, whatever the order the parts came in.
  const auto mid = residuals.begin() + static_cast<std::ptrdiff_t>(residuals.size() / 2);
  std::nth_element(residuals.begin(), mid, residuals.end());
  s.resolution = std::isfinite(resolution) ? resolution : 0.0;
  s.mad_sigma = kMadToSigma * *mid;
  s.scale = std::max(s.mad_sigma, s.resolution);
  return s;
}

/// Pulse counts: the samples of [from, to) that may lie beyond `limit`, found on the counts. A rate
/// is an increasing function of its count, so the six neighbours' middle pair is that of their counts,
/// found in 16-bit lanes; a sample whose count residual stays a quarter count inside the limit (far
/// more than the rates' rounding) cannot be an outlier. Nothing when the counts do not fit 13 bits:
/// then every sample is a candidate.
std::optional<std::vector<char>> count_candidates(const RateSource& src, std::size_t from, std::size_t to,
                                                  double limit) {
  constexpr std::int64_t kFits = std::int64_t{1} << 13;  // |2c − a − b| then fits int16
  const std::size_t lo = std::max<std::size_t>(from, 3), hi = std::min(to, src.n - 3);  // interior samples
  if (!src.phase || !src.phase->exact() || lo >= hi) return std::nullopt;
  const std::int64_t* x = src.phase->counts.data();
  std::vector<std::int16_t> c(hi - lo + 6);
  for (std::size_t j = 0; j < c.size(); ++j) {
    const std::size_t i = lo - 3 + j;
    const auto d = static_cast<std::int64_t>(static_cast<std::uint64_t>(x[i + 1]) - static_cast<std::uint64_t>(x[i]));
    if (d <= -kFits || d >= kFits) return std::nullopt;
    c[j] = static_cast<std::int16_t>(d);
  }
  const double step = src.phase->arcsec_per_count / src.phase->tau0_s;  // rate of one count
  const double edge = std::floor(std::min(2.0 * limit / step - 0.5, 30000.0));
  const auto limit2 = static_cast<std::int16_t>(std::max(-1.0, edge));  // |2c − a − b| above it: a candidate
  std::vector<char> maybe(to - from, 1);
  for (std::size_t j = 3; j + 3 < c.size(); ++j) {
    std::int16_t a = c[j - 3], b = c[j - 2], m3 = c[j - 1], m4 = c[j + 1], e = c[j + 2], f = c[j + 3];
    middle_pair6(a, b, m3, m4, e, f);
    const int u = 2 * c[j] - m3 - m4;
    maybe[lo - 3 + j - from] = static_cast<char>((u < 0 ? -u : u) > limit2);
  }
  return maybe;
}

/// Rates: the samples of [from, to) that may lie beyond `limit`. The median of six neighbours lies
/// between their least and greatest, so a sample within [greatest − limit, least + limit] has a
/// residual within ±limit (also as rounded: the floating subtraction is monotonic) and cannot be an
/// outlier; that is almost every sample, found without the median's sorting network.
std::vector<char> rate_candidates(const Window& w, std::size_t from, std::size_t to, double limit) {
  std::vector<char> maybe(to - from, 1);
  const std::size_t lo = std::max<std::size_t>(from, 3), hi = std::min(to, w.n - 3);  // interior samples
  for (std::size_t i = lo; i < hi; ++i) {
    const double a = w.at(i - 3), b = w.at(i - 2), c = w.at(i - 1), d = w.at(i + 1), e = w.at(i + 2), f = w.at(i + 3);
    const double least = std::min(std::min(std::min(a, b), std::min(c, d)), std::min(e, f));
    const double greatest = std::max(std::max(std::max(a, b), std::max(c, d)), std::max(e, f));
    const double y = w.at(i);
    maybe[i - from] = static_cast<char>(!(y - least <= limit && greatest - y <= limit));
  }
  return maybe;
}

std::vector<Outlier> outliers_of(const RateSource& src, double threshold, const OutlierScale& s) {
  if (src.n < kMinSamples || !(s.scale > 0)) return {};  // a constant record has no outliers
  const double limit = threshold * s.scale;
  std::vector<std::vector<Outlier>> parts(chunks_of(src.n));
  parallel_for(parts.size(), [&](std::size_t c) {
    const std::size_t from = c * kChunk, to = std::min(src.n, from + kChunk);
    std::optional<std::vector<char>> maybe = count_candidates(src, from, to, limit);
    if (maybe && std::find(maybe->begin(), maybe->end(), 1) == maybe->end()) return;
    const Window w(src, from, to);
    if (!maybe) maybe = rate_candidates(w, from, to, limit);
    for (std::size_t i = from; i < to; ++i) {
      if (maybe && !(*maybe)[i - from]) continue;
      const double r = w.residual(i);
      if (std::abs(r) > limit) parts[c].push_back({i, 0, w.at(i), r / s.scale});
    }
  });
  std::vector<Outlier> out;
  for (const auto& p : parts) out.insert(out.end(), p.begin(), p.end());
  return out;
}

}  // namespace

OutlierScale outlier_scale(const std::vector<double>& rates) { return scale_of(source_of(rates)); }

OutlierScale outlier_scale(const PhaseSeries& phase) { return scale_of(source_of(phase)); }

std::vector<Outlier> find_outliers(const std::vector<double>& rates, double threshold) {
  return find_outliers(rates, threshold, outlier_scale(rates));
}

std::vector<Outlier> find_outliers(const std::vector<double>& rates, double threshold, const OutlierScale& s) {
  return outliers_of(source_of(rates), threshold, s);
}

std::vector<Outlier> find_outliers(const PhaseSeries& phase, double threshold, const OutlierScale& s) {
  return outliers_of(source_of(phase), threshold, s);
}

std::vector<Outlier> find_outliers(const Recording& recording, double threshold) {
  auto out = find_outliers(recording.phase, threshold, outlier_scale(recording.phase));
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

// The increments with the outliers replaced by their local median (Replace) or left as they are.
template <class T>
void replace_increments(std::vector<T>& inc, const std::vector<char>& bad, const std::vector<Outlier>& outliers) {
  std::vector<double> as_double(inc.begin(), inc.end());
  for (const auto& o : outliers) {
    if (o.index >= inc.size()) continue;
    const double med = local_median(as_double, bad, o.index);
    if (std::isnan(med)) continue;
    if constexpr (std::is_integral_v<T>)
      inc[o.index] = static_cast<T>(std::llround(med));  // exact counts stay whole
    else
      inc[o.index] = med;
  }
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
  std::vector<double> out = rates;
  replace_increments(out, outlier_mask(rates.size(), outliers), outliers);
  return out;
}

PhaseSeries apply_outliers(const PhaseSeries& phase, const std::vector<Outlier>& outliers, OutlierAction action) {
  if (action == OutlierAction::Keep || outliers.empty()) return phase;
  PhaseSeries out;
  out.tau0_s = phase.tau0_s;
  out.kind = phase.kind;
  out.arcsec_per_count = phase.arcsec_per_count;
  out.rate_offset = phase.rate_offset;
  const std::size_t m = phase.points() > 0 ? phase.points() - 1 : 0;  // increments
  const auto bad = outlier_mask(m, outliers);
  const bool remove = action == OutlierAction::Remove;
  if (phase.exact()) {
    // The integer increments (modular differences, as PhaseSeries::diff), summed again.
    std::vector<std::int64_t> inc(m);
    for (std::size_t i = 0; i < m; ++i)
      inc[i] = static_cast<std::int64_t>(static_cast<std::uint64_t>(phase.count(i + 1)) -
                                         static_cast<std::uint64_t>(phase.count(i)));
    if (!remove) replace_increments(inc, bad, outliers);
    out.counts.assign(1, 0);
    std::uint64_t acc = 0;
    for (std::size_t i = 0; i < m; ++i) {
      if (remove && bad[i]) continue;
      acc += static_cast<std::uint64_t>(inc[i]);
      out.counts.push_back(static_cast<std::int64_t>(acc));
    }
    return out;
  }
  std::vector<double> inc(m);
  for (std::size_t i = 0; i < m; ++i) inc[i] = phase.values[i + 1] - phase.values[i];
  if (!remove) replace_increments(inc, bad, outliers);
  out.values.assign(1, phase.values.empty() ? 0.0 : phase.values.front());
  long double acc = out.values.front();
  for (std::size_t i = 0; i < m; ++i) {
    if (remove && bad[i]) continue;
    acc += inc[i];
    out.values.push_back(static_cast<double>(acc));
  }
  return out;
}

}  // namespace rwcalc
