// Unit tests of the class verdict: boundaries, tolerance, limits files, probabilities.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>

#include "rwcalc/analysis.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/simulate.hpp"
#include "rwcalc/verdict.hpp"
#include "test_support.hpp"

namespace rwcalc {
namespace {

/// An estimate known exactly (step confidence distribution).
EstimateInput exact(double v) { return lognormal_estimate(v, 0.0); }

// The verdict under other options from one analysis is the one analyze gives with those options:
// each B estimate, and a tolerance, on a 30-min GL-2D-like record.
TEST(Verdict, UnderOtherOptionsIsWhatAnalyzeDecidesWithThem) {
  SimulationSettings s;
  s.duration_s = 1800;
  s.rate_hz = 100;
  s.seed = 20261203;
  const Recording rec = test::simulated_gyro(0.0009, 0.008, s);
  const AnalysisResult base = analyze(rec);
  for (const BEstimate b : {BEstimate::Fit, BEstimate::SigmaMin, BEstimate::Avg100}) {
    AnalysisOptions o;
    o.verdict.b_estimate = b;
    o.verdict.tolerance_pct = b == BEstimate::Avg100 ? 50 : 0;
    const Verdict direct = analyze(rec, o).verdict, again = verdict_under(base, o);
    EXPECT_EQ(again.statement(), direct.statement()) << to_string(b);
    EXPECT_EQ(again.cls, direct.cls) << to_string(b);
    ASSERT_EQ(again.p_meets.size(), direct.p_meets.size());
    for (std::size_t i = 0; i < direct.p_meets.size(); ++i) EXPECT_EQ(again.p_meets[i], direct.p_meets[i]);
  }
}

TEST(Verdict, ClassBoundariesOfTheGostTable) {
  const VerdictOptions o;
  EXPECT_EQ(decide(exact(0.005), exact(0.0010), 0, o).cls, 1);  // on the limit meets it
  EXPECT_EQ(decide(exact(0.0050001), exact(0.0010), 0, o).B.cls, 2);
  EXPECT_EQ(decide(exact(0.0050001), exact(0.0010), 0, o).cls, 2);  // overall is the worse
  EXPECT_EQ(decide(exact(0.004), exact(0.0016), 0, o).N.cls, 3);
  EXPECT_EQ(decide(exact(0.004), exact(0.0016), 0, o).cls, 3);
  const Verdict out = decide(exact(0.016), exact(0.0005), 0, o);
  EXPECT_FALSE(out.B.cls.has_value());
  EXPECT_FALSE(out.cls.has_value());
  EXPECT_EQ(out.statement(), "outside class 3 (P=1.00)");
  // Margins: positive when met, in percent of the limit.
  const Verdict v = decide(exact(0.004), exact(0.0012), 0, o);
  EXPECT_NEAR(v.B.margin_pct[0], 20.0, 1e-9);
  EXPECT_NEAR(v.N.margin_pct[0], -20.0, 1e-9);
  EXPECT_NEAR(v.N.margin_pct[1], 20.0, 1e-9);
}

TEST(Verdict, ToleranceAppliesToBAndIsMarked) {
  VerdictOptions o;
  o.tolerance_pct = 50;
  const Verdict v = decide(exact(0.0074), exact(0.0009), 0, o);
  EXPECT_EQ(v.B.cls, 1);
  EXPECT_EQ(v.B.cls_strict, 2);
  EXPECT_EQ(v.cls, 1);
  EXPECT_EQ(v.cls_strict, 2);
  EXPECT_TRUE(v.tolerance_changed);
  EXPECT_NEAR(v.B.limit[1], 0.012, 1e-12);
  EXPECT_NEAR(v.N.limit[0], 0.0010, 1e-15);  // N limits unchanged
  // The paper's +50 °C case: B 0.0083 is class 3 strictly, class 2 with the tolerance.
  const Verdict w = decide(exact(0.0083), exact(0.00098), 0, o);
  EXPECT_EQ(w.cls, 2);
  EXPECT_EQ(w.cls_strict, 3);
  const Verdict same = decide(exact(0.004), exact(0.0009), 0, o);
  EXPECT_FALSE(same.tolerance_changed);
  o.tolerance_pct = -1;
  EXPECT_THROW(decide(exact(0.004), exact(0.0009), 0, o), UsageError);
}

TEST(Verdict, ProbabilitiesFromTheLogNormalSamplingDistribution) {
  const VerdictOptions o;
  // B exactly on the class-2 limit with 10 % uncertainty: P(class ≤ 2) = 0.5.
  const Verdict v = decide(lognormal_estimate(0.008, 0.0008), exact(0.0005), 0, o);
  EXPECT_NEAR(v.B.p_meets[1], 0.5, 1e-9);
  double sum = 0;
  for (double p : v.B.p_is) sum += p;
  EXPECT_NEAR(sum, 1.0, 1e-12);
  EXPECT_EQ(v.B.cls, 2);
  EXPECT_FALSE(v.decisive);
  EXPECT_EQ(v.statement(), fmt::format("class 2 or 3 (P={:.2f}/{:.2f})", v.p_is[1], v.p_is[2]));
  // Far from every limit: decisive.
  const Verdict d = decide(lognormal_estimate(0.003, 0.0003), lognormal_estimate(0.0005, 0.00005), 0, o);
  EXPECT_TRUE(d.decisive);
  EXPECT_GT(d.p_class, 0.99);
  EXPECT_EQ(d.statement(), fmt::format("class 1 (P={:.2f})", d.p_class));
}

TEST(Verdict, AnUnresolvedEstimateIsTakenAsPositive) {
  // A fit whose B estimate is 0: half the confidence distribution sits at 0, the rest a half-normal
  // whose 97.5 % point (the reported upper bound) is 0.0062 °/h.
  const double s = 0.0062 / 1.959964;
  EstimateInput b;
  b.value = 0.0062;
  b.high = 0.0062;
  b.resolved = false;
  b.cdf = [s](double x) { return x > 0 ? 0.5 + 0.5 * std::erf(x / s / std::numbers::sqrt2) : 0.0; };
  const Verdict v = decide(b, exact(0.0005), 0, VerdictOptions{});
  // Given B > 0: P(B ≤ x) = 2·cdf(x) − 1, not cdf(x) (which put P(class 1) at 0.94, now 0.89).
  EXPECT_NEAR(v.B.p_meets[0], 2 * b.cdf(0.005) - 1, 1e-12);
  EXPECT_NEAR(v.B.p_meets[1], 2 * b.cdf(0.008) - 1, 1e-12);
  EXPECT_LT(v.B.p_meets[0], b.cdf(0.005) - 0.05);
  // A resolved estimate has no mass at 0 and keeps its distribution.
  const auto r = lognormal_estimate(0.006, 0.001);
  EXPECT_NEAR(decide(r, exact(0.0005), 0, VerdictOptions{}).B.p_meets[0], r.cdf(0.005), 1e-15);
}

TEST(Verdict, OverallProbabilityCombinesBothParameters) {
  const VerdictOptions o;
  const auto b = lognormal_estimate(0.005, 0.001);   // P(B ≤ class 1) = 0.5
  const auto n = lognormal_estimate(0.001, 0.0002);  // P(N ≤ class 1) = 0.5
  const Verdict ind = decide(b, n, 0.0, o);
  EXPECT_NEAR(ind.p_meets[0], 0.25, 1e-6);
  const Verdict pos = decide(b, n, 0.999999, o);
  EXPECT_NEAR(pos.p_meets[0], 0.5, 2e-3);
  const Verdict neg = decide(b, n, -0.999999, o);
  EXPECT_NEAR(neg.p_meets[0], 0.0, 2e-3);
}

TEST(BivariateNormal, KnownValues) {
  for (double rho : {-0.9, -0.5, 0.0, 0.3, 0.8}) {
    EXPECT_NEAR(bivariate_normal_cdf(0, 0, rho), 0.25 + std::asin(rho) / (2 * std::numbers::pi), 1e-7) << rho;
  }
  EXPECT_NEAR(bivariate_normal_cdf(1.0, INFINITY, 0.5), 0.841344746, 1e-8);
  EXPECT_EQ(bivariate_normal_cdf(-INFINITY, 1.0, 0.5), 0.0);
}

TEST(ClassTableFile, LoadsAndRejects) {
  test::TempDir dir;
  const auto good = dir.write("limits.json", R"({"name": "lab table", "classes": [
      {"class": 1, "position_error_km_h": 1, "B_deg_per_h": 0.01, "N_deg_per_sqrt_h": 0.002},
      {"class": 2, "B_deg_per_h": 0.1, "N_deg_per_sqrt_h": 0.02}]})");
  const ClassTable t = ClassTable::load(good.string());
  EXPECT_EQ(t.name, "lab table");
  ASSERT_EQ(t.classes.size(), 2u);
  VerdictOptions o;
  o.table = t;
  const Verdict v = decide(exact(0.05), exact(0.001), 0, o);
  EXPECT_EQ(v.cls, 2);
  EXPECT_EQ(v.p_is.size(), 3u);

