// The executable, run as a separate process: output that does not arrive is never a success, and
// an interrupted rwcalc leaves no temporary file behind.
// - A failed write to standard output (a full device, a closed descriptor) ends every command with
//   status 3 and a message naming standard output.
// - SIGINT or SIGTERM during a write removes the output's temporary file (.NAME.tmpXXXX) and
//   gnuplot's scratch directory (rwcalc-plot-*), and the process still ends by that signal.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "test_support.hpp"

extern char** environ;

namespace {

namespace fs = std::filesystem;
using rwcalc::test::run_cli;
using rwcalc::test::run_exe_stdout;
using rwcalc::test::TempDir;

// A short simulated record to feed the commands (10 min at 100 Hz).
fs::path make_record(const TempDir& tmp) {
  const auto path = tmp.path() / "rec.csv";
  const auto r =
      run_cli({"simulate", "-o", path.string(), "--duration", "600", "--rate", "100", "--arw", "0.05", "--seed", "3"});
  EXPECT_EQ(r.status, 0) << r.err;
  return path;
}

// ---- Standard output ----------------------------------------------------------------------------

TEST(StandardOutput, AFailedWriteIsStatusThreeForEveryCommand) {
  TempDir tmp;
  const auto rec = make_record(tmp);
  const auto lines = tmp.path() / "runs.jsonl";
  ASSERT_EQ(run_cli({"batch", rec.string(), "--jsonl", "-o", lines.string()}).status, 0);
  const std::vector<std::vector<std::string>> commands = {
      {"analyze", rec.string()},
      {"analyze", rec.string(), "--json"},
      {"analyze", rec.string(), "-o", "-"},
      {"allan", rec.string()},
      {"allan", rec.string(), "--csv"},
      {"batch", rec.string()},
      {"merge", lines.string(), "--csv"},
      {"simulate", "-o", "-", "--duration", "60", "--arw", "1"},
      {"simulate", "-o", "-", "--duration", "3600", "--arw", "1"},  // larger than any buffer
      {"simulate", "-o", (tmp.path() / "sim.csv").string(), "--duration", "60", "--arw", "1", "--force"},
      {"--help"},
  };
  for (const char* redirection : {">/dev/full", ">&-"})
    for (const auto& args : commands) {
      const auto r = run_exe_stdout(args, redirection);
      EXPECT_EQ(r.status, 3) << args[0] << " " << redirection << ": " << r.err;
      EXPECT_NE(r.err.find("standard output"), std::string::npos) << args[0] << " " << redirection << ": " << r.err;
    }
}

TEST(StandardOutput, ClosedStandardOutputNeverLandsInAnOutputFile) {
  TempDir tmp;
  const auto rec = make_record(tmp);
  const auto out = tmp.path() / "report.txt";
  const auto r = run_exe_stdout({"simulate", "-o", out.string(), "--duration", "60", "--arw", "1"}, ">&-");
  EXPECT_EQ(r.status, 3) << r.err;  // the "wrote …" line could not be written
  const auto text = rwcalc::test::slurp(out);
  EXPECT_EQ(text.find("wrote "), std::string::npos) << "the message for standard output went into the record";
}

// ---- Interrupted writes -------------------------------------------------------------------------

struct Child {
  pid_t pid = -1;
};

/// Start the executable in its own process group, with TMPDIR (and more) set, output discarded.
Child spawn_rwcalc(const std::vector<std::string>& args, const std::vector<std::string>& env_overrides) {
  std::vector<std::string> storage{RWCALC_EXE};
  storage.insert(storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& s : storage) argv.push_back(s.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_storage = env_overrides;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string entry(*e);
    const auto name = entry.substr(0, entry.find('=') + 1);
    bool overridden = false;
    for (const auto& o : env_overrides) overridden = overridden || o.rfind(name, 0) == 0;
    if (!overridden) env_storage.push_back(entry);
  }
  std::vector<char*> envp;
  for (auto& s : env_storage) envp.push_back(s.data());
  envp.push_back(nullptr);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attr, 0);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  Child c;
  const int rc = posix_spawn(&c.pid, RWCALC_EXE, &actions, &attr, argv.data(), envp.data());
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  EXPECT_EQ(rc, 0) << std::strerror(rc);
  return c;
}

