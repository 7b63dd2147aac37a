// NIST SP 1065 reference values (NBS14 10-point set and W. Riley's 1000-point set): ADEV, OADEV
// and MDEV to 1e-6 relative, from phase data and from frequency data alike. The data and the
// published values are public (W. J. Riley, Handbook of Frequency Stability Analysis, NIST SP 1065,
// 2008, pp. 107-108): the 9 NBS14 frequencies are written here and the 1000-point set is made by
// its published recipe, so a plain clone runs these known-answer tests; the copies in ../shared are
// checked to be the same data when present.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "rwcalc/allan.hpp"
#include "test_allan_refdata.hpp"
#include "test_support.hpp"

namespace rwcalc::test {
namespace {

constexpr double kTol = 1e-6;

std::filesystem::path nbs_dir() { return shared_data("reference/nbs14_riley"); }

struct Reference {
  std::string dataset, statistic;
  long tau = 0;
  double value = 0;
};

// NIST SP 1065, tables of the NBS14 10-point and the 1000-point test sets.
const std::vector<Reference>& references() {
  static const std::vector<Reference> refs = {
      {"nbs14_10point", "ADEV", 1, 91.22945},         {"nbs14_10point", "ADEV", 2, 115.8082},
      {"nbs14_10point", "OADEV", 1, 91.22945},        {"nbs14_10point", "OADEV", 2, 85.95287},
      {"nbs14_10point", "MDEV", 1, 91.22945},         {"nbs14_10point", "MDEV", 2, 74.78849},
      {"nbs14_1000point", "ADEV", 1, 2.922319e-01},   {"nbs14_1000point", "ADEV", 10, 9.965736e-02},
      {"nbs14_1000point", "ADEV", 100, 3.897804e-02}, {"nbs14_1000point", "OADEV", 1, 2.922319e-01},
      {"nbs14_1000point", "OADEV", 10, 9.159953e-02}, {"nbs14_1000point", "OADEV", 100, 3.241343e-02},
      {"nbs14_1000point", "MDEV", 1, 2.922319e-01},   {"nbs14_1000point", "MDEV", 10, 6.172376e-02},
      {"nbs14_1000point", "MDEV", 100, 2.170921e-02}};
  return refs;
}

/// The NBS14 set: 9 fractional frequencies at τ0 = 1 s (its 10 phase points integrate them).
std::vector<double> nbs14_frequencies() { return {892, 809, 823, 798, 671, 644, 883, 903, 677}; }

/// Riley's 1000-point set: n_0 = 1234567890, n_{i+1} = 16807·n_i mod (2^31 − 1), y_i = n_i/(2^31 − 1).
std::vector<double> thousand_point_frequencies() {
  constexpr std::uint64_t kModulus = 2147483647;
  std::uint64_t n = 1234567890;
  std::vector<double> y;
  for (int i = 0; i < 1000; ++i) {
    y.push_back(static_cast<double>(n) / static_cast<double>(kModulus));
    n = n * 16807 % kModulus;
  }
  return y;
}

/// Phase x_0 = 0, x_{i+1} = x_i + y_i (τ0 = 1).
std::vector<double> integrated(const std::vector<double>& y) {
  std::vector<double> x{0.0};
  for (double v : y) x.push_back(x.back() + v);
  return x;
}

Estimator estimator_named(const std::string& s) {
  if (s == "ADEV") return Estimator::NonOverlapping;
  if (s == "OADEV") return Estimator::Overlapping;
  return Estimator::Modified;
}

void check_dataset(const std::string& dataset, const PhaseSeries& x) {
  int checked = 0;
  for (const Reference& r : references()) {
    if (r.dataset != dataset) continue;
    SCOPED_TRACE(r.statistic + " tau " + std::to_string(r.tau));
    const double dev = std::sqrt(allan_variance(x, r.tau, estimator_named(r.statistic)));
    EXPECT_LE(rel_err(dev, r.value), kTol) << dev << " vs " << r.value;
    ++checked;
  }
  EXPECT_GE(checked, 6) << "reference rows for " << dataset;
}

TEST(Nbs14, RecipeStartsAsPublished) {
  // SP 1065 lists n_1, n_2, n_3 of the recipe.
  const std::vector<double> y = thousand_point_frequencies();
  constexpr double kModulus = 2147483647.0;
  EXPECT_EQ(y[1] * kModulus, 395529916.0);
  EXPECT_EQ(y[2] * kModulus, 1209410747.0);
  EXPECT_EQ(y[3] * kModulus, 633705974.0);
}

TEST(Nbs14, TenPointPhase) {
  const PhaseSeries x = phase_series(integrated(nbs14_frequencies()));
  ASSERT_EQ(x.points(), 10u);
  check_dataset("nbs14_10point", x);
}

TEST(Nbs14, TenPointFrequency) {
  const PhaseSeries x = frequency_series(nbs14_frequencies());
  ASSERT_EQ(x.points(), 10u);
  check_dataset("nbs14_10point", x);
}

TEST(Nbs14, ThousandPointFrequency) {
  const PhaseSeries x = frequency_series(thousand_point_frequencies());
  ASSERT_EQ(x.points(), 1001u);
  check_dataset("nbs14_1000point", x);
}

TEST(Nbs14, SharedCopiesAreTheSameData) {
  RWCALC_REQUIRE_SHARED(nbs_dir() / "nbs14_1000point_freq.txt");
  const std::vector<double> shared = load_column(nbs_dir() / "nbs14_1000point_freq.txt");
  const std::vector<double> made = thousand_point_frequencies();
  ASSERT_EQ(shared.size(), made.size());
  for (std::size_t i = 0; i < made.size(); ++i) EXPECT_NEAR(shared[i], made[i], 1e-14) << i;
  EXPECT_EQ(load_column(nbs_dir() / "nbs14_10point_freq.txt"), nbs14_frequencies());
}

TEST(Nbs14, ThousandPointThroughComputeAllanWithExplicitGrid) {
  const PhaseSeries x = frequency_series(thousand_point_frequencies());
  for (const char* stat : {"ADEV", "OADEV", "MDEV"}) {
    AllanOptions o;
    o.estimator = estimator_named(stat);
    o.grid = TauGrid::parse("1,10,100");
    const AllanResult res = compute_allan(x, o);
    ASSERT_EQ(res.points.size(), 3u);
    for (const Reference& r : references()) {
      if (r.dataset != "nbs14_1000point" || r.statistic != stat) continue;
      for (const AllanPoint& p : res.points) {
        if (p.m == r.tau) {
          EXPECT_LE(rel_err(p.dev, r.value), kTol) << stat << " " << r.tau;
        }
      }
    }
  }
}

}  // namespace
}  // namespace rwcalc::test
