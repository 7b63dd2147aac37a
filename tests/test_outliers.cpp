// Outlier detection: no false alarms on clean noise (white, drifting, quantised), every planted
// spike found, the known glitches of real IMU records found, and the remove/replace helpers.
#include <algorithm>
#include <cmath>
#include <iterator>
#include <random>
#include <set>
#include <vector>

#include <gtest/gtest.h>

#include "rwcalc/outliers.hpp"
#include "rwcalc/reader.hpp"
#include "test_support.hpp"

namespace {

using rwcalc::find_outliers;
using rwcalc::OutlierAction;

std::vector<double> gaussian(std::size_t n, double sigma, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, sigma);
  std::vector<double> y(n);
  for (auto& v : y) v = g(rng);
  return y;
}

TEST(Outliers, NoFalseAlarmOnHalfAMillionGaussianSamples) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const auto y = gaussian(500000, 0.37, seed);
    const auto out = find_outliers(y);
    EXPECT_TRUE(out.empty()) << "seed " << seed << ": " << out.size() << " false alarms, first z "
                             << (out.empty() ? 0.0 : out[0].robust_z);
    const auto s = rwcalc::outlier_scale(y);
    // Residual from the neighbour median: sd is a little over σ (the median adds its own spread).
    EXPECT_GT(s.mad_sigma, 0.37);
    EXPECT_LT(s.mad_sigma, 0.37 * 1.3);
  }
}

TEST(Outliers, NoFalseAlarmOnDriftingAndQuantisedRecords) {
  // White noise plus a random walk 10× stronger over the record and an offset: the neighbour
  // median follows the drift.
  auto y = gaussian(500000, 1.0, 4);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> step(0.0, 0.02);
  double walk = 100.0;
  for (auto& v : y) v += (walk += step(rng));
  EXPECT_TRUE(find_outliers(y).empty());

  // GL-2D-like pulse rates: mostly 0 or 1 pulse per 2.5 ms (368 °/h per pulse). The median residual
  // is 0; the resolution floor keeps single pulses from being "outliers".
  std::poisson_distribution<int> pulses(0.3);
  std::vector<double> q(500000);
  for (auto& v : q) v = 368.0 * pulses(rng);
  const auto s = rwcalc::outlier_scale(q);
  EXPECT_EQ(s.mad_sigma, 0.0);
  EXPECT_DOUBLE_EQ(s.resolution, 368.0);
  EXPECT_TRUE(find_outliers(q).empty());
  q[12345] = 368.0 * 40;  // a 40-pulse glitch stands out
  const auto out = find_outliers(q);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].index, 12345u);
}

TEST(Outliers, EveryPlantedSpikeFoundAndNothingElse) {
  const double sigma = 2.0;
  auto y = gaussian(500000, sigma, 9);
  std::mt19937_64 rng(10);
  std::set<std::size_t> planted;
  while (planted.size() < 60) {
    const std::size_t i = rng() % y.size();
    // Keep spikes isolated (no two within 3 samples) except the deliberate pair below.
    if (planted.lower_bound(i >= 3 ? i - 3 : 0) != planted.upper_bound(i + 3)) continue;
    planted.insert(i);
  }
  planted.insert(0);             // first sample
  planted.insert(y.size() - 1);  // last sample
  planted.insert(250000);        // two adjacent bad samples
  planted.insert(250001);
  std::uniform_real_distribution<double> mag(12.0, 60.0);
  for (auto i : planted) y[i] += ((rng() & 1) ? 1 : -1) * mag(rng) * sigma;

  const auto out = find_outliers(y);
  std::set<std::size_t> found;
  for (const auto& o : out) {
    found.insert(o.index);
    EXPECT_EQ(o.value, y[o.index]);
    EXPECT_GT(std::abs(o.robust_z), 8.0);
    EXPECT_EQ(o.line, 0u);
  }
  std::vector<std::size_t> missed, extra;
  std::set_difference(planted.begin(), planted.end(), found.begin(), found.end(), std::back_inserter(missed));
  std::set_difference(found.begin(), found.end(), planted.begin(), planted.end(), std::back_inserter(extra));
  EXPECT_TRUE(missed.empty()) << "missed " << missed.size() << ", first " << (missed.empty() ? 0 : missed[0]);
  EXPECT_TRUE(extra.empty()) << "extra " << extra.size() << ", first " << (extra.empty() ? 0 : extra[0]);
  EXPECT_TRUE(std::is_sorted(out.begin(), out.end(), [](auto& a, auto& b) { return a.index < b.index; }));

  // Replacing them leaves a clean record; removing them shortens it by their number.
  const auto replaced = rwcalc::replace_outliers(y, out);
  EXPECT_TRUE(find_outliers(replaced).empty());
  for (const auto& o : out) EXPECT_LT(std::abs(replaced[o.index]), 6 * sigma);
  EXPECT_EQ(rwcalc::remove_outliers(y, out).size(), y.size() - out.size());
}

