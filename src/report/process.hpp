#pragma once
// Running a helper program (gnuplot, a headless Chromium) from an argument vector: no shell, so
// no file name or title is ever interpreted as a command. Each helper runs in a process group of
// its own, within a time limit, and neither it, what it started, nor its scratch directory
// outlives rwcalc (core/cleanup.hpp).
#include <fmt/format.h>

#include <filesystem>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rwcalc/cleanup.hpp"

namespace rwcalc::detail {

struct ProcessResult {
  bool started = false;
  int spawn_errno = 0;
  int status = -1;         ///< exit status, or 128 + signal
  bool timed_out = false;  ///< stopped at the time limit (status is then that of the stop)
  std::string err;         ///< what the process wrote to stdout and stderr
};

/// The time a helper may take, s: RWCALC_HELPER_TIMEOUT when set (a positive number; anything
/// else is a UsageError), else 300.
double helper_timeout_s();

/// The helper program named by the environment variable `env` when it is set and not empty, else
/// the first of `names` found executable in PATH; empty when none.
std::string find_program(const char* env, std::initializer_list<const char*> names);

/// Run `command args…` with stdin from /dev/null and stdout+stderr captured in `log`; in the
/// directory `cwd` when it is not empty. The helper leads a new process group. One still running
/// after `timeout_s` is stopped: SIGTERM to its group, SIGKILL 2 s later. Once it has ended,
/// anything it left running in its group is killed.
ProcessResult run_process(const std::string& command, const std::vector<std::string>& args,
                          const std::filesystem::path& log, const std::filesystem::path& cwd = {},
                          double timeout_s = helper_timeout_s());

/// A private temporary directory NAME-XXXXXX under TMPDIR, removed with everything in it when the
/// object goes, and by the signal handler when a signal ends rwcalc.
class ScratchDir {
 public:
  /// `failure`: the message (a msgid with one {} for the reason) of the OutputError thrown when
  /// the directory cannot be made.
  ScratchDir(std::string_view name, fmt::format_string<std::string> failure);
  ~ScratchDir();
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  std::optional<RemoveOnSignal> on_signal_;
};

}  // namespace rwcalc::detail