/// The first entry of `dir` whose name contains `part` (searched one level down too).
std::optional<fs::path> find_entry(const fs::path& dir, const std::string& part) {
  std::error_code ec;
  for (fs::recursive_directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (it.depth() > 1) continue;
    if (it->path().filename().string().find(part) != std::string::npos) return it->path();
  }
  return std::nullopt;
}

/// Poll until `ready()` or the child ends (60 s at most). True when ready while it runs.
template <class Ready>
bool wait_until(pid_t pid, Ready ready) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    if (ready()) return true;
    int status = 0;
    if (::waitpid(pid, &status, WNOHANG) == pid) return false;  // ended before
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return false;
}

int wait_for(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return status;
}

std::vector<std::string> entries(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  return names;
}

TEST(InterruptedWrite, NoTemporaryFileIsLeftBehind) {
  for (const int sig : {SIGINT, SIGTERM}) {
    TempDir tmp;
    fs::create_directory(tmp.path() / "out");
    fs::create_directory(tmp.path() / "tmp");
    // A long compressed record: its temporary file exists for a good while.
    const auto child = spawn_rwcalc({"simulate", "-o", (tmp.path() / "out" / "rec.csv.gz").string(), "--duration",
                                     "14400", "--rate", "400", "--arw", "0.01"},
                                    {"TMPDIR=" + (tmp.path() / "tmp").string()});
    const bool seen = wait_until(child.pid, [&] { return find_entry(tmp.path() / "out", ".tmp").has_value(); });
    if (seen) ::kill(child.pid, sig);
    const int status = wait_for(child.pid);
    ASSERT_TRUE(seen) << "rwcalc ended before its temporary file was seen; the record must be longer";
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << "status " << status << ", signal " << sig;
    EXPECT_TRUE(entries(tmp.path() / "out").empty()) << "left: " << entries(tmp.path() / "out").front();
    EXPECT_TRUE(entries(tmp.path() / "tmp").empty());
  }
}

TEST(InterruptedWrite, NoGnuplotScratchDirectoryIsLeftBehind) {
  TempDir tmp;
  const auto rec = make_record(tmp);
  // A stand-in for gnuplot that answers --version and then takes its time over the figure.
  const auto fake = tmp.write("slow-gnuplot",
                              "#!/bin/sh\nif [ \"$1\" = --version ]; then echo 'gnuplot 5.4'; exit 0; fi\n"
                              "exec sleep 60\n");
  fs::permissions(fake, fs::perms::owner_all);
  for (const bool whole_group : {true, false}) {  // Ctrl-C reaches the group; kill reaches rwcalc
    const int sig = whole_group ? SIGINT : SIGTERM;
    const auto scratch = tmp.path() / (whole_group ? "tmp-int" : "tmp-term");
    fs::create_directory(scratch);
    const auto child = spawn_rwcalc({"analyze", rec.string(), "--plot", (tmp.path() / "fig.svg").string(), "--force"},
                                    {"TMPDIR=" + scratch.string(), "RWCALC_GNUPLOT=" + fake.string()});
    const bool seen = wait_until(child.pid, [&] {
      const auto dir = find_entry(scratch, "rwcalc-plot-");
      return dir && fs::exists(*dir / "figure.gp");
    });
    if (seen) ::kill(whole_group ? -child.pid : child.pid, sig);
    const int status = wait_for(child.pid);
    ::kill(-child.pid, SIGKILL);  // the stand-in, when only rwcalc was signalled
    ASSERT_TRUE(seen) << "rwcalc ended before gnuplot's scratch directory was seen";
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << "status " << status << ", signal " << sig;
    EXPECT_TRUE(entries(scratch).empty()) << "left: " << entries(scratch).front();
    EXPECT_FALSE(fs::exists(tmp.path() / "fig.svg"));
  }
}

}  // namespace