// The screen skips the median of a sample inside [greatest − limit, least + limit] of its six
// neighbours; what it flags must be exactly what the median of every sample flags. Heavy tails and
// low limits put many samples near the edge.
TEST(Outliers, ScreenFlagsWhatTheMedianOfEverySampleFlags) {
  std::mt19937_64 rng(31);
  std::student_t_distribution<double> t(2.0);
  std::vector<double> y(300000);
  for (auto& v : y) v = t(rng);
  for (double limit : {0.5, 2.0, 6.0}) {
    rwcalc::OutlierScale scale;
    scale.scale = 1.0;
    const auto out = find_outliers(y, limit, scale);
    std::set<std::size_t> found;
    for (const auto& o : out) found.insert(o.index);
    std::size_t flagged = 0;
    for (std::size_t i = 3; i + 3 < y.size(); ++i) {
      std::vector<double> v{y[i - 3], y[i - 2], y[i - 1], y[i + 1], y[i + 2], y[i + 3]};
      std::sort(v.begin(), v.end());
      const bool outlier = std::abs(y[i] - 0.5 * (v[2] + v[3])) > limit;
      flagged += outlier;
      EXPECT_EQ(found.count(i) == 1, outlier) << "sample " << i << " limit " << limit;
    }
    EXPECT_GT(flagged, 100u) << "limit " << limit;  // the case is not empty
  }
}

TEST(Outliers, TooShortOrConstantRecordsHaveNone) {
  EXPECT_TRUE(find_outliers(std::vector<double>{1, 100, 1, 1}).empty());
  EXPECT_TRUE(find_outliers(std::vector<double>(1000, 3.0)).empty());
}

TEST(Outliers, ApplyToExactPulseCountsKeepsThemExact) {
  // Pulse file with one glitch: 2 pulses per sample except a 90-pulse spike at sample 50.
  std::string text;
  for (int i = 0; i < 200; ++i) text += (i == 50 ? "90\n" : (i % 3 ? "2\n" : "3\n"));
  const auto rec = rwcalc::read_recording_text(text, "glitch.txt");
  const auto out = find_outliers(rec);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].index, 50u);
  EXPECT_EQ(out[0].line, 51u);
  EXPECT_DOUBLE_EQ(out[0].value, 90 * 0.92 / 0.0025);

  const auto kept = rwcalc::apply_outliers(rec.phase, out, OutlierAction::Keep);
  EXPECT_EQ(kept.counts, rec.phase.counts);
  const auto replaced = rwcalc::apply_outliers(rec.phase, out, OutlierAction::Replace);
  ASSERT_EQ(replaced.counts.size(), rec.phase.counts.size());
  // Neighbours 48, 49, 51, 52 hold 3, 2, 3, 2 pulses: median 2.5, rounded half away from zero.
  EXPECT_EQ(replaced.counts[51] - replaced.counts[50], 3);
  EXPECT_EQ(replaced.counts.back(), rec.phase.counts.back() - 90 + 3);
  const auto removed = rwcalc::apply_outliers(rec.phase, out, OutlierAction::Remove);
  EXPECT_EQ(removed.counts.size(), rec.phase.counts.size() - 1);
  EXPECT_EQ(removed.counts.back(), rec.phase.counts.back() - 90);
  EXPECT_TRUE(find_outliers(replaced.counts.empty() ? std::vector<double>{} : [&] {
                std::vector<double> r;
                for (std::size_t i = 0; i + 1 < replaced.points(); ++i) r.push_back(replaced.rate(i));
                return r;
              }()).empty());
}

