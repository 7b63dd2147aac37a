// The Allan variance of a record split at its gaps (segments.hpp).
#include "rwcalc/segments.hpp"

#include <algorithm>
#include <map>

#include "rwcalc/confidence.hpp"
#include "rwcalc/error.hpp"

namespace rwcalc {

PhaseSeries phase_slice(const PhaseSeries& x, std::size_t first, std::size_t last) {
  PhaseSeries p;
  p.tau0_s = x.tau0_s;
  p.kind = x.kind;
  p.arcsec_per_count = x.arcsec_per_count;
  p.rate_offset = x.rate_offset;
  const auto from = static_cast<std::ptrdiff_t>(first), to = static_cast<std::ptrdiff_t>(last) + 1;
  if (x.exact())
    p.counts.assign(x.counts.begin() + from, x.counts.begin() + to);
  else
    p.values.assign(x.values.begin() + from, x.values.begin() + to);
  return p;
}

std::vector<PhaseSeries> segment_phases(const Recording& rec) {
  if (rec.segments.size() < 2) return {rec.phase};
  const std::size_t lead = rec.phase.points() - rec.samples;  // 1: a phase point before the first sample
  std::vector<PhaseSeries> out;
  for (const auto& s : rec.segments) out.push_back(phase_slice(rec.phase, s.first, s.first + s.samples - 1 + lead));
  return out;
}

PhaseSeries longest_segment(const Recording& rec) {
  std::vector<PhaseSeries> all = segment_phases(rec);
  return *std::max_element(all.begin(), all.end(),
                           [](const PhaseSeries& a, const PhaseSeries& b) { return a.points() < b.points(); });
}

AllanResult allan_of_record(const Recording& rec, const AllanOptions& options) {
  if (rec.segments.size() < 2) return compute_allan(rec.phase, options);
  struct Pool {
    AllanPoint p;
    double sum = 0;           // Σ n·σ² over the segments
    std::size_t longest = 0;  // points of the longest segment that has the τ (its α)
  };
  std::map<std::int64_t, Pool> pooled;
  AllanResult out;
  for (const PhaseSeries& seg : segment_phases(rec)) {
    AllanResult a;
    try {
      a = compute_allan(seg, options);
    } catch (const AnalysisError&) {
      continue;  // a segment too short for any τ adds no term
    }
    out.estimator = a.estimator, out.unit = a.unit, out.tau0_s = a.tau0_s, out.confidence = a.confidence;
    out.points_in += seg.points();
    for (const AllanPoint& p : a.points) {
      Pool& q = pooled[p.m];
      if (q.p.m == 0) q.p = p, q.p.n = 0, q.p.edf = 0;
      q.sum += static_cast<double>(p.n) * p.var;
      q.p.n += p.n;
      q.p.edf += p.edf;
      if (seg.points() > q.longest) q.longest = seg.points(), q.p.alpha = p.alpha;
    }
  }
  if (pooled.empty()) throw AnalysisError(rec.source + ": no segment is long enough for one tau");
  for (auto& [m, q] : pooled) {
    AllanPoint p = q.p;
    p.var = q.sum / static_cast<double>(p.n);
    p.dev = std::sqrt(p.var);
    const DevInterval ci = chi2_interval(p.var, p.edf, out.confidence);
    p.dev_low = ci.low, p.dev_high = ci.high;
    out.points.push_back(p);
  }
  return out;
}

}  // namespace rwcalc
