#pragma once
// Files and directories that must not outlive an interrupted rwcalc (an output's temporary file,
// gnuplot's scratch directory). On SIGINT, SIGTERM or SIGHUP a handler removes every path still
// registered (unlink, rmdir: async-signal-safe), then re-raises the signal with its default
// action, so the exit status stays 128 + signal. A signal ignored or handled elsewhere is left so.
#include <string>

namespace rwcalc::detail {

class RemoveOnSignal {
 public:
  enum class Kind { File, Directory };  ///< files are removed before directories
  /// Best effort: a path beyond PATH_MAX, or beyond 128 paths at once, is not registered.
  RemoveOnSignal(const std::string& path, Kind kind);
  ~RemoveOnSignal();  ///< unregisters; removing the path in the normal course is the owner's job
  RemoveOnSignal(const RemoveOnSignal&) = delete;
  RemoveOnSignal& operator=(const RemoveOnSignal&) = delete;

 private:
  int slot_ = -1;
};

}  // namespace rwcalc::detail
