// Every case of the bad-input corpus (tests/bad_input/MANIFEST.tsv) through the command line:
// `rwcalc analyze FILE OPTIONS` exits with the documented status and prints one error naming the
// file and the line; accepted inputs are either analysed or refused by the analysis with its own
// message (these records are a few samples long) — never a crash, a hang or silence.
// An output option given an empty name is a usage error naming the option, for every command.
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "bad_input_corpus.hpp"
#include "test_support.hpp"

namespace {

using rwcalc::test::bad_input_case_name;
using rwcalc::test::BadInputCase;
using rwcalc::test::load_bad_input_manifest;

class CliBadInput : public ::testing::TestWithParam<BadInputCase> {};

TEST_P(CliBadInput, AnalyzeExitsWithTheDocumentedStatusNamingFileAndLine) {
  const BadInputCase& c = GetParam();
  const rwcalc::test::TempDir tmp;
  const auto staged = rwcalc::test::stage_bad_input(c, tmp);
  if (!staged) GTEST_SKIP() << "running as root: permissions do not stop reading";
  const std::string& path = *staged;
  std::vector<std::string> args{"analyze", path};
  if (c.options != "-") {
    std::stringstream ss(c.options);
    for (std::string word; ss >> word;) args.push_back(word);
  }
  auto r = rwcalc::test::run_cli(args);
  if (c.status == 0) {
    // Read without complaint (the reader's notes aside); the analysis either runs or says why it
    // cannot (too short).
    std::string err, line;
    for (std::istringstream in(r.err); std::getline(in, line);)
      if (!line.starts_with("rwcalc: note: ")) err += line + "\n";
    r.err = err;
    if (r.status == 0) {
      EXPECT_NE(r.out.find("rwcalc analyze"), std::string::npos) << r.out.substr(0, 400);
      EXPECT_TRUE(r.err.empty()) << r.err;
    } else {
      EXPECT_EQ(r.status, 1) << r.err;
      EXPECT_EQ(r.err.rfind("rwcalc: error: ", 0), 0u) << r.err;
      EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
    }
    return;
  }
  EXPECT_EQ(r.status, c.status) << r.err;
  EXPECT_TRUE(r.out.empty()) << "nothing is printed on standard output for a refused input";
  const std::string where = c.line ? path + ":" + std::to_string(c.line) + ": " : path + ": ";
  EXPECT_EQ(r.err.rfind("rwcalc: error: " + where, 0), 0u) << r.err;
  EXPECT_NE(r.err.find(c.fragment), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line of diagnosis: " << r.err;
}

INSTANTIATE_TEST_SUITE_P(Corpus, CliBadInput, ::testing::ValuesIn(load_bad_input_manifest()), bad_input_case_name);

TEST(CliErrors, AnEmptyOutputNameIsAUsageErrorNamingTheOption) {
  // "-o ''" used to end in ": cannot move the finished file into place" (status 3), or in nothing.
  const rwcalc::test::TempDir tmp;
  const auto rec = (tmp.path() / "rec.csv").string();
  ASSERT_EQ(rwcalc::test::run_cli({"simulate", "-o", rec, "--duration", "600", "--rate", "10", "--arw", "0.1"}).status,
            0);
  const auto saved = rwcalc::test::run_cli({"analyze", rec, "--json"});
  ASSERT_EQ(saved.status, 0) << saved.err;
  const auto json = tmp.write("a.json", saved.out).string();
  const auto lines = tmp.write("a.jsonl", rwcalc::test::run_cli({"batch", rec, "--jsonl"}).out).string();
  struct Case {
    std::vector<std::string> args;  ///< the option with its empty value last
    std::string option;
  };
  const std::vector<Case> cases{
      {{"analyze", rec, "-o", ""}, "--output"},
      {{"analyze", rec, "--plot", ""}, "--plot"},
      {{"analyze", rec, "--plot-script", ""}, "--plot-script"},
      {{"batch", rec, "-o", ""}, "--output"},
      {{"batch", rec, "--plot", ""}, "--plot"},
      {{"merge", lines, "-o", ""}, "--output"},
      {{"simulate", "-o", ""}, "--output"},
      {{"simulate", "-o", rec, "--truth", ""}, "--truth"},
      {{"diagnose", rec, "-o", ""}, "--output"},
      {{"diagnose", rec, "--plot-script", ""}, "--plot-script"},
      {{"imu", rec, "--gyro", "pulses", "-o", ""}, "--output"},
      {{"imu", rec, "--gyro", "pulses", "--kalibr", ""}, "--kalibr"},
      {{"imu", rec, "--gyro", "pulses", "--report", ""}, "--report"},
      {{"report", json, "-o", ""}, "--output"},
  };
  for (const auto& c : cases) {
    const auto r = rwcalc::test::run_cli(c.args);
    const std::string shown = c.args[0] + " " + c.option;
    EXPECT_EQ(r.status, 2) << shown << ": " << r.err;
    EXPECT_NE(r.err.find(c.option), std::string::npos) << shown << ": " << r.err;
    EXPECT_NE(r.err.find("empty"), std::string::npos) << shown << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << shown;
  }
}

}  // namespace
