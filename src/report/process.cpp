// Helper programs: spawned in their own process group, waited for within a time limit, their
// group ended afterwards; their scratch directories.
#include "process.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>

#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"

extern char** environ;

namespace rwcalc::detail {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

constexpr double kDefaultTimeoutS = 300;
constexpr auto kGrace = std::chrono::seconds(2);  // between SIGTERM and SIGKILL

// Wait for `pid` until `deadline`; true once it has ended (its wait status in `wstatus`, -1 when
// it could not be waited for).
bool wait_until(pid_t pid, Clock::time_point deadline, int& wstatus) {
  auto pause = std::chrono::microseconds(500);
  for (;;) {
    const pid_t got = waitpid(pid, &wstatus, WNOHANG);
    if (got == pid) return true;
    if (got < 0 && errno != EINTR) {
      wstatus = -1;
      return true;
    }
    const auto now = Clock::now();
    if (now >= deadline) return false;
    std::this_thread::sleep_for(std::min<Clock::duration>(pause, deadline - now));
    pause = std::min(pause * 2, std::chrono::microseconds(50000));
  }
}

// SIGTERM to the group, then SIGKILL when it has not ended after the grace period.
void stop(pid_t pid, int& wstatus) {
  (void)kill(-pid, SIGTERM);
  if (wait_until(pid, Clock::now() + kGrace, wstatus)) return;
  (void)kill(-pid, SIGKILL);
  while (waitpid(pid, &wstatus, 0) < 0 && errno == EINTR) {
  }
}

// Attributes of the child: its own process group; the signals rwcalc handles or ignores back at
// their default actions, none blocked.
struct SpawnAttributes {
  posix_spawnattr_t attr{};
  SpawnAttributes() {
    posix_spawnattr_init(&attr);
    sigset_t defaults, none;
    sigemptyset(&defaults);
    for (const int sig : {SIGINT, SIGTERM, SIGHUP, SIGXFSZ, SIGPIPE}) sigaddset(&defaults, sig);
    sigemptyset(&none);
    posix_spawnattr_setsigdefault(&attr, &defaults);
    posix_spawnattr_setsigmask(&attr, &none);
    posix_spawnattr_setpgroup(&attr, 0);
    posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK);
  }
  ~SpawnAttributes() { posix_spawnattr_destroy(&attr); }
  SpawnAttributes(const SpawnAttributes&) = delete;
  SpawnAttributes& operator=(const SpawnAttributes&) = delete;
};

}  // namespace

double helper_timeout_s() {
  const char* env = std::getenv("RWCALC_HELPER_TIMEOUT");
  if (env == nullptr || *env == '\0') return kDefaultTimeoutS;
  char* end = nullptr;
  const double s = std::strtod(env, &end);
  if (*end != '\0' || !std::isfinite(s) || !(s > 0) || s > 1e6)
    throw UsageError(trf("RWCALC_HELPER_TIMEOUT must be a number of seconds in (0, 1e6], got '{}'", env));
  return s;
}

ProcessResult run_process(const std::string& command, const std::vector<std::string>& args, const fs::path& log,
                          const fs::path& cwd, double timeout_s) {
  ProcessResult r;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  if (!cwd.empty()) posix_spawn_file_actions_addchdir_np(&actions, cwd.c_str());
  // A relative command path names a file from our directory, not from `cwd`.
  std::error_code ec;
  const auto absolute = fs::absolute(command, ec);
  std::vector<std::string> storage{!cwd.empty() && command.find('/') != std::string::npos && !ec ? absolute.string()
                                                                                                 : command};
  storage.insert(storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  argv.reserve(storage.size() + 1);
  for (auto& s : storage) argv.push_back(s.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const SpawnAttributes spawn;
  const int rc = posix_spawnp(&pid, storage.front().c_str(), &actions, &spawn.attr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) {
    r.spawn_errno = rc;
    return r;
  }
  r.started = true;
  const EndOnSignal on_signal(pid);
  int wstatus = -1;
  const auto limit = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_s));
  if (!wait_until(pid, Clock::now() + limit, wstatus)) {
    r.timed_out = true;
    stop(pid, wstatus);
  }
  (void)kill(-pid, SIGKILL);    // whatever the helper left running in its group
  if (wstatus == -1) return r;  // status -1
  r.status = WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : 128 + WTERMSIG(wstatus);
  std::ifstream in(log, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  r.err = ss.str();
  return r;
}

ScratchDir::ScratchDir(std::string_view name, fmt::format_string<std::string> failure) {
  std::string templ = (fs::temp_directory_path() / (std::string(name) + "XXXXXX")).string();
  if (mkdtemp(templ.data()) == nullptr) throw OutputError(trf(failure, std::string(std::strerror(errno))));
  path_ = templ;
  on_signal_.emplace(path_.string(), RemoveOnSignal::Kind::Tree);
}

ScratchDir::~ScratchDir() {
  std::error_code ec;
  fs::remove_all(path_, ec);
}

}  // namespace rwcalc::detail

namespace rwcalc::detail {

std::string find_program(const char* env, std::initializer_list<const char*> names) {
  if (const char* named = std::getenv(env); named && *named) return named;
  const char* path = std::getenv("PATH");
  if (!path) return {};
  const std::string dirs = path;
  for (const char* name : names)
    for (std::size_t at = 0; at <= dirs.size();) {
      const std::size_t end = std::min(dirs.find(':', at), dirs.size());
      const fs::path candidate = fs::path(dirs.substr(at, end - at)) / name;
      if (end > at && access(candidate.c_str(), X_OK) == 0) return candidate.string();
      at = end + 1;
    }
  return {};
}

}  // namespace rwcalc::detail