TEST(Outliers, SingleSpikeOfAdis16405RunFourGyroX) {
  const auto path = rwcalc::test::shared_data("real/imudata_adis16405/adis_16405_imu4.csv.gz");
  RWCALC_REQUIRE_SHARED(path);
  rwcalc::ReadOptions o{.mode = rwcalc::InputMode::Rate,
                        .column = "gyro_x_dps",
                        .rate_hz = 100.0,
                        .rate_unit = rwcalc::RateUnit::DegPerSecond};
  const auto rec = rwcalc::read_recording(path.string(), o);
  const auto out = find_outliers(rec);
  // The documented glitch: sample 404608 (0-based) = 8.400001 °/s, off the 0.05 °/s LSB grid.
  const auto it = std::find_if(out.begin(), out.end(), [](auto& x) { return x.index == 404608; });
  ASSERT_NE(it, out.end());
  EXPECT_NEAR(it->value / 3600.0, 8.400001, 1e-9);
  EXPECT_EQ(it->line, 404608u + 4u);  // two comment lines and a header precede the data
  EXPECT_GT(it->robust_z, 20.0);
  // Everything flagged is a rare event: a handful in a million samples. Around the glitch the
  // record is disturbed for ~10 samples; elsewhere only excursions beyond 2.5 °/s (7σ) are flagged.
  EXPECT_LT(out.size(), 30u);
  for (const auto& x : out) {
    if (x.index + 10 < 404608 || x.index > 404608 + 10) {
      EXPECT_GT(std::abs(x.value / 3600.0 - 0.4), 2.5) << x.index;
    }
  }
}

TEST(Outliers, XsensContaminatedRecordGrossErrorsAreFound) {
  const auto path = rwcalc::test::shared_data("real/imudata_xsens_mtig_contaminated/cont_imu1_gyro_x.csv.gz");
  RWCALC_REQUIRE_SHARED(path);
  rwcalc::ReadOptions o{.mode = rwcalc::InputMode::Rate, .rate_hz = 100.0, .rate_unit = rwcalc::RateUnit::RadPerSecond};
  const auto rec = rwcalc::read_recording(path.string(), o);
  const auto y = rec.rates();
  ASSERT_EQ(y.size(), 500000u);
  const auto out = find_outliers(rec);
  std::set<std::size_t> found;
  for (const auto& x : out) found.insert(x.index);
  // Independent check: the global median and MAD; a sample 40 robust σ away whose neighbours
  // (±2) are ordinary is a gross isolated error and must be reported.
  auto tmp = y;
  std::nth_element(tmp.begin(), tmp.begin() + tmp.size() / 2, tmp.end());
  const double med = tmp[tmp.size() / 2];
  for (auto& v : tmp) v = std::abs(v - med);
  std::nth_element(tmp.begin(), tmp.begin() + tmp.size() / 2, tmp.end());
  const double sd = 1.4826 * tmp[tmp.size() / 2];
  std::size_t gross = 0;
  for (std::size_t i = 2; i + 2 < y.size(); ++i) {
    auto big = [&](std::size_t k) { return std::abs(y[k] - med) > 10 * sd; };
    if (std::abs(y[i] - med) > 40 * sd && !big(i - 2) && !big(i - 1) && !big(i + 1) && !big(i + 2)) {
      ++gross;
      EXPECT_TRUE(found.count(i)) << "gross error at sample " << i << " not reported";
    }
  }
  EXPECT_GT(gross, 20u);
  // The heavy-tailed bulk (≈27 000 samples beyond 6 robust σ of the global median) is not
  // reported sample by sample: only departures from the neighbours beyond 8 robust σ are
  // (about 800, 0.16 % of the record).
  EXPECT_LT(out.size(), 2500u);
  EXPECT_GT(out.size(), gross);
  for (const auto& x : out) EXPECT_EQ(x.line, x.index + 4);
}

}  // namespace

namespace {

// A long record (screened in stretches of 2^16 samples, several at once): every planted spike is
// found once, in index order, including those beside a stretch's ends and at the record's ends.
TEST(Outliers, LongRecordFindsEverySpikeOnceInOrder) {
  const std::size_t n = (std::size_t{3} << 20) + 17;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<double> y(n);
  for (auto& v : y) v = g(rng);
  const std::size_t mid = std::size_t{24} << 16;  // a stretch boundary
  std::vector<std::size_t> planted = {0, 5, 1000, n / 3, mid - 2, mid - 1, mid, mid + 3, n - 4, n - 1};
  ASSERT_TRUE(std::is_sorted(planted.begin(), planted.end()));
  for (std::size_t k = 0; k < planted.size(); ++k) y[planted[k]] += (k % 2 ? -1.0 : 1.0) * 40.0;
  const auto out = find_outliers(y);
  std::vector<std::size_t> idx;
  for (const auto& o : out) idx.push_back(o.index);
  EXPECT_EQ(idx, planted);
  const auto again = find_outliers(y, rwcalc::kDefaultOutlierThreshold, rwcalc::outlier_scale(y));
  ASSERT_EQ(again.size(), out.size());
  for (std::size_t k = 0; k < out.size(); ++k) EXPECT_EQ(again[k].robust_z, out[k].robust_z);
}

}  // namespace

