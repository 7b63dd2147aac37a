// Every file rwcalc writes appears whole or not at all and never replaces an existing file without
// --force: the library call (write_file_atomic) and each command that writes (simulate records and
// truth, analyze/batch/merge -o). A refused or failed write leaves the existing file byte for byte
// as it was and no temporary file behind. What the target is decides how it is written: a device
// or FIFO is written into, a symbolic link is followed and kept, a directory, socket or block
// device is refused; a replaced file keeps its permissions; the outputs of one command are
// checked together (same file under two names, existing files) before any is written.
#include <fcntl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/un.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "rwcalc/error.hpp"
#include "rwcalc/output.hpp"
#include "test_support.hpp"

namespace {

namespace fs = std::filesystem;
using rwcalc::test::concat;
using rwcalc::test::gunzip;
using rwcalc::test::run_cli;
using rwcalc::test::slurp;
using rwcalc::test::TempDir;

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
  r = run_cli(
      {"simulate", "-o", fresh.string(), "--truth", truth.string(), "--duration", "60", "--rate", "100", "--arw", "1"});
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_FALSE(fs::exists(fresh)) << "the record was written although its truth file could not be";
  EXPECT_EQ(slurp(truth), "{}\n");

  // With --force both are replaced, and nothing else appears.
  r = run_cli({"simulate", "-o", rec.string(), "--truth", truth.string(), "--duration", "60", "--rate", "100", "--arw",
               "1", "--force"});
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

// ---- What the target is ----------------------------------------------------------------------

mode_t kind_of(const fs::path& p) {
  struct stat st {};
  EXPECT_EQ(::lstat(p.c_str(), &st), 0) << p << ": " << std::strerror(errno);
  return st.st_mode & S_IFMT;
}

std::string error_of(const std::string& path, const std::string& content, bool force) {
  try {
    rwcalc::write_file_atomic(path, content, force);
  } catch (const rwcalc::OutputError& e) {
    return e.what();
  }
  return {};
}

/// A character device like /dev/null (1,3), made in `dir`; empty when it cannot be made or used
/// here (not root, a file system mounted nodev).
std::optional<fs::path> make_null_device(const fs::path& dir) {
  const auto node = dir / "null";
  if (::geteuid() != 0 || ::mknod(node.c_str(), S_IFCHR | 0666, makedev(1, 3)) != 0) return std::nullopt;
  const int fd = ::open(node.c_str(), O_WRONLY);
  if (fd < 0) return std::nullopt;
  ::close(fd);
  return node;
}

TEST(WriteFileAtomic, WritesIntoACharacterDeviceAndLeavesItADevice) {
  TempDir tmp;
  const auto node = make_null_device(tmp.path());
  if (!node)
    GTEST_SKIP() << "a character device cannot be made here (mknod needs root and a file system without nodev)";
  for (const bool force : {false, true}) {
    rwcalc::write_file_atomic(node->string(), "discarded\n", force);
    rwcalc::write_file_atomic(node->string(), std::string(3 << 20, 'x'), force);  // larger than any buffer
    EXPECT_EQ(kind_of(*node), S_IFCHR) << "force " << force;
    EXPECT_EQ(listing(tmp.path()), (std::set<std::string>{"null"})) << "force " << force;
  }
  // The reproducer: analyze -o DEVICE --force, and without --force.
  const auto rec = make_record(tmp);
  for (const bool force : {false, true}) {
    auto args = std::vector<std::string>{"analyze", rec.string(), "-o", node->string()};
    if (force) args.push_back("--force");
    const auto r = run_cli(args);
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(kind_of(*node), S_IFCHR) << "force " << force;
  }
}

TEST(CommandOutputs, DevNullIsWrittenWithoutForce) {
  TempDir tmp;
  const auto rec = make_record(tmp);
  const auto r = run_cli({"analyze", rec.string(), "--json", "-o", "/dev/null"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(kind_of("/dev/null"), S_IFCHR);
}

/// Write `content` to the FIFO `fifo` while a reader drains it; what the reader got.
std::string through_fifo(const fs::path& fifo, const std::string& content, bool force, std::string& error) {
  // The test holds a writer end itself, so that the reader opens at once and sees the end of the
  // data only when both the test and rwcalc have closed theirs (also when rwcalc fails).
  const int keeper = ::open(fifo.c_str(), O_RDWR);
  const int reader = ::open(fifo.c_str(), O_RDONLY);
  EXPECT_GE(keeper, 0);
  EXPECT_GE(reader, 0);
  std::string got;
  std::thread drain([&] {
    char buf[65536];
    for (ssize_t n; (n = ::read(reader, buf, sizeof buf)) > 0;) got.append(buf, static_cast<std::size_t>(n));
  });
  error = error_of(fifo.string(), content, force);
  ::close(keeper);
  drain.join();
  ::close(reader);
  return got;
}

TEST(WriteFileAtomic, WritesIntoAFifoThatAReaderDrains) {
  TempDir tmp;
  const auto fifo = tmp.path() / "pipe";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  std::string content;
  for (int i = 0; i < 200000; ++i) content += std::to_string(i) + "\n";  // more than a pipe holds
  for (const bool force : {false, true}) {
    std::string error;
    const std::string got = through_fifo(fifo, content, force, error);
    EXPECT_EQ(got.size(), content.size()) << "force " << force;
    EXPECT_TRUE(got == content) << "force " << force << ": the reader got other bytes";
    EXPECT_EQ(error, "") << "force " << force;
    EXPECT_EQ(kind_of(fifo), S_IFIFO) << "force " << force;
    EXPECT_EQ(listing(tmp.path()), (std::set<std::string>{"pipe"})) << "force " << force;
  }
}

TEST(WriteFileAtomic, FollowsASymbolicLinkToARegularFileAndKeepsTheLink) {
  TempDir tmp;
  fs::create_directory(tmp.path() / "data");
  const auto real = tmp.write("data/real.txt", "old\n");
  const auto link = tmp.path() / "link.txt";
  fs::create_symlink("data/real.txt", link);
  // Without --force: refused, both as they were.
  EXPECT_NE(error_of(link.string(), "new\n", false).find("use --force"), std::string::npos);
  EXPECT_EQ(slurp(real), "old\n");
  // With --force: the link's target is replaced, in its own directory; the link stays a link.
  rwcalc::write_file_atomic(link.string(), "new\n", true);
  EXPECT_EQ(kind_of(link), S_IFLNK);
  EXPECT_EQ(fs::read_symlink(link), fs::path("data/real.txt"));
  EXPECT_EQ(slurp(real), "new\n");
  EXPECT_EQ(listing(tmp.path()), (std::set<std::string>{"data", "link.txt"}));
  EXPECT_EQ(listing(tmp.path() / "data"), (std::set<std::string>{"real.txt"}));
}

TEST(WriteFileAtomic, ADanglingSymbolicLinkNeedsForceAndThenGetsItsTarget) {
  TempDir tmp;
  fs::create_directory(tmp.path() / "data");
  const auto link = tmp.path() / "link.txt";
  fs::create_symlink("data/new.txt", link);
  const auto message = error_of(link.string(), "content\n", false);
  EXPECT_NE(message.find("use --force"), std::string::npos) << message;
  EXPECT_NE(message.find("link.txt"), std::string::npos) << message;
  EXPECT_TRUE(listing(tmp.path() / "data").empty());
  rwcalc::write_file_atomic(link.string(), "content\n", true);
  EXPECT_EQ(kind_of(link), S_IFLNK);
  EXPECT_EQ(slurp(tmp.path() / "data" / "new.txt"), "content\n");
  EXPECT_EQ(listing(tmp.path() / "data"), (std::set<std::string>{"new.txt"}));
}

TEST(WriteFileAtomic, RefusesDirectoriesSocketsAndBlockDevicesWithAndWithoutForce) {
  TempDir tmp;
  std::vector<std::pair<fs::path, std::string>> refused;  // path, the kind named in the message
  fs::create_directory(tmp.path() / "dir");
  refused.emplace_back(tmp.path() / "dir", "directory");
  fs::create_directory_symlink("dir", tmp.path() / "dirlink");
  refused.emplace_back(tmp.path() / "dirlink", "directory");
  const auto sock_path = tmp.path() / "sock";
  const int sock = ::socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  ASSERT_LT(sock_path.string().size(), sizeof addr.sun_path);
  std::strcpy(addr.sun_path, sock_path.c_str());
  ASSERT_EQ(::bind(sock, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0) << std::strerror(errno);
  refused.emplace_back(sock_path, "socket");
  if (::geteuid() == 0 && ::mknod((tmp.path() / "block").c_str(), S_IFBLK | 0600, makedev(7, 200)) == 0)
    refused.emplace_back(tmp.path() / "block", "block device");
  const auto before = listing(tmp.path());
  for (const auto& [path, kind] : refused)
    for (const bool force : {false, true}) {
      const auto kind_before = kind_of(path);
      const auto message = error_of(path.string(), "x", force);
      EXPECT_NE(message.find(path.string()), std::string::npos) << message;
      EXPECT_NE(message.find(kind), std::string::npos) << message;
      EXPECT_EQ(kind_of(path), kind_before) << path;
    }
  EXPECT_EQ(listing(tmp.path()), before);
  EXPECT_TRUE(listing(tmp.path() / "dir").empty());
  ::close(sock);
}

// ---- A replaced file keeps its permissions (and owner) ---------------------------------------

TEST(WriteFileAtomic, ReplacingKeepsThePermissionsAndOwnerOfTheReplacedFile) {
  TempDir tmp;
  for (const mode_t mode : {0600u, 0640u, 0444u, 0755u}) {
    const auto target = tmp.write("out.txt", "old\n");
    fs::permissions(target, static_cast<fs::perms>(mode));
    rwcalc::write_file_atomic(target.string(), "new\n", true);
    struct stat st {};
    ASSERT_EQ(::stat(target.c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 07777, mode) << std::oct << "was " << mode << ", now " << (st.st_mode & 07777);
    EXPECT_EQ(slurp(target), "new\n");
    fs::remove(target);
  }
  // Through a symbolic link, and the .gz form.
  const auto real = tmp.write("real.csv.gz", "old");
  fs::permissions(real, static_cast<fs::perms>(0600));
  fs::create_symlink("real.csv.gz", tmp.path() / "link.csv.gz");
  rwcalc::write_file_atomic((tmp.path() / "link.csv.gz").string(), "new\n", true);
  struct stat st {};
  ASSERT_EQ(::stat(real.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0600u);
  if (::geteuid() == 0) {
    const auto owned = tmp.write("owned.txt", "old\n");
    ASSERT_EQ(::chown(owned.c_str(), 4321, 4322), 0) << std::strerror(errno);
    rwcalc::write_file_atomic(owned.string(), "new\n", true);
    ASSERT_EQ(::stat(owned.c_str(), &st), 0);
    EXPECT_EQ(st.st_uid, 4321u);
    EXPECT_EQ(st.st_gid, 4322u);
  }
}

TEST(CommandOutputs, ForceKeepsThePermissionsOfTheReplacedOutput) {
  TempDir tmp;
  const auto rec = make_record(tmp);
  const auto out = tmp.write("private.txt", "previous\n");
  fs::permissions(out, static_cast<fs::perms>(0600));
  const auto r = run_cli({"analyze", rec.string(), "-o", out.string(), "--force"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(slurp(out), "previous\n");
  EXPECT_EQ(fs::status(out).permissions(), static_cast<fs::perms>(0600));
}

// ---- .gz outputs read back whole ---------------------------------------------------------------

TEST(WriteFileAtomic, GzipTargetsReadBackWholeNewAndReplaced) {
  TempDir tmp;
  std::string content;
  for (int i = 0; i < 300000; ++i) content += std::to_string(static_cast<long long>(i) * 7919 % 100003) + "\n";
  const auto gz = tmp.path() / "rec.csv.gz";
  rwcalc::write_file_atomic(gz.string(), content, false);
  EXPECT_EQ(gunzip(gz), content);
  rwcalc::write_file_atomic(gz.string(), "short\n", true);
  EXPECT_EQ(gunzip(gz), "short\n");
  EXPECT_EQ(listing(tmp.path()), (std::set<std::string>{"rec.csv.gz"}));
}

// ---- All outputs of a command are checked together before any is written ---------------------

void expect_refused(const std::vector<std::string>& args, int status, const fs::path& dir,
                    const std::set<std::string>& before, const std::string& fragment) {
  const auto r = run_cli(args);
  EXPECT_EQ(r.status, status) << args[0] << ": " << r.err;
  EXPECT_NE(r.err.find(fragment), std::string::npos) << r.err;
  EXPECT_EQ(listing(dir), before) << args[0] << " wrote a file although one of its outputs was refused";
}

TEST(CommandOutputs, TwoOutputsNamingTheSameFileAreRefusedBeforeAnyIsWritten) {
  TempDir tmp;
  const auto rec = make_record(tmp);
  fs::create_directory(tmp.path() / "out");
  const auto dir = tmp.path() / "out";
  const std::string a = (dir / "a.svg").string();
  const std::string dotted = (dir / "." / "a.svg").string();
  const auto before = listing(dir);
  for (const std::string cmd : {"analyze", "batch", "diagnose"}) {
    std::vector<std::string> base{cmd, rec.string()};
    if (cmd == "diagnose") base = concat(base, {"--runs", "10"});
    expect_refused(concat(base, {"-o", a, "--plot", a}), 2, dir, before, "same file");
    expect_refused(concat(base, {"-o", a, "--plot-script", dotted}), 2, dir, before, "same file");
    expect_refused(concat(base, {"--plot", a, "--plot-script", dotted, "--force"}), 2, dir, before, "same file");
  }
  expect_refused({"simulate", "-o", a, "--truth", dotted, "--duration", "60", "--arw", "1"}, 2, dir, before,
                 "same file");
  expect_refused({"simulate", "-o", a, "--truth", a, "--runs", "2", "--duration", "60", "--arw", "1"}, 2, dir, before,
                 "same file");
  expect_refused({"simulate", "-o", "-", "--truth", "-", "--duration", "60", "--arw", "1"}, 2, dir, before,
                 "same file");

  // One existing file under two names (a symbolic link), with --force: still the same file.
  const auto real = tmp.write("out/real.txt", "keep\n");
  fs::create_symlink("real.txt", dir / "link.txt");
  const auto with_link = listing(dir);
  expect_refused({"analyze", rec.string(), "-o", real.string(), "--plot-script", (dir / "link.txt").string(),
                  "--force"},
                 2, dir, with_link, "same file");
  expect_refused({"simulate", "-o", (dir / "link.txt").string(), "--truth", real.string(), "--force", "--duration",
                  "60", "--arw", "1"},
                 2, dir, with_link, "same file");
  EXPECT_EQ(slurp(real), "keep\n");
}

TEST(CommandOutputs, AnExistingOutputStopsEveryOutputOfTheCommand) {
  TempDir tmp;
  const auto rec = make_record(tmp);
  fs::create_directory(tmp.path() / "out");
  const auto dir = tmp.path() / "out";
  const auto existing = tmp.write("out/existing.txt", "keep\n");
  const auto before = listing(dir);
  for (const std::string cmd : {"analyze", "batch", "diagnose"}) {
    std::vector<std::string> base{cmd, rec.string()};
    if (cmd == "diagnose") base = concat(base, {"--runs", "10"});
    // The existing file is the report; the new figure script must not be written either.
    expect_refused(concat(base, {"-o", existing.string(), "--plot-script", (dir / "new.gp").string()}), 3, dir, before,
                   "use --force");
    expect_refused(concat(base, {"-o", (dir / "new.txt").string(), "--plot-script", existing.string()}), 3, dir, before,
                   "use --force");
  }
  expect_refused({"simulate", "-o", (dir / "new.csv").string(), "--truth", existing.string(), "--duration", "60",
                  "--arw", "1"},
                 3, dir, before, "use --force");
  EXPECT_EQ(slurp(existing), "keep\n");
}

TEST(CommandOutputs, ReportRefusesItsOutputBeforeTheAnalysisAndFollowsALink) {
  TempDir tmp;
  const auto rec = make_record(tmp);
  const auto dir = tmp.path() / "rep";
  fs::create_directory(dir);
  fs::create_directory(dir / "report.html");  // a directory where the report should go
  auto r = run_cli({"report", rec.string(), "-o", dir.string(), "--no-figures", "--force"});
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("is a directory"), std::string::npos) << r.err;
  fs::remove(dir / "report.html");
  // report.html as a link to a file elsewhere: needs --force, then the link's target is written.
  const auto real = tmp.write("kept.html", "old\n");
  fs::create_symlink(real, dir / "report.html");
  r = run_cli({"report", rec.string(), "-o", dir.string(), "--no-figures"});
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_EQ(slurp(real), "old\n");
  r = run_cli({"report", rec.string(), "-o", dir.string(), "--no-figures", "--force"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(kind_of(dir / "report.html"), S_IFLNK);
  EXPECT_NE(slurp(real).find("<html"), std::string::npos);
}

}  // namespace
