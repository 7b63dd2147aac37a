// Outliers on `rwcalc analyze`: always detected and reported with their position (rate sample
// index, time from the first sample, input line), in the report and the JSON; kept by default,
// removed (a splice: the record gets shorter) or replaced by the local median on request. Known
// answers: a planted spike in a small pulse record; the known glitch of ADIS16405 run 4 gyro X
// (sample 404608, 8.400001 °/s, off the LSB grid); the contaminated Xsens MTi-G record, whose
// largest sample must be among those reported.
#include <gtest/gtest.h>

#include <zlib.h>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "rwcalc/analysis.hpp"
#include "rwcalc/reader.hpp"
#include "test_support.hpp"

namespace {

using nlohmann::json;
using rwcalc::test::run_cli;
using rwcalc::test::shared_data;

// 20 minutes of ±1 pulse noise at 400 Hz with one spike of 40 pulses; two comment lines and a
// header before the data, so line = sample + 4.
std::string spiked_pulses(std::size_t spike_at, std::size_t n) {
  std::string s = "# rate_hz: 400\n# scale_arcsec_per_pulse: 0.92\npulses\n";
  std::uint64_t state = 12345;
  for (std::size_t i = 0; i < n; ++i) {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    const int v = static_cast<int>((state >> 33) % 5) - 2 + 3;  // 1..5 pulses
    s += std::to_string(i == spike_at ? 60 : v) + "\n";
  }
  return s;
}

TEST(AnalyzeOutliers, PlantedSpikeIsReportedAtItsSampleTimeAndLine) {
  rwcalc::test::TempDir tmp;
  constexpr std::size_t kSpike = 123457, kN = 480000;
  const auto path = tmp.write("spike.txt", spiked_pulses(kSpike, kN)).string();

  auto r = run_cli({"analyze", path, "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  json j = json::parse(r.out);
  const auto& o = j["outliers"];
  EXPECT_EQ(o["action"], "keep");
  ASSERT_EQ(o["count"], 1) << o.dump();
  EXPECT_EQ(o["positions"][0]["index"], kSpike);
  EXPECT_EQ(o["positions"][0]["line"], kSpike + 4);
  EXPECT_NEAR(o["positions"][0]["time_s"].get<double>(), kSpike / 400.0, 1e-9);
  EXPECT_NEAR(o["positions"][0]["value"].get<double>(), 60 * 0.92 * 400, 1e-6);
  EXPECT_EQ(j["samples"], kN);

  r = run_cli({"analyze", path});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("1 found; KEPT"), std::string::npos) << r.out.substr(0, 1500);
  EXPECT_NE(r.out.find(std::to_string(kSpike + 4)), std::string::npos);

  r = run_cli({"analyze", path, "--json", "--outliers", "remove"});
  ASSERT_EQ(r.status, 0) << r.err;
  j = json::parse(r.out);
  EXPECT_EQ(j["outliers"]["removed"], 1);
  EXPECT_EQ(j["samples"], kN - 1);
  const double mean_removed = j["mean_rate"];

  r = run_cli({"analyze", path, "--json", "--outliers", "replace"});
  ASSERT_EQ(r.status, 0) << r.err;
  j = json::parse(r.out);
  EXPECT_EQ(j["outliers"]["replaced"], 1);
  EXPECT_EQ(j["samples"], kN);
  // Both leave the spike's ~57 extra pulses (52″ over 1200 s) out of the mean rate; keep does not.
  const double mean_kept = json::parse(run_cli({"analyze", path, "--json"}).out)["mean_rate"];
  const double mean_replaced = j["mean_rate"];
  EXPECT_GT(mean_kept - mean_replaced, 50 * 0.92 / 1200.0);  // ″/s = °/h
  EXPECT_LT(mean_kept - mean_replaced, 60 * 0.92 / 1200.0);
  EXPECT_NEAR(mean_removed, mean_replaced, 0.005);

  r = run_cli({"analyze", path, "--outliers", "drop"});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("keep, remove, replace"), std::string::npos) << r.err;
}

TEST(AnalyzeOutliers, Adis16405Run4GyroXSingleSpikeFoundAtItsPosition) {
  const auto file = shared_data("real/imudata_adis16405/adis_16405_imu4.csv.gz");
  RWCALC_REQUIRE_SHARED(file);
  const auto r = run_cli({"analyze", file.string(), "--input", "rate", "--rate-unit", "deg/s", "--column", "gyro_x_dps",
                          "--rate", "100", "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json o = json::parse(r.out)["outliers"];
  // The glitch (the only sample off the 0.05 °/s LSB grid) sits inside a burst of large readings
  // (indices 404605-404615, up to 17 °/s against a 0.35 °/s spread); three more excursions of
  // 3-4 °/s come near 117 s (flagged readings are all beyond 2 °/s). All are flagged; nothing else in the 10^6 samples
  // is.
  const std::size_t count = o["count"];
  std::printf("[ outliers ] ADIS16405 run 4 gyro X: %zu found\n", count);
  EXPECT_GE(count, 1u);
  EXPECT_LE(count, 20u);
  bool found = false;
  for (const auto& p : o["positions"]) {
    EXPECT_GT(std::abs(p["value"].get<double>()), 2.0 * 3600) << p.dump();  // > 5.7 sigma of the record
    if (p["index"] != 404608) continue;
    found = true;
    EXPECT_EQ(p["line"], 404608 + 4);  // two comment lines and the header come first
    EXPECT_NEAR(p["time_s"].get<double>(), 4046.08, 1e-9);
    EXPECT_NEAR(p["value"].get<double>(), 8.400001 * 3600, 1e-6);
    EXPECT_GT(p["robust_z"].get<double>(), 8.0);
  }
  EXPECT_TRUE(found) << "the known glitch at sample 404608 was not reported: " << o.dump(1);
}

TEST(AnalyzeOutliers, XsensContaminatedRecordReportsCountAndPositions) {
  const auto file = shared_data("real/imudata_xsens_mtig_contaminated/cont_imu1_gyro_x.csv.gz");
  RWCALC_REQUIRE_SHARED(file);
  rwcalc::ReadOptions ro;
  ro.mode = rwcalc::InputMode::Rate;
  ro.rate_unit = rwcalc::RateUnit::RadPerSecond;
  ro.rate_hz = 100;
  const auto rec = rwcalc::read_recording(file.string(), ro);
  const auto rates = rec.rates();
  ASSERT_EQ(rates.size(), 500000u);
  std::size_t largest = 0;
  for (std::size_t i = 0; i < rates.size(); ++i)
    if (std::abs(rates[i]) > std::abs(rates[largest])) largest = i;

  const auto r =
      run_cli({"analyze", file.string(), "--input", "rate", "--rate-unit", "rad/s", "--rate", "100", "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const json o = json::parse(r.out)["outliers"];
  const std::size_t count = o["count"];
  std::printf("[ outliers ] Xsens contaminated gyro X: %zu found\n", count);
  EXPECT_GE(count, 100u);               // heavily contaminated (PROVENANCE: ~27 000 beyond 6 robust sd)
  EXPECT_LT(count, rates.size() / 10);  // but not a tenth of the record
  EXPECT_EQ(o["positions"].size(), std::min<std::size_t>(count, rwcalc::kMaxOutlierPositions));
  bool found_largest = false;
  std::size_t previous = 0;
  for (const auto& p : o["positions"]) {
    const std::size_t i = p["index"];
    EXPECT_GE(i, previous);
    previous = i;
    EXPECT_EQ(p["line"], i + 4);  // two comment lines and the header
    EXPECT_NEAR(p["time_s"].get<double>(), static_cast<double>(i) / 100.0, 1e-9);
    found_largest |= i == largest;
  }
  if (largest < o["positions"].back()["index"].get<std::size_t>()) {
    EXPECT_TRUE(found_largest) << "the largest sample (index " << largest << ") is not reported";
  }

  const auto text = run_cli({"analyze", file.string(), "--input", "rate", "--rate-unit", "rad/s", "--rate", "100"});
  ASSERT_EQ(text.status, 0) << text.err;
  EXPECT_NE(text.out.find(std::to_string(count) + " found; KEPT"), std::string::npos) << text.out.substr(0, 2000);
}

}  // namespace
