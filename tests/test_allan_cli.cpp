// 'rwcalc allan' end to end: reference data through the real reader and the command line, every
// output form, and the error paths with their exit statuses.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <sstream>

#include "test_allan_refdata.hpp"
#include "test_support.hpp"

namespace rwcalc::test {
namespace {

std::filesystem::path adis() { return shared_data("real/imudata_adis16405/adis_16405_imu1.csv.gz"); }
std::filesystem::path phase_dat() { return shared_data("reference/nbs14_riley/stable32_PHASE_DAT/PHASE.DAT"); }

TEST(AllanCli, Adis16405GyroXThroughTheReaderMatchesThePublishedAv) {
  RWCALC_REQUIRE_SHARED(adis());
  const auto ref_path = shared_data("real/imudata_adis16405/reference_avar_adis_av_run1.csv");
  std::istringstream in(read_text_gz(ref_path));
  std::string line, taus;
  std::vector<double> want;  // ADEV, °/h
  while (std::getline(in, line)) {
    if (!line.starts_with("Gyro_X,")) continue;
    std::vector<std::string> f;
    std::istringstream ls(line);
    for (std::string x; std::getline(ls, x, ',');) f.push_back(x);
    taus += (taus.empty() ? "" : ",") + f[2];
    want.push_back(std::stod(f[4]) * 3600.0);
  }
  ASSERT_EQ(want.size(), 18u);
  const auto r = run_cli({"allan", adis().string(), "--input", "rate", "--rate-unit", "deg/s", "--rate", "100",
                          "--column", "gyro_x_dps", "--tau", taus, "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("unit"), "deg/h");
  EXPECT_EQ(j.at("samples"), 1000000);
  ASSERT_EQ(j.at("points").size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    const auto& p = j.at("points")[i];
    EXPECT_LE(rel_err(p.at("dev").get<double>(), want[i]), 1e-4) << "tau " << p.at("tau_s");
    EXPECT_LT(p.at("dev_low").get<double>(), p.at("dev").get<double>());
    EXPECT_GT(p.at("dev_high").get<double>(), p.at("dev").get<double>());
  }
}

TEST(AllanCli, PhaseDatAsClockPhaseReproducesStable32OctaveTable) {
  RWCALC_REQUIRE_SHARED(phase_dat());
  const Stable32Table t = load_stable32(phase_dat().parent_path() / "phase_dat_oadev_octave.txt");
  const auto r = run_cli({"allan", phase_dat().string(), "--input", "angle", "--angle-unit", "s", "--rate", "1",
                          "--json", "--tau", "octave"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("unit"), "1");
  const auto& pts = j.at("points");
  ASSERT_GE(pts.size(), t.rows.size());
  // Stable32 stops its octave run at N/4; rwcalc goes on to N/2, so compare the common part. (The
  // last Stable32 row carries its previous α over; ours at m = 128 is not the last, so skip α there.)
  for (std::size_t i = 0; i < t.rows.size(); ++i) {
    const auto& p = pts[i];
    ASSERT_EQ(p.at("af").get<long>(), t.rows[i].af);
    EXPECT_EQ(p.at("n").get<long>(), t.rows[i].n);
    EXPECT_LE(rel_err(p.at("dev").get<double>(), t.rows[i].sigma), 5e-5);
    if (i + 1 < t.rows.size()) {
      EXPECT_EQ(p.at("alpha").get<int>(), t.rows[i].alpha);
      EXPECT_LE(rel_err(p.at("dev_low").get<double>(), t.rows[i].min_sigma), 2e-3);
      EXPECT_LE(rel_err(p.at("dev_high").get<double>(), t.rows[i].max_sigma), 2e-3);
    }
  }
}

std::filesystem::path gl2d() { return source_path("data/gl2d/gl2d_p25C.csv.gz"); }

TEST(AllanCli, GyroPulseFileGivesTableCsvAndJsonThatAgree) {
  if (!std::filesystem::exists(gl2d())) GTEST_SKIP() << "sample recording absent: " << gl2d();
  const auto table = run_cli({"allan", gl2d().string(), "--tau", "decade"});
  ASSERT_EQ(table.status, 0) << table.err;
  for (const char* s : {"°/h", "1″/s = 1 °/h", "overlapping Allan", "confidence: 0.683", "EDF", "σ_min", "σ_max"})
    EXPECT_NE(table.out.find(s), std::string::npos) << s;
  const auto csv = run_cli({"allan", gl2d().string(), "--tau", "decade", "--csv"});
  ASSERT_EQ(csv.status, 0) << csv.err;
  EXPECT_TRUE(csv.out.starts_with("af,tau_s,n,alpha,edf,dev_low_deg_h,dev_deg_h,dev_high_deg_h\n"));
  const auto js = run_cli({"allan", gl2d().string(), "--tau", "decade", "--json"});
  ASSERT_EQ(js.status, 0) << js.err;
  const auto j = nlohmann::json::parse(js.out);
  EXPECT_EQ(j.at("estimator"), "oadev");
  EXPECT_DOUBLE_EQ(j.at("confidence").get<double>(), 0.683);
  // Same numbers in CSV and JSON.
  std::istringstream rows(csv.out);
  std::string row;
  std::getline(rows, row);
  for (const auto& p : j.at("points")) {
    ASSERT_TRUE(std::getline(rows, row));
    std::istringstream f(row);
    std::string af, tau, n, alpha, edf, lo, dev;
    for (std::string* s : {&af, &tau, &n, &alpha, &edf, &lo, &dev}) std::getline(f, *s, ',');
    EXPECT_EQ(std::stol(af), p.at("af").get<long>());
    EXPECT_NEAR(std::stod(dev) / p.at("dev").get<double>(), 1.0, 1e-9);
  }
  const auto mdev = run_cli({"allan", gl2d().string(), "--estimator", "mdev", "--json", "--tau", "1,10"});
  ASSERT_EQ(mdev.status, 0) << mdev.err;
  EXPECT_EQ(nlohmann::json::parse(mdev.out).at("points").size(), 2u);
  for (const char* est : {"ohdev", "hdev"}) {
    const auto h = run_cli({"allan", gl2d().string(), "--estimator", est, "--json"});
    ASSERT_EQ(h.status, 0) << h.err;
    const auto hj = nlohmann::json::parse(h.out);
    EXPECT_EQ(hj.at("estimator"), est);
    EXPECT_GT(hj.at("points").size(), 15u);
    const auto text = run_cli({"allan", gl2d().string(), "--estimator", est});
    EXPECT_NE(text.out.find("Hadamard"), std::string::npos);
  }
}

TEST(AllanCli, ErrorsAreReportedWithTheirExitStatus) {
  TempDir dir;
  const auto file = dir.write("short.txt", "pulses\n1\n2\n3\n0\n1\n2\n");
  const auto two = dir.write("two.txt", "angle\n1\n2\n");  // two phase points: no τ fits
  struct Case {
    std::vector<std::string> args;
    int status;
    const char* message;
  };
  const std::vector<Case> cases = {
      {{"allan", file.string(), "--tau", "fast"}, 2, "--tau"},
      {{"allan", file.string(), "--tau", "0.003"}, 2, "whole number of samples"},
      {{"allan", file.string(), "--tau", "10"}, 2, "beyond the longest"},
      {{"allan", file.string(), "--confidence", "1.5"}, 2, "confidence"},
      {{"allan", file.string(), "--estimator", "tdev"}, 2, "ohdev or hdev"},
      {{"allan", file.string(), "--json", "--csv"}, 2, "excludes"},
      {{"allan", (dir.path() / "missing.txt").string()}, 2, "missing.txt"},
      {{"allan", two.string(), "--input", "angle", "--rate", "400"}, 1, "phase point"},
  };
  for (const Case& c : cases) {
    const auto r = run_cli(c.args);
    EXPECT_EQ(r.status, c.status) << c.args.back() << "\n" << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
  }
  const auto help = run_exe({"allan", "--help"});
  EXPECT_EQ(help.status, 0);
  for (const char* s : {"--tau", "--confidence", "--estimator", "--json", "--csv", "--input", "--column"})
    EXPECT_NE(help.out.find(s), std::string::npos) << s;
}

}  // namespace
}  // namespace rwcalc::test
