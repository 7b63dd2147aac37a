// The executable, run as a separate process: output that does not arrive is never a success, and
// an interrupted rwcalc leaves no temporary file behind.
// - A failed write to standard output (a full device, a closed descriptor) ends every command with
//   status 3 and a message naming standard output.
// - SIGINT or SIGTERM during a write removes the output's temporary file (.NAME.tmpXXXX) and
//   gnuplot's scratch directory (rwcalc-plot-*), and the process still ends by that signal.
// - A file-size limit (ulimit -f) is an output error (status 3), not SIGXFSZ with the temporary
//   file left behind.
// - A helper program (the headless Chromium of report --pdf) that hangs is stopped at its timeout;
//   a signal to rwcalc ends the helper's whole process group; neither leaves a scratch directory.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
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
using rwcalc::test::slurp;
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

// ---- Limits and helper programs ------------------------------------------------------------------

std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

/// `sh -c 'SETUP; exec env ENV… rwcalc ARGS…'`, standard error kept in `tmp`/err.
rwcalc::test::CliResult run_shell(const TempDir& tmp, const std::string& setup, const std::vector<std::string>& env,
                                  const std::vector<std::string>& args) {
  std::string cmd = setup + "; exec env";
  for (const auto& e : env) cmd += " " + shell_quote(e);
  cmd += " " + shell_quote(RWCALC_EXE);
  for (const auto& a : args) cmd += " " + shell_quote(a);
  cmd +=
      " </dev/null >" + shell_quote((tmp.path() / "out").string()) + " 2>" + shell_quote((tmp.path() / "err").string());
  const int rc = std::system(("sh -c " + shell_quote(cmd)).c_str());
  rwcalc::test::CliResult r;
  r.status = WIFEXITED(rc) ? WEXITSTATUS(rc) : 128 + WTERMSIG(rc);
  r.out = slurp(tmp.path() / "out");
  r.err = slurp(tmp.path() / "err");
  return r;
}

TEST(InterruptedWrite, AFileSizeLimitIsAnOutputErrorAndLeavesNoTemporaryFile) {
  TempDir tmp;
  fs::create_directory(tmp.path() / "records");
  const auto out = (tmp.path() / "records" / "rec.csv").string();
  // A 1-h record at 400 Hz is megabytes; the limit is 64 blocks.
  const auto r = run_shell(tmp, "ulimit -f 64", {},
                           {"simulate", "-o", out, "--duration", "3600", "--rate", "400", "--arw", "0.01"});
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("rwcalc: error: " + out), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("File too large"), std::string::npos) << r.err;
  EXPECT_TRUE(entries(tmp.path() / "records").empty()) << "left: " << entries(tmp.path() / "records").front();
}

/// True while process `pid` exists and is not a zombie.
bool alive(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string text;
  if (!std::getline(stat, text)) return false;
  const auto paren = text.rfind(')');
  return paren != std::string::npos && paren + 2 < text.size() && text[paren + 2] != 'Z';
}

/// The pid written in `file`, or -1.
pid_t pid_in(const fs::path& file) {
  std::ifstream in(file);
  long pid = -1;
  return in >> pid ? static_cast<pid_t>(pid) : -1;
}

/// True once neither process is alive (within 10 s).
bool both_gone(pid_t a, pid_t b) {
  for (int i = 0; i < 1000; ++i) {
    if (!alive(a) && !alive(b)) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

/// A stand-in for Chromium that fills its profile directory like the real one, starts a child of
/// its own, writes both pids into `pids`, and then hangs.
fs::path hanging_chromium(const TempDir& tmp, const fs::path& pids) {
  fs::create_directory(pids);
  const auto script =
      tmp.write("hanging-chromium",
                "#!/bin/sh\n"
                "for a in \"$@\"; do case \"$a\" in --user-data-dir=*) d=\"${a#--user-data-dir=}\";; esac; done\n"
                "mkdir -p \"$d/Default/Cache\" && echo cached >\"$d/Default/Cache/data_0\"\n"
                "sleep 30 &\n"
                "echo $! >" +
                    shell_quote((pids / "child").string()) +
                    "\n"
                    "echo $$ >" +
                    shell_quote((pids / "helper").string()) +
                    "\n"
                    "wait\n");
  fs::permissions(script, fs::perms::owner_all);
  return script;
}

TEST(HelperProcesses, AHangingChromiumIsStoppedAtItsTimeoutWithItsChildren) {
  TempDir tmp;
  const auto rec = make_record(tmp);
  const auto pids = tmp.path() / "pids";
  const auto chromium = hanging_chromium(tmp, pids);
  fs::create_directory(tmp.path() / "tmp");
  const auto start = std::chrono::steady_clock::now();
  const auto r = run_shell(tmp, "true",
                           {"RWCALC_CHROMIUM=" + chromium.string(), "RWCALC_HELPER_TIMEOUT=2",
                            "TMPDIR=" + (tmp.path() / "tmp").string()},
                           {"report", rec.string(), "-o", (tmp.path() / "report").string(), "--no-figures", "--pdf"});
  const auto seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_NE(r.err.find("did not finish within 2 s"), std::string::npos) << r.err;
  EXPECT_LT(seconds, 20) << "the helper was not stopped at its timeout";
  EXPECT_TRUE(both_gone(pid_in(pids / "helper"), pid_in(pids / "child"))) << "the helper's processes still run";
  EXPECT_TRUE(entries(tmp.path() / "tmp").empty()) << "left: " << entries(tmp.path() / "tmp").front();
  EXPECT_FALSE(fs::exists(tmp.path() / "report" / "report.pdf"));
}

TEST(HelperProcesses, ASignalEndsTheHelpersProcessGroupAndRemovesItsScratchDirectory) {
  TempDir tmp;
  const auto rec = make_record(tmp);
  for (const bool whole_group : {true, false}) {  // Ctrl-C reaches rwcalc's group; kill reaches rwcalc
    const int sig = whole_group ? SIGINT : SIGTERM;
    const auto pids = tmp.path() / (whole_group ? "pids-int" : "pids-term");
    const auto chromium = hanging_chromium(tmp, pids);
    const auto scratch = tmp.path() / (whole_group ? "tmp-int" : "tmp-term");
    fs::create_directory(scratch);
    const auto child = spawn_rwcalc({"report", rec.string(), "-o", (tmp.path() / "report").string(), "--no-figures",
                                     "--pdf", "--force"},
                                    {"TMPDIR=" + scratch.string(), "RWCALC_CHROMIUM=" + chromium.string()});
    const bool seen = wait_until(child.pid, [&] { return fs::exists(pids / "helper"); });
    if (seen) ::kill(whole_group ? -child.pid : child.pid, sig);
    const int status = wait_for(child.pid);
    ASSERT_TRUE(seen) << "rwcalc ended before the helper started";
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig) << "status " << status << ", signal " << sig;
    const pid_t helper = pid_in(pids / "helper"), grandchild = pid_in(pids / "child");
    EXPECT_TRUE(both_gone(helper, grandchild)) << "the helper's processes still run";
    for (const pid_t p : {helper, grandchild})
      if (p > 0 && alive(p)) ::kill(p, SIGKILL);
    EXPECT_TRUE(entries(scratch).empty()) << "left: " << entries(scratch).front();
    EXPECT_FALSE(fs::exists(tmp.path() / "report" / "report.pdf"));
  }
}

}  // namespace
