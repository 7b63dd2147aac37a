#include "rwcalc/output.hpp"
#include "rwcalc/i18n.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <stdio.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <optional>
#include <random>

#include "output_detail.hpp"
#include "rwcalc/cleanup.hpp"
#include "rwcalc/error.hpp"

namespace rwcalc {

namespace fs = std::filesystem;

namespace detail {
namespace {
std::atomic<SyncObserver> g_sync_observer{nullptr};
}
void set_sync_observer(SyncObserver observer) { g_sync_observer.store(observer); }
}  // namespace detail

namespace {

std::string reason(int err) { return std::strerror(err); }

/// How the content reaches its target.
enum class Sink {
  Stdout,   ///< "-"
  Stream,   ///< a character device or FIFO, written straight into
  Replace,  ///< a temporary file renamed over (or into) the target
};

struct Plan {
  Sink sink = Sink::Replace;
  fs::path target;                 ///< the file written: a symbolic link's final target
  std::optional<struct stat> old;  ///< the regular file replaced, if any
};

/// The final target of a chain of symbolic links (which may not exist: a dangling link).
fs::path follow_links(const std::string& path) {
  fs::path p = path;
  for (int hops = 0; hops < 40; ++hops) {
    struct stat st {};
    if (::lstat(p.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return p;
    std::error_code ec;
    const fs::path next = fs::read_symlink(p, ec);
    if (ec) throw OutputError(trf("{}: cannot read the symbolic link {}: {}", path, p.string(), ec.message()));
    p = next.is_absolute() ? next : p.parent_path() / next;
  }
  throw OutputError(trf("{}: cannot follow the symbolic links: {}", path, reason(ELOOP)));
}

void require_directory_of(const std::string& path, const fs::path& target) {
  fs::path dir = target.parent_path();
  if (dir.empty()) dir = ".";
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw OutputError(trf("{}: directory {} does not exist", path, dir.string()));
}

/// What kind of file a non-regular target is, for the refusal.
std::string kind_name(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

/// Where the content of `path` goes, or why it cannot (OutputError); the rules are in output.hpp.
Plan plan_output(const std::string& path, bool force) {
  if (path == "-") return {Sink::Stdout, path, std::nullopt};
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) {
    if (errno != ENOENT) throw OutputError(trf("{}: cannot examine the target: {}", path, reason(errno)));
    require_directory_of(path, path);
    return {Sink::Replace, path, std::nullopt};
  }
  const bool link = S_ISLNK(st.st_mode);
  if (link && ::stat(path.c_str(), &st) != 0) {
    if (errno != ENOENT) throw OutputError(trf("{}: cannot follow the symbolic link: {}", path, reason(errno)));
    const fs::path final_target = follow_links(path);
    if (!force)
      throw OutputError(trf("{}: exists (a symbolic link to the missing {}); use --force to create that file", path,
                            final_target.string()));
    require_directory_of(path, final_target);
    return {Sink::Replace, final_target, std::nullopt};
  }
  if (S_ISCHR(st.st_mode) || S_ISFIFO(st.st_mode)) return {Sink::Stream, path, std::nullopt};
  if (!S_ISREG(st.st_mode))
    throw OutputError(
        trf("{}: is {}; rwcalc writes regular files, character devices and FIFOs only", path, kind_name(st.st_mode)));
  if (!force) throw OutputError(trf("{}: exists; use --force to overwrite it", path));
  return {Sink::Replace, link ? follow_links(path) : fs::path(path), st};
}

/// fsync `fd`, tell the test seam, and throw OutputError with `what` on failure.
void sync_or_throw(int fd, detail::SyncedKind kind, const std::string& path, const char* what) {
  if (::fsync(fd) != 0) throw OutputError(trf("{}: cannot sync {} to disk: {}", path, what, reason(errno)));
  if (auto observer = detail::g_sync_observer.load()) observer(kind, fd);
}

/// Sync the directory that holds `target`, so that the rename itself survives a crash.
void sync_directory(const fs::path& target, const std::string& path) {
  fs::path dir = target.parent_path();
  if (dir.empty()) dir = ".";
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0)
    throw OutputError(trf("{}: cannot open its directory {} to sync it: {}", path, dir.string(), reason(errno)));
  // Some file systems cannot sync a directory (EINVAL): nothing more can be done there.
  if (::fsync(fd) != 0 && errno != EINVAL) {
    const int err = errno;
    ::close(fd);
    throw OutputError(
        trf("{}: written, but its directory {} could not be synced: {}", path, dir.string(), reason(err)));
  }
  if (auto observer = detail::g_sync_observer.load()) observer(detail::SyncedKind::Directory, fd);
  ::close(fd);
}

void write_all(int fd, std::string_view data, const std::string& path) {
  while (!data.empty()) {
    const ssize_t n = ::write(fd, data.data(), data.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw OutputError(trf("{}: write failed: {}", path, reason(errno)));
    data.remove_prefix(static_cast<std::size_t>(n));
  }
}

}  // namespace

struct AtomicOutput::State {
  std::string path;
  Plan plan;
  bool force = false;
  fs::path tmp;                                     ///< Sink::Replace only
  std::optional<detail::RemoveOnSignal> on_signal;  ///< the temporary file, while it exists
  int fd = -1;  ///< the temporary file, the device or FIFO; for gzip, a duplicate kept to sync
  gzFile gz = nullptr;
  std::string buffer;  ///< plain output collects small pieces into large writes
  bool committed = false;

  void open_target();
  void flush_buffer() {
    write_all(fd, buffer, path);
    buffer.clear();
  }
  void finish_writing();
  void move_into_place();
  void discard() noexcept;
};

void AtomicOutput::State::open_target() {
  if (plan.sink == Sink::Stream) {
    fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd < 0) throw OutputError(trf("{}: cannot open for writing: {}", path, reason(errno)));
  } else {
    std::random_device rd;
    const fs::path name =
        plan.target.parent_path() / fmt::format(".{}.tmp{:08x}", plan.target.filename().string(), rd());
    on_signal.emplace(name.string(), detail::RemoveOnSignal::Kind::File);  // before it exists
    fd = ::open(name.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0) throw OutputError(trf("{}: cannot write: {}", path, reason(errno)));
    tmp = name;  // ours from here on: removed unless committed
    if (plan.old) {
      // The replacement keeps the replaced file's permissions (not the set-id bits) and, where the
      // system allows it (root), its owner.
      if (plan.old->st_uid != ::geteuid() || plan.old->st_gid != ::getegid())
        (void)::fchown(fd, plan.old->st_uid, plan.old->st_gid);
      if (::fchmod(fd, plan.old->st_mode & 01777) != 0)
        throw OutputError(trf("{}: cannot keep the permissions of the replaced file: {}", path, reason(errno)));
    }
  }
  if (path.ends_with(".gz")) {
    // zlib takes over one descriptor and closes it; the other stays open to sync the finished file.
    const int own = ::dup(fd);
    if (own < 0 || (gz = gzdopen(own, "wb6")) == nullptr) {
      if (own >= 0) ::close(own);
      throw OutputError(trf("{}: cannot start the compressed stream: {}", path, reason(errno ? errno : ENOMEM)));
    }
  }
}

void AtomicOutput::State::finish_writing() {
  if (gz != nullptr) {
    const int rc = gzclose(gz);
    gz = nullptr;
    if (rc != Z_OK) throw OutputError(trf("{}: compressed write failed (zlib error {})", path, rc));
  } else {
    flush_buffer();
  }
  if (plan.sink == Sink::Replace) sync_or_throw(fd, detail::SyncedKind::File, path, "the written file");
  const int rc = ::close(fd);
  fd = -1;
  if (rc != 0) throw OutputError(trf("{}: write failed: {}", path, reason(errno)));
}

void AtomicOutput::State::move_into_place() {
  const fs::path& target = plan.target;
  if (!force) {
    // Without --force the target must still be absent at the moment of the rename (it may have
    // appeared while the content was written): move into place only if nothing is there.
    if (::renameat2(AT_FDCWD, tmp.c_str(), AT_FDCWD, target.c_str(), RENAME_NOREPLACE) == 0) return;
    const int err = errno;
    if (err == EEXIST) throw OutputError(trf("{}: exists; use --force to overwrite it", path));
    if (err != EINVAL && err != ENOSYS)  // else: the file system cannot refuse; plain rename below
      throw OutputError(trf("{}: cannot move the finished file into place: {}", path, reason(err)));
  }
  if (::rename(tmp.c_str(), target.c_str()) != 0)
    throw OutputError(trf("{}: cannot move the finished file into place: {}", path, reason(errno)));
}

void AtomicOutput::State::discard() noexcept {
  if (gz != nullptr) gzclose(gz);
  gz = nullptr;
  if (fd >= 0) ::close(fd);
  fd = -1;
  if (!tmp.empty()) ::unlink(tmp.c_str());
  on_signal.reset();
}

AtomicOutput::AtomicOutput(const std::string& path, bool force) : state_(std::make_unique<State>()) {
  state_->path = path;
  state_->force = force;
  state_->plan = plan_output(path, force);
  if (state_->plan.sink == Sink::Stdout) return;
  try {
    state_->open_target();
  } catch (...) {
    state_->discard();
    throw;
  }
}

AtomicOutput::~AtomicOutput() {
  if (!state_->committed) state_->discard();
}

void AtomicOutput::write(std::string_view chunk) {
  State& s = *state_;
  if (s.committed) throw OutputError(trf("{}: written after it was finished", s.path));
  if (s.plan.sink == Sink::Stdout) {
    std::cout.write(chunk.data(), static_cast<std::streamsize>(chunk.size()));
    return;
  }
  if (s.gz != nullptr) {
    while (!chunk.empty()) {
      const auto n = static_cast<unsigned>(std::min<std::size_t>(chunk.size(), 1u << 30));
      if (gzwrite(s.gz, chunk.data(), n) != static_cast<int>(n)) {
        int zerr = Z_OK;
        const char* msg = gzerror(s.gz, &zerr);
        throw OutputError(
            trf("{}: compressed write failed: {}", s.path, zerr == Z_ERRNO ? reason(errno) : std::string(msg)));
      }
      chunk.remove_prefix(n);
    }
    return;
  }
  constexpr std::size_t kBuffer = 1 << 20;
  if (s.buffer.size() + chunk.size() > kBuffer) s.flush_buffer();
  if (chunk.size() >= kBuffer)
    write_all(s.fd, chunk, s.path);
  else
    s.buffer.append(chunk);
}

void AtomicOutput::commit() {
  State& s = *state_;
  if (s.committed) return;
  if (s.plan.sink != Sink::Stdout) s.finish_writing();
  if (s.plan.sink == Sink::Replace) {
    s.move_into_place();
    s.tmp.clear();  // renamed: nothing to remove any more
    s.on_signal.reset();
  }
  s.committed = true;
  if (s.plan.sink == Sink::Stdout) flush_standard_output(std::cout);
  if (s.plan.sink == Sink::Replace) sync_directory(s.plan.target, s.path);
}

const std::string& AtomicOutput::path() const { return state_->path; }

void write_file_atomic(const std::string& path, std::string_view content, bool force) {
  AtomicOutput out(path, force);
  out.write(content);
  out.commit();
}

namespace {

/// What identifies the file a target names: device and inode when it exists, else its absolute
/// path with "." and ".." and the symbolic links of its directories resolved.
std::string identity_of(const fs::path& file) {
  struct stat st {};
  if (::stat(file.c_str(), &st) == 0) return fmt::format("inode {}:{}", st.st_dev, st.st_ino);
  std::error_code ec;
  const fs::path p = fs::weakly_canonical(fs::absolute(file, ec), ec);
  return "path " + (ec ? fs::absolute(file).lexically_normal().string() : p.string());
}

}  // namespace

void check_output_targets(const std::vector<OutputTarget>& targets, bool force) {
  std::vector<std::pair<std::string, const OutputTarget*>> seen;
  for (const auto& t : targets) {
    if (t.path.empty()) continue;
    // With force here, so that two names of one existing file are reported as the same file
    // rather than as "exists".
    const Plan plan = plan_output(t.path, true);
    const std::string id = plan.sink == Sink::Stdout ? std::string("standard output") : identity_of(plan.target);
    for (const auto& [other_id, other] : seen)
      if (other_id == id)
        throw UsageError(
            t.path == other->path
                ? trf("{} and {} name the same file '{}'", other->option, t.option, t.path)
                : trf("{} '{}' and {} '{}' are the same file", other->option, other->path, t.option, t.path));
    seen.emplace_back(id, &t);
  }
  for (const auto& t : targets)
    if (!t.path.empty()) (void)plan_output(t.path, force);
}

bool DescriptorBuffer::put(const char* data, std::size_t size) {
  while (size > 0 && error_ == 0) {
    const ssize_t n = ::write(fd_, data, size);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) error_ = errno;
    if (n <= 0) break;
    data += n;
    size -= static_cast<std::size_t>(n);
  }
  return error_ == 0 && size == 0;
}

int DescriptorBuffer::sync() {
  const bool ok = put(pbase(), static_cast<std::size_t>(pptr() - pbase()));
  setp(buffer_, buffer_ + sizeof buffer_);
  return ok ? 0 : -1;
}

DescriptorBuffer::int_type DescriptorBuffer::overflow(int_type c) {
  if (sync() != 0) return traits_type::eof();
  if (traits_type::eq_int_type(c, traits_type::eof())) return traits_type::not_eof(c);
  *pptr() = traits_type::to_char_type(c);
  pbump(1);
  return c;
}

std::streamsize DescriptorBuffer::xsputn(const char* s, std::streamsize n) {
  if (n < epptr() - pptr()) {
    std::memcpy(pptr(), s, static_cast<std::size_t>(n));
    pbump(static_cast<int>(n));
    return n;
  }
  // A large piece goes straight out after what is buffered.
  if (sync() != 0 || !put(s, static_cast<std::size_t>(n))) return 0;
  return n;
}

void flush_standard_output(std::ostream& out) {
  errno = 0;
  out.flush();
  bool failed = !out;
  int err = errno;
  if (const auto* own = dynamic_cast<const DescriptorBuffer*>(out.rdbuf())) {
    failed = failed || own->error() != 0;
    if (own->error() != 0) err = own->error();
  } else if (&out == &std::cout) {
    // std::cout left on C's stdout: its error flag and buffer are the real state.
    errno = 0;
    if (std::fflush(stdout) != 0 || std::ferror(stdout) != 0) {
      failed = true;
      if (errno != 0) err = errno;
    }
  }
  if (!failed) return;
  throw OutputError(trf("standard output: write failed: {}",
                        err != 0 ? reason(err) : std::string(tr("the stream reported an error"))));
}

bool stderr_is_terminal() { return isatty(STDERR_FILENO) != 0; }

}  // namespace rwcalc
