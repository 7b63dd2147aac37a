// The shipped data/gl2d runs are reproducible bit for bit: re-running the documented command
// (scripts/make-gl2d-data.sh) for one 2-h run gives the shipped file's exact content.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "test_support.hpp"

namespace {

using rwcalc::test::gunzip;
using rwcalc::test::run_cli;
using rwcalc::test::slurp;
using rwcalc::test::source_path;
using rwcalc::test::TempDir;

std::string num(const nlohmann::json& v) { return fmt::format("{}", v.get<double>()); }

TEST(Gl2dData, ShippedRunRegeneratesBitForBit) {
  const auto truth_path = source_path("data/gl2d/gl2d_p50C.truth.json");
  const auto data_path = source_path("data/gl2d/gl2d_p50C.csv.gz");
  ASSERT_TRUE(std::filesystem::exists(truth_path)) << truth_path;
  const auto truth = nlohmann::json::parse(slurp(truth_path));
  const auto& m = truth.at("model");
  const auto& s = truth.at("settings");
  // The command of scripts/make-gl2d-data.sh, written uncompressed.
  TempDir dir;
  const auto out = dir.path() / "p50C.csv";
  const auto r = run_cli({"simulate",
                          "-o",
                          out.string(),
                          "--duration",
                          num(s.at("duration_s")),
                          "--rate",
                          num(s.at("rate_hz")),
                          "--scale",
                          num(s.at("scale_arcsec_per_pulse")),
                          "--latitude",
                          "55.75",
                          "--white-readout",
                          "--arw",
                          num(m.at("arw_deg_per_sqrt_h")),
                          "--bias-instability",
                          num(m.at("bias_instability_deg_per_h")),
                          "--temperature",
                          num(s.at("temperature_c")),
                          "--seed",
                          std::to_string(truth.at("seed").get<std::uint64_t>())});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string shipped = gunzip(data_path);
  ASSERT_FALSE(shipped.empty());
  const std::string fresh = slurp(out);
  EXPECT_EQ(fresh.size(), shipped.size());
  EXPECT_TRUE(fresh == shipped) << "data/gl2d/gl2d_p50C.csv.gz differs from a regeneration";
  EXPECT_NE(shipped.find("# temperature_c: 50\n"), std::string::npos);
  EXPECT_NEAR(m.at("earth_rate_deg_per_h").get<double>(), 12.4328, 1e-4);  // 55.75° N
}

TEST(Gl2dData, FiveRunsWithTruthAndTheirTemperatures) {
  const std::pair<const char*, double> runs[] = {{"m50C", -50}, {"m25C", -25}, {"0C", 0}, {"p25C", 25}, {"p50C", 50}};
  for (const auto& [name, temp] : runs) {
    const auto truth = nlohmann::json::parse(slurp(source_path(fmt::format("data/gl2d/gl2d_{}.truth.json", name))));
    EXPECT_EQ(truth.at("settings").at("temperature_c").get<double>(), temp) << name;
    EXPECT_EQ(truth.at("model").at("readout"), "white") << name;
    EXPECT_EQ(truth.at("settings").at("samples").get<int>(), 2880000) << name;
    const auto size = std::filesystem::file_size(source_path(fmt::format("data/gl2d/gl2d_{}.csv.gz", name)));
    EXPECT_LT(size, 2'000'000u) << name;
  }
}

}  // namespace
