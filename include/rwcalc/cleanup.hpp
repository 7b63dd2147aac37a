#pragma once
// What must not outlive an interrupted rwcalc: an output's temporary file, a helper's scratch
// directory, a helper program (gnuplot, Chromium) and the processes it started. On SIGINT, SIGTERM
// or SIGHUP a handler kills every registered process group (SIGKILL) and reaps its leader, removes
// every path still registered (unlink, rmdir, and a tree walked with openat/getdents64/unlinkat:
// async-signal-safe calls only), then re-raises the signal with its default action, so the exit
// status stays 128 + signal. A signal ignored or handled elsewhere is left so. SIGXFSZ, when it has
// its default action, is ignored once the first path is registered: a write beyond the file-size
// limit (ulimit -f) then fails with EFBIG, an output error that removes the temporary file.
#include <sys/types.h>

#include <string>

namespace rwcalc::detail {

class RemoveOnSignal {
 public:
  /// Files are removed first, then trees (a directory and everything in it), then directories.
  enum class Kind { File, Directory, Tree };
  /// Best effort: a path beyond PATH_MAX, or beyond 128 paths at once, is not registered.
  RemoveOnSignal(const std::string& path, Kind kind);
  ~RemoveOnSignal();  ///< unregisters; removing the path in the normal course is the owner's job
  RemoveOnSignal(const RemoveOnSignal&) = delete;
  RemoveOnSignal& operator=(const RemoveOnSignal&) = delete;

 private:
  int slot_ = -1;
};

/// A child that leads its own process group: on a signal the whole group is killed and the child
/// reaped before the paths are removed (so that nothing writes into them any more).
class EndOnSignal {
 public:
  /// Best effort: beyond 16 groups at once, one is not registered.
  explicit EndOnSignal(pid_t group);
  ~EndOnSignal();  ///< unregisters; ending the group in the normal course is the owner's job
  EndOnSignal(const EndOnSignal&) = delete;
  EndOnSignal& operator=(const EndOnSignal&) = delete;

 private:
  pid_t group_;
  int slot_ = -1;
};

}  // namespace rwcalc::detail
