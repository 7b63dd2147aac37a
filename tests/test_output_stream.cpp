// The streaming form of an output (AtomicOutput), what is synced to disk and when, and the check
// of a command's outputs taken together (check_output_targets).
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <filesystem>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "core/output_detail.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/output.hpp"
#include "test_support.hpp"

namespace {

namespace fs = std::filesystem;
using rwcalc::test::gunzip;
using rwcalc::test::slurp;
using rwcalc::test::TempDir;

std::set<std::string> listing(const fs::path& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

TEST(AtomicOutput, PiecesAppearOnlyAtCommitAndWhole) {
  TempDir tmp;
  for (const std::string name : {"rec.csv", "rec.csv.gz"}) {
    const auto target = tmp.path() / name;
    std::string expected;
    {
      rwcalc::AtomicOutput out(target.string(), false);
      for (int block = 0; block < 50; ++block) {
        std::string piece;
        for (int i = 0; i < 20000; ++i) piece += std::to_string(block * 20000 + i) + "\n";
        out.write(piece);
        expected += piece;
        EXPECT_FALSE(fs::exists(target)) << "the target appeared before commit";
      }
      out.commit();
    }
    EXPECT_EQ(name == "rec.csv" ? slurp(target) : gunzip(target), expected) << name;
  }
  EXPECT_EQ(listing(tmp.path()), (std::set<std::string>{"rec.csv", "rec.csv.gz"}));
}

TEST(AtomicOutput, WithoutCommitNothingIsLeftAndTheTargetIsUnchanged) {
  TempDir tmp;
  const auto target = tmp.write("rec.csv", "old\n");
  for (const std::string name : {"rec.csv", "new.csv.gz"}) {
    try {
      rwcalc::AtomicOutput out((tmp.path() / name).string(), true);
      out.write("partial\n");
      throw std::runtime_error("the producer failed");
    } catch (const std::runtime_error&) {
    }
  }
  EXPECT_EQ(slurp(target), "old\n");
  EXPECT_EQ(listing(tmp.path()), (std::set<std::string>{"rec.csv"}));
}

// What was synced, in order: the kind, the synced file's inode, and whether the target existed.
struct Synced {
  rwcalc::detail::SyncedKind kind;
  ino_t inode;
  bool target_existed;
};
std::vector<Synced> g_synced;
fs::path g_target;

void record_sync(rwcalc::detail::SyncedKind kind, int fd) {
  struct stat st {};
  ::fstat(fd, &st);
  g_synced.push_back({kind, st.st_ino, fs::exists(g_target)});
}

TEST(AtomicOutput, TheFileIsSyncedBeforeTheRenameAndItsDirectoryAfter) {
  TempDir tmp;
  fs::create_directory(tmp.path() / "out");
  rwcalc::detail::set_sync_observer(record_sync);
  for (const std::string name : {"rec.csv", "rec.csv.gz"}) {
    g_target = tmp.path() / "out" / name;
    g_synced.clear();
    rwcalc::write_file_atomic(g_target.string(), "content\n", false);
    struct stat file {
    }, dir{};
    ASSERT_EQ(::stat(g_target.c_str(), &file), 0);
    ASSERT_EQ(::stat((tmp.path() / "out").c_str(), &dir), 0);
    ASSERT_EQ(g_synced.size(), 2u) << name;
    EXPECT_EQ(g_synced[0].kind, rwcalc::detail::SyncedKind::File) << name;
    EXPECT_EQ(g_synced[0].inode, file.st_ino) << name << ": the synced file is not the one put in place";
    EXPECT_FALSE(g_synced[0].target_existed) << name << ": synced after the rename";
    EXPECT_EQ(g_synced[1].kind, rwcalc::detail::SyncedKind::Directory) << name;
    EXPECT_EQ(g_synced[1].inode, dir.st_ino) << name << ": not the target's directory";
    EXPECT_TRUE(g_synced[1].target_existed) << name;
  }
  EXPECT_EQ(gunzip(tmp.path() / "out" / "rec.csv.gz"), "content\n");
  rwcalc::detail::set_sync_observer(nullptr);
}

TEST(CheckOutputTargets, SameFileUnderAnyNameIsAUsageError) {
  TempDir tmp;
  const auto dir = tmp.path();
  fs::create_directory(dir / "sub");
  const auto existing = tmp.write("sub/real.txt", "x");
  fs::create_symlink("sub/real.txt", dir / "link.txt");
  fs::create_symlink("sub/new.txt", dir / "dangling.txt");
  const std::vector<std::pair<std::string, std::string>> same = {
      {(dir / "a.txt").string(), (dir / "." / "a.txt").string()},
      {(dir / "a.txt").string(), (dir / "sub" / ".." / "a.txt").string()},
      {existing.string(), (dir / "link.txt").string()},
      {(dir / "sub" / "new.txt").string(), (dir / "dangling.txt").string()},
      {"-", "-"},
  };
  for (const auto& [a, b] : same)
    EXPECT_THROW(rwcalc::check_output_targets({{"-o", a}, {"--truth", b}}, true), rwcalc::UsageError) << a << " " << b;
  EXPECT_NO_THROW(rwcalc::check_output_targets(
      {{"-o", (dir / "a.txt").string()}, {"--truth", (dir / "b.txt").string()}, {"--plot", ""}, {"--plot-script", "-"}},
      false));
  EXPECT_THROW(rwcalc::check_output_targets({{"-o", (dir / "a.txt").string()}, {"--truth", existing.string()}}, false),
               rwcalc::OutputError);
  EXPECT_EQ(listing(dir), (std::set<std::string>{"sub", "link.txt", "dangling.txt"}));
}

}  // namespace
