// NIST SP 1065 reference values (NBS14 10-point set and W. Riley's 1000-point set): ADEV, OADEV
// and MDEV to 1e-6 relative, from phase data and from frequency data alike.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

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

std::vector<Reference> load_references() {
  std::vector<Reference> refs;
  std::istringstream in(read_text_gz(nbs_dir() / "reference_values.csv"));
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line.starts_with("dataset")) continue;
    std::istringstream f(line);
    Reference r;
    std::string tau, value;
    std::getline(f, r.dataset, ',');
    std::getline(f, r.statistic, ',');
    std::getline(f, tau, ',');
    std::getline(f, value, ',');
    r.tau = std::stol(tau);
    r.value = std::stod(value);
    if (r.statistic == "ADEV" || r.statistic == "OADEV" || r.statistic == "MDEV") refs.push_back(r);
  }
  return refs;
}

Estimator estimator_named(const std::string& s) {
  if (s == "ADEV") return Estimator::NonOverlapping;
  if (s == "OADEV") return Estimator::Overlapping;
  return Estimator::Modified;
}

void check_dataset(const std::string& dataset, const PhaseSeries& x) {
  int checked = 0;
  for (const Reference& r : load_references()) {
    if (r.dataset != dataset) continue;
    SCOPED_TRACE(r.statistic + " tau " + std::to_string(r.tau));
    const double dev = std::sqrt(allan_variance(x, r.tau, estimator_named(r.statistic)));
    EXPECT_LE(rel_err(dev, r.value), kTol) << dev << " vs " << r.value;
    ++checked;
  }
  EXPECT_GE(checked, 6) << "reference rows for " << dataset;
}

TEST(Nbs14, TenPointPhase) {
  RWCALC_REQUIRE_SHARED(nbs_dir() / "nbs14_10point_phase.txt");
  const PhaseSeries x = phase_series(load_column(nbs_dir() / "nbs14_10point_phase.txt"));
  ASSERT_EQ(x.points(), 10u);
  check_dataset("nbs14_10point", x);
}

TEST(Nbs14, TenPointFrequency) {
  RWCALC_REQUIRE_SHARED(nbs_dir() / "nbs14_10point_freq.txt");
  const PhaseSeries x = frequency_series(load_column(nbs_dir() / "nbs14_10point_freq.txt"));
  ASSERT_EQ(x.points(), 10u);
  check_dataset("nbs14_10point", x);
}

TEST(Nbs14, ThousandPointFrequency) {
  RWCALC_REQUIRE_SHARED(nbs_dir() / "nbs14_1000point_freq.txt");
  const PhaseSeries x = frequency_series(load_column(nbs_dir() / "nbs14_1000point_freq.txt"));
  ASSERT_EQ(x.points(), 1001u);
  check_dataset("nbs14_1000point", x);
}

TEST(Nbs14, ThousandPointThroughComputeAllanWithExplicitGrid) {
  RWCALC_REQUIRE_SHARED(nbs_dir() / "nbs14_1000point_freq.txt");
  const PhaseSeries x = frequency_series(load_column(nbs_dir() / "nbs14_1000point_freq.txt"));
  for (const char* stat : {"ADEV", "OADEV", "MDEV"}) {
    AllanOptions o;
    o.estimator = estimator_named(stat);
    o.grid = TauGrid::parse("1,10,100");
    const AllanResult res = compute_allan(x, o);
    ASSERT_EQ(res.points.size(), 3u);
    for (const Reference& r : load_references()) {
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