namespace {

// The scan of a phase series (rates computed stretch by stretch) is the scan of its rates as a
// vector, bit for bit: scale, indices, values and z, on exact counts (whose candidates are screened
// on the counts, in a stretch with a count beyond 13 bits through the rates) and on a floating
// phase with a rate offset (as the reader keeps a rate record's mean), with RWCALC_THREADS=1 and =2.
TEST(Outliers, PhaseSeriesScanEqualsVectorScan) {
  std::mt19937_64 rng(21);
  std::poisson_distribution<int> pulses(2.5);
  rwcalc::PhaseSeries counts;
  counts.tau0_s = 0.0025;
  counts.arcsec_per_count = 0.92;
  const std::size_t n = (std::size_t{1} << 20) + 4321;  // many stretches
  counts.counts.assign(1, 1000000007);                  // an offset: differences are what count
  for (std::size_t i = 0; i < n; ++i) {
    std::int64_t c = pulses(rng);
    if (i % 99991 == 17 || i == 1 || i == n - 1) c += 60;  // glitches, two at the very ends
    if (i == 500000) c += 20000;                           // beyond the 13 bits of the counts' candidate screen
    counts.counts.push_back(counts.counts.back() + c);
  }
  rwcalc::PhaseSeries floating;
  floating.tau0_s = 0.01;
  floating.kind = rwcalc::PhaseKind::Gyro;
  // A rate record as the reader keeps it: the phase from 0 (its differences then carry every bit)
  // and the mean rate apart. Computed as (x[i+1] - x[i])/τ0 + offset, a quarter of these rates
  // would differ from PhaseSeries::rate in the last bit.
  floating.rate_offset = 15.0411 * 0.7071;
  auto y = gaussian(300001, 0.4, 22);
  for (std::size_t i = 0; i < y.size(); i += 7919) y[i] += 30.0;
  floating.values.assign(1, 0.0);
  for (double v : y) floating.values.push_back(floating.values.back() + v * floating.tau0_s);

  for (const rwcalc::PhaseSeries* ph : {&counts, &floating}) {
    std::vector<double> rates(ph->points() - 1);
    for (std::size_t i = 0; i < rates.size(); ++i) rates[i] = ph->rate(i);
    const auto sv = rwcalc::outlier_scale(rates);
    const auto ov = find_outliers(rates, 8.0, sv);
    EXPECT_FALSE(ov.empty());
    for (const char* threads : {"1", "2"}) {
      const rwcalc::test::ScopedEnv env("RWCALC_THREADS", threads);
      const auto sp = rwcalc::outlier_scale(*ph);
      EXPECT_EQ(sv.scale, sp.scale);
      EXPECT_EQ(sv.mad_sigma, sp.mad_sigma);
      EXPECT_EQ(sv.resolution, sp.resolution);
      const auto op = find_outliers(*ph, 8.0, sp);
      ASSERT_EQ(ov.size(), op.size()) << "threads " << threads;
      for (std::size_t k = 0; k < ov.size(); ++k) {
        EXPECT_EQ(ov[k].index, op[k].index);
        EXPECT_EQ(ov[k].value, op[k].value);
        EXPECT_EQ(ov[k].robust_z, op[k].robust_z);
      }
    }
  }
}

// Short records (7 to 20 samples): edges and interior agree too.
TEST(Outliers, PhaseSeriesScanEqualsVectorScanOnShortRecords) {
  for (std::size_t n = 7; n <= 20; ++n) {
    rwcalc::PhaseSeries ph;
    ph.counts.assign(1, 0);
    for (std::size_t i = 0; i < n; ++i) ph.counts.push_back(ph.counts.back() + (i == n / 2 ? 90 : 2 + (i % 3 == 0)));
    std::vector<double> rates(n);
    for (std::size_t i = 0; i < n; ++i) rates[i] = ph.rate(i);
    const auto sv = rwcalc::outlier_scale(rates), sp = rwcalc::outlier_scale(ph);
    EXPECT_EQ(sv.scale, sp.scale) << n;
    EXPECT_EQ(sv.resolution, sp.resolution) << n;
    const auto ov = find_outliers(rates, 8.0, sv), op = find_outliers(ph, 8.0, sp);
    ASSERT_EQ(ov.size(), op.size()) << n;
    for (std::size_t k = 0; k < ov.size(); ++k) EXPECT_EQ(ov[k].index, op[k].index) << n;
  }
}

}  // namespace