  EXPECT_THROW(ClassTable::load((dir.path() / "absent.json").string()), InputError);
  const auto bad_json = dir.write("bad.json", "{ not json");
  EXPECT_THROW(ClassTable::load(bad_json.string()), InputError);
  const auto missing = dir.write("missing.json", R"({"classes": [{"class": 1, "B_deg_per_h": 0.01}]})");
  EXPECT_THROW(ClassTable::load(missing.string()), InputError);
  const auto order = dir.write("order.json", R"({"classes": [
      {"class": 1, "B_deg_per_h": 0.01, "N_deg_per_sqrt_h": 0.002},
      {"class": 2, "B_deg_per_h": 0.005, "N_deg_per_sqrt_h": 0.02}]})");
  try {
    ClassTable::load(order.string());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("order.json"), std::string::npos);
  }
  const auto neg =
      dir.write("neg.json", R"({"classes": [{"class": 1, "B_deg_per_h": -1, "N_deg_per_sqrt_h": 0.002}]})");
  EXPECT_THROW(ClassTable::load(neg.string()), InputError);
}

TEST(Verdict, JsonCarriesTheIssueKeys) {
  const Verdict v = decide(lognormal_estimate(0.007, 0.001), lognormal_estimate(0.0009, 0.0001), -0.5, {});
  const nlohmann::json j = to_json(v);
  for (const char* k : {"class_B", "class_N", "class", "p_class", "statement", "b_estimate", "tolerance_pct"})
    EXPECT_TRUE(j.contains(k)) << k;
  EXPECT_EQ(j["class_B"], 2);
  EXPECT_EQ(j["b_estimate"], "fit");
  const Verdict none = decide(exact(0.02), exact(0.01), 0, {});
  EXPECT_TRUE(to_json(none)["class"].is_null());
  EXPECT_EQ(parse_b_estimate("sigma-min"), BEstimate::SigmaMin);
  EXPECT_THROW(parse_b_estimate("median"), UsageError);
}

}  // namespace
}  // namespace rwcalc
