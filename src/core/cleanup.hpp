#pragma once
// Files and directories that must not outlive an interrupted rwcalc: the temporary file of an
// output being written, gnuplot's scratch directory. When SIGINT, SIGTERM or SIGHUP ends the
// process, a signal handler removes every path still registered (async-signal-safe calls only:
// unlink, rmdir), then re-raises the signal with its default action, so the exit status stays
// 128 + signal. A signal that is ignored or handled elsewhere when the first path is registered
// is left as it is.
#include <string>

namespace rwcalc::detail {

class RemoveOnSignal {
 public:
  enum class Kind { File, Directory };  ///< files are removed before directories
  /// Registers `path`. Best effort: a path longer than PATH_MAX, or more than the fixed number of
  /// paths at once (128), is not registered.
  RemoveOnSignal(const std::string& path, Kind kind);
  /// Unregisters; removing the path in the normal course is the owner's business.
  ~RemoveOnSignal();
  RemoveOnSignal(const RemoveOnSignal&) = delete;
  RemoveOnSignal& operator=(const RemoveOnSignal&) = delete;

 private:
  int slot_ = -1;
};

}  // namespace rwcalc::detail
