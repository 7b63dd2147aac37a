// Progress lines end to end: every command that can run long (simulate, analyze, allan, batch, imu,
// report, diagnose) draws them on standard error when that is a terminal (a pseudo-terminal made by
// util-linux `script`), and draws none under --quiet or when standard error is a file; what it
// writes on standard output is the same either way. The inputs are small: a line is drawn as soon
// as the work starts, however short it is.
#include <gtest/gtest.h>

#include <cstdlib>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "test_support.hpp"

namespace {

using rwcalc::test::CliResult;
using rwcalc::test::TempDir;

const TempDir& inputs() {
  static const TempDir dir;
  return dir;
}

/// A 1300-s GL-2D record (the diagnosis needs 1200 s), simulated once.
std::string record() {
  static const std::string path = [] {
    const std::string p = (inputs().path() / "run.csv.gz").string();
    const CliResult r = rwcalc::test::run_exe(
        {"simulate", "-o", p, "--duration", "1300", "--arw", "0.001", "--bias-instability", "0.008", "--seed", "5"});
    EXPECT_EQ(r.status, 0) << r.err;
    return p;
  }();
  return path;
}

/// A small IMU file: a gyro and an accelerometer column, 2000 samples at 100 Hz.
std::string imu_file() {
  static const std::string path = [] {
    std::mt19937_64 rng(7);
    std::normal_distribution<double> noise;
    std::ostringstream text;
    text << "time,gyro_x_dps,acc_x_g\n";
    for (int i = 0; i < 2000; ++i) text << i * 0.01 << ',' << 0.01 * noise(rng) << ',' << 0.001 * noise(rng) << '\n';
    return inputs().write("imu.csv", text.str()).string();
  }();
  return path;
}

/// Standard output without the line that says how long the work took (diagnose's last).
std::string without_time_taken(const std::string& out) {
  return std::regex_replace(out, std::regex(R"(\n  \([0-9.]+ s\)\n$)"), "\n");
}

bool script_available() { return std::system("command -v script >/dev/null 2>&1") == 0; }

/// `args` on a terminal shows a progress line starting with each of `labels`; on a terminal with
/// --quiet, and with standard error a file, none; standard output is the same all three ways.
void expect_progress(const std::vector<std::string>& args, const std::vector<std::string>& labels) {
  const CliResult shown = rwcalc::test::run_exe_on_terminal(args);
  ASSERT_EQ(shown.status, 0) << shown.err;
  for (const auto& label : labels) EXPECT_NE(shown.err.find("\r" + label), std::string::npos) << label << shown.err;
  std::vector<std::string> quiet_args = args;
  quiet_args.push_back("--quiet");
  const CliResult quiet = rwcalc::test::run_exe_on_terminal(quiet_args);
  const CliResult file = rwcalc::test::run_exe(args);
  ASSERT_EQ(quiet.status, 0) << quiet.err;
  ASSERT_EQ(file.status, 0) << file.err;
  for (const auto& label : labels) {
    EXPECT_EQ(quiet.err.find("\r" + label), std::string::npos) << quiet.err;
    EXPECT_EQ(file.err.find(label), std::string::npos) << file.err;
  }
  EXPECT_EQ(without_time_taken(quiet.out), without_time_taken(shown.out));
  EXPECT_EQ(without_time_taken(file.out), without_time_taken(shown.out));
}

class ProgressOnTerminal : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!script_available()) GTEST_SKIP() << "util-linux script (package bsdutils) is not installed";
  }
};

TEST_F(ProgressOnTerminal, Simulate) {
  const TempDir out;
  const std::string path = (out.path() / "sim.csv.gz").string();
  expect_progress({"simulate", "-o", path, "--duration", "3600", "--arw", "0.001", "--force"}, {"simulating " + path});
}

TEST_F(ProgressOnTerminal, AnalyzeAndAllanShowReadingAndAnalysis) {
  expect_progress({"analyze", record()}, {"reading " + record() + ": ", "analysing " + record() + ": "});
  expect_progress({"allan", record(), "--tau", "dense"},
                  {"reading " + record() + ": ", "computing the deviation at each τ: "});
}

TEST_F(ProgressOnTerminal, BatchCountsTheRuns) {
  const std::string copy = (inputs().path() / "copy.csv.gz").string();
  const CliResult r =
      rwcalc::test::run_exe({"simulate", "-o", copy, "--duration", "1300", "--arw", "0.001", "--seed", "6", "--force"});
  ASSERT_EQ(r.status, 0) << r.err;
  expect_progress({"batch", record(), copy}, {"analysing the runs: 0/2 (0%)"});
}

TEST_F(ProgressOnTerminal, ImuCountsTheChannels) {
  expect_progress({"imu", imu_file(), "--gyro", "gyro_x_dps", "--accel", "acc_x_g"},
                  {"analysing the channels of " + imu_file() + ": 0/2"});
}

TEST_F(ProgressOnTerminal, Report) {
  const TempDir out;
  expect_progress({"report", record(), "-o", out.path().string(), "--no-figures", "--force"},
                  {"analysing the runs: ", "reading " + record()});
}

TEST_F(ProgressOnTerminal, DiagnoseCountsItsLikelihoodTests) {
  expect_progress({"diagnose", record()}, {"diagnosing " + record() + " (likelihood tests): 0/"});
}

TEST_F(ProgressOnTerminal, InTheOutputLanguage) {
  const CliResult r = rwcalc::test::run_exe_on_terminal({"analyze", record(), "--lang", "ru"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("\rчтение " + record() + ": "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(" кБ ("), std::string::npos) << r.err;
}

}  // namespace
