// Every file rwcalc writes appears whole or not at all and never replaces an existing file without
// --force: the library call (write_file_atomic) and each command that writes (simulate records and
// truth, analyze/batch/merge -o). A refused or failed write leaves the existing file byte for byte
// as it was and no temporary file behind.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "rwcalc/error.hpp"
#include "rwcalc/output.hpp"
#include "test_support.hpp"

namespace {

namespace fs = std::filesystem;
using rwcalc::test::run_cli;
using rwcalc::test::TempDir;
using rwcalc::test::slurp;

std::set<std::string> listing(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

// A short simulated record to feed the commands (10 min at 100 Hz).
fs::path make_record(const TempDir& tmp, const std::string& name = "rec.csv") {
  const auto path = tmp.path() / name;
  const auto r = run_cli({"simulate", "-o", path.string(), "--duration", "600", "--rate", "100", "--arw", "0.05",
                          "--bias-instability", "0.02", "--seed", "3"});
  EXPECT_EQ(r.status, 0) << r.err;
  return path;
}

TEST(WriteFileAtomic, RefusesAnExistingFileWithoutForceAndLeavesItUnchanged) {
  TempDir tmp;
  const auto target = tmp.write("out.txt", "original\n");
  const auto before = listing(tmp.path());
  try {
    rwcalc::write_file_atomic(target.string(), "new content\n", false);
    FAIL() << "overwrote without force";
  } catch (const rwcalc::OutputError& e) {
    EXPECT_NE(std::string(e.what()).find("use --force"), std::string::npos) << e.what();
  }
  EXPECT_EQ(slurp(target), "original\n");
  EXPECT_EQ(listing(tmp.path()), before) << "a temporary file was left behind";

  rwcalc::write_file_atomic(target.string(), "new content\n", true);
  EXPECT_EQ(slurp(target), "new content\n");
  EXPECT_EQ(listing(tmp.path()), before);
}

TEST(WriteFileAtomic, FailuresLeaveNoTemporaryFile) {
  TempDir tmp;
  fs::create_directory(tmp.path() / "sub");
  const auto before = listing(tmp.path());
  // The target is a directory, with and without force.
  EXPECT_THROW(rwcalc::write_file_atomic((tmp.path() / "sub").string(), "x", false), rwcalc::OutputError);
  EXPECT_THROW(rwcalc::write_file_atomic((tmp.path() / "sub").string(), "x", true), rwcalc::OutputError);
  // The directory of the target does not exist.
  EXPECT_THROW(rwcalc::write_file_atomic((tmp.path() / "missing" / "f.txt").string(), "x", true), rwcalc::OutputError);
  EXPECT_EQ(listing(tmp.path()), before);
  EXPECT_TRUE(listing(tmp.path() / "sub").empty());
}

TEST(WriteFileAtomic, NewFilesAppearWholeAndGzipTargetsAreCompressed) {
  TempDir tmp;
  const std::string content(100000, 'x');
  rwcalc::write_file_atomic((tmp.path() / "a.txt").string(), content, false);
  rwcalc::write_file_atomic((tmp.path() / "a.txt.gz").string(), content, false);
  EXPECT_EQ(slurp(tmp.path() / "a.txt"), content);
  const auto gz = slurp(tmp.path() / "a.txt.gz");
  ASSERT_GE(gz.size(), 2u);
  EXPECT_EQ(static_cast<unsigned char>(gz[0]), 0x1f);
  EXPECT_EQ(static_cast<unsigned char>(gz[1]), 0x8b);
  EXPECT_LT(gz.size(), content.size() / 10);
  EXPECT_EQ(listing(tmp.path()), (std::set<std::string>{"a.txt", "a.txt.gz"}));
}

TEST(CommandOutputs, SimulateRefusesExistingRecordAndTruthWithoutForce) {
  TempDir tmp;
  const auto rec = make_record(tmp);
  const std::string original = slurp(rec);
  const auto before = listing(tmp.path());
  auto r = run_cli({"simulate", "-o", rec.string(), "--duration", "60", "--rate", "100", "--arw", "1", "--seed", "9"});
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find(rec.string()), std::string::npos) << r.err;
  EXPECT_EQ(slurp(rec), original);
  EXPECT_EQ(listing(tmp.path()), before);

  // An existing truth file stops the run before the (new) record is written.
  const auto truth = tmp.write("truth.json", "{}\n");
  const auto fresh = tmp.path() / "fresh.csv";
  r = run_cli({"simulate", "-o", fresh.string(), "--truth", truth.string(), "--duration", "60", "--rate", "100",
               "--arw", "1"});
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_FALSE(fs::exists(fresh)) << "the record was written although its truth file could not be";
  EXPECT_EQ(slurp(truth), "{}\n");

  // With --force both are replaced, and nothing else appears.
  r = run_cli({"simulate", "-o", rec.string(), "--truth", truth.string(), "--duration", "60", "--rate", "100",
               "--arw", "1", "--force"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(slurp(rec), original);
  EXPECT_NE(slurp(truth), "{}\n");
  EXPECT_EQ(listing(tmp.path()), (std::set<std::string>{"rec.csv", "truth.json"}));
}

TEST(CommandOutputs, SimulateRunsWriteNothingWhenOneTargetExists) {
  TempDir tmp;
  const auto second = tmp.write("sim_002.csv", "keep me\n");
  const auto r = run_cli({"simulate", "-o", (tmp.path() / "sim.csv").string(), "--runs", "3", "--duration", "60",
                          "--rate", "100", "--arw", "1"});
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("sim_002.csv"), std::string::npos) << r.err;
  EXPECT_EQ(listing(tmp.path()), (std::set<std::string>{"sim_002.csv"}));
  EXPECT_EQ(slurp(second), "keep me\n");
}

TEST(CommandOutputs, AnalyzeBatchAndMergeRefuseExistingOutputWithoutForce) {
  TempDir tmp;
  const auto rec = make_record(tmp);
  const auto out = tmp.write("out.txt", "previous\n");
  const auto before = listing(tmp.path());
  const std::vector<std::vector<std::string>> commands = {
      {"analyze", rec.string(), "-o", out.string()},
      {"batch", rec.string(), "-o", out.string()},
  };
  for (const auto& args : commands) {
    const auto r = run_cli(args);
    EXPECT_EQ(r.status, 3) << args[0] << ": " << r.err;
    EXPECT_NE(r.err.find("use --force"), std::string::npos) << r.err;
    EXPECT_EQ(slurp(out), "previous\n") << args[0];
    EXPECT_EQ(listing(tmp.path()), before) << args[0] << " left a file behind";
  }
  // merge reads batch's JSON lines.
  const auto lines = tmp.path() / "runs.jsonl";
  auto r = run_cli({"batch", rec.string(), "--jsonl", "-o", lines.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto with_lines = listing(tmp.path());
  r = run_cli({"merge", lines.string(), "-o", out.string()});
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_EQ(slurp(out), "previous\n");
  EXPECT_EQ(listing(tmp.path()), with_lines);

  r = run_cli({"analyze", rec.string(), "--json", "-o", out.string(), "--force"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(slurp(out).rfind("{", 0), 0u);
  EXPECT_EQ(listing(tmp.path()), with_lines);
}

}  // namespace
