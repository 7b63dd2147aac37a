#pragma once
// Running a helper program (gnuplot, a headless Chromium) from an argument vector: no shell, so
// no file name or title is ever interpreted as a command.
#include <filesystem>
#include <string>
#include <vector>

namespace rwcalc::detail {

struct ProcessResult {
  bool started = false;
  int spawn_errno = 0;
  int status = -1;  ///< exit status, or 128 + signal
  std::string err;  ///< what the process wrote to stdout and stderr
};

/// Run `command args…` with stdin from /dev/null and stdout+stderr captured in `log`; in the
/// directory `cwd` when it is not empty.
ProcessResult run_process(const std::string& command, const std::vector<std::string>& args,
                          const std::filesystem::path& log, const std::filesystem::path& cwd = {});

}  // namespace rwcalc::detail
