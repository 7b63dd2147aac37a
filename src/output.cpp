#include "rwcalc/output.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <stdio.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <random>

#include "rwcalc/error.hpp"

namespace rwcalc {

namespace fs = std::filesystem;

namespace {

bool ends_with(std::string_view s, std::string_view suffix) {
  return s.size() >= suffix.size() && s.substr(s.size() - suffix.size()) == suffix;
}

void write_plain(const fs::path& tmp, std::string_view content, const std::string& target) {
  std::FILE* f = std::fopen(tmp.c_str(), "wb");
  if (!f) throw OutputError(fmt::format("{}: cannot write: {}", target, std::strerror(errno)));
  const bool ok = std::fwrite(content.data(), 1, content.size(), f) == content.size();
  const bool flushed = std::fflush(f) == 0 && fsync(fileno(f)) == 0;
  const bool closed = std::fclose(f) == 0;
  if (!ok || !flushed || !closed) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw OutputError(fmt::format("{}: write failed: {}", target, std::strerror(errno)));
  }
}

void write_gzip(const fs::path& tmp, std::string_view content, const std::string& target) {
  gzFile g = gzopen(tmp.c_str(), "wb6");
  if (!g) throw OutputError(fmt::format("{}: cannot write: {}", target, std::strerror(errno)));
  std::size_t done = 0;
  bool ok = true;
  while (done < content.size() && ok) {
    const auto chunk = static_cast<unsigned>(std::min<std::size_t>(content.size() - done, 1u << 30));
    ok = gzwrite(g, content.data() + done, chunk) == static_cast<int>(chunk);
    done += chunk;
  }
  if (gzclose(g) != Z_OK || !ok) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw OutputError(fmt::format("{}: compressed write failed", target));
  }
}

}  // namespace

void write_file_atomic(const std::string& path, std::string_view content, bool force) {
  if (path == "-") {
    std::cout.write(content.data(), static_cast<std::streamsize>(content.size()));
    std::cout.flush();
    return;
  }
  const fs::path target(path);
  std::error_code ec;
  if (fs::is_directory(target, ec))
    throw OutputError(fmt::format("{}: is a directory", path));
  if (fs::exists(target, ec) && !force)
    throw OutputError(fmt::format("{}: exists; use --force to overwrite it", path));
  fs::path dir = target.parent_path();
  if (dir.empty()) dir = ".";
  if (!fs::is_directory(dir, ec))
    throw OutputError(fmt::format("{}: directory {} does not exist", path, dir.string()));
  std::random_device rd;
  const fs::path tmp = dir / fmt::format(".{}.tmp{:08x}", target.filename().string(), rd());
  if (ends_with(path, ".gz"))
    write_gzip(tmp, content, path);
  else
    write_plain(tmp, content, path);
  if (!force) {
    // Without --force the target must still be absent at the moment of the rename (it may have
    // appeared while the content was written): move into place only if nothing is there.
    if (::renameat2(AT_FDCWD, tmp.c_str(), AT_FDCWD, target.c_str(), RENAME_NOREPLACE) == 0) return;
    const int err = errno;
    if (err == EEXIST) {
      std::error_code ec2;
      fs::remove(tmp, ec2);
      throw OutputError(fmt::format("{}: exists; use --force to overwrite it", path));
    }
    if (err != EINVAL && err != ENOSYS) {  // else: the file system cannot refuse; plain rename below
      std::error_code ec2;
      fs::remove(tmp, ec2);
      throw OutputError(fmt::format("{}: cannot move the finished file into place: {}", path, std::strerror(err)));
    }
  }
  fs::rename(tmp, target, ec);
  if (ec) {
    std::error_code ec2;
    fs::remove(tmp, ec2);
    throw OutputError(fmt::format("{}: cannot move the finished file into place: {}", path, ec.message()));
  }
}

namespace {

// Rename the finished temporary file over the target; without `force` only if the target is
// still absent at that moment (renameat2 RENAME_NOREPLACE where the file system supports it).
// On failure the temporary file is removed.
void move_into_place(const fs::path& tmp, const std::string& path, bool force) {
  const fs::path target(path);
  std::error_code ec;
  if (!force) {
    if (::renameat2(AT_FDCWD, tmp.c_str(), AT_FDCWD, target.c_str(), RENAME_NOREPLACE) == 0) return;
    const int err = errno;
    if (err == EEXIST) {
      fs::remove(tmp, ec);
      throw OutputError(fmt::format("{}: exists; use --force to overwrite it", path));
    }
    if (err != EINVAL && err != ENOSYS) {
      fs::remove(tmp, ec);
      throw OutputError(fmt::format("{}: cannot move the finished file into place: {}", path, std::strerror(err)));
    }
  }
  fs::rename(tmp, target, ec);
  if (ec) {
    std::error_code ec2;
    fs::remove(tmp, ec2);
    throw OutputError(fmt::format("{}: cannot move the finished file into place: {}", path, ec.message()));
  }
}

}  // namespace

AtomicOutput::AtomicOutput(const std::string& path, bool force) : path_(path), force_(force) {
  if (path == "-") {
    to_stdout_ = true;
    return;
  }
  const fs::path target(path);
  std::error_code ec;
  if (fs::is_directory(target, ec)) throw OutputError(fmt::format("{}: is a directory", path));
  if (fs::exists(target, ec) && !force) throw OutputError(fmt::format("{}: exists; use --force to overwrite it", path));
  fs::path dir = target.parent_path();
  if (dir.empty()) dir = ".";
  if (!fs::is_directory(dir, ec)) throw OutputError(fmt::format("{}: directory {} does not exist", path, dir.string()));
  std::random_device rd;
  tmp_ = dir / fmt::format(".{}.tmp{:08x}", target.filename().string(), rd());
  fd_ = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd_ < 0) {
    const int err = errno;
    tmp_.clear();
    done_ = true;
    throw OutputError(fmt::format("{}: cannot write: {}", path, std::strerror(err)));
  }
  // The stream gets its own descriptor, so that fd_ stays open for the fsync after it is closed.
  const int stream_fd = ::dup(fd_);
  if (stream_fd >= 0) {
    if (ends_with(path, ".gz"))
      gz_ = gzdopen(stream_fd, "wb6");
    else
      plain_ = ::fdopen(stream_fd, "wb");
  }
  if (!gz_ && !plain_) {
    const int err = errno;
    if (stream_fd >= 0) ::close(stream_fd);
    discard();
    throw OutputError(fmt::format("{}: cannot write: {}", path, std::strerror(err)));
  }
}

AtomicOutput::~AtomicOutput() {
  if (!done_) discard();
}

void AtomicOutput::discard() noexcept {
  if (gz_) gzclose(static_cast<gzFile>(gz_));
  if (plain_) std::fclose(plain_);
  if (fd_ >= 0) ::close(fd_);
  gz_ = nullptr;
  plain_ = nullptr;
  fd_ = -1;
  std::error_code ec;
  if (!tmp_.empty()) fs::remove(tmp_, ec);
  done_ = true;
}

void AtomicOutput::write(std::string_view chunk) {
  if (done_) throw OutputError(fmt::format("{}: written after it was finished or abandoned", path_));
  if (to_stdout_) {
    std::cout.write(chunk.data(), static_cast<std::streamsize>(chunk.size()));
    if (!std::cout) throw OutputError(fmt::format("{}: cannot write to standard output", path_));
    return;
  }
  bool ok = true;
  if (gz_) {
    for (std::size_t done = 0; done < chunk.size() && ok;) {
      const auto piece = static_cast<unsigned>(std::min<std::size_t>(chunk.size() - done, 1u << 30));
      ok = gzwrite(static_cast<gzFile>(gz_), chunk.data() + done, piece) == static_cast<int>(piece);
      done += piece;
    }
  } else {
    ok = std::fwrite(chunk.data(), 1, chunk.size(), plain_) == chunk.size();
  }
  if (!ok) {
    const int err = errno;
    discard();
    throw OutputError(fmt::format("{}: write failed: {}", path_, std::strerror(err)));
  }
}

void AtomicOutput::commit() {
  if (done_) throw OutputError(fmt::format("{}: finished twice or after it was abandoned", path_));
  if (to_stdout_) {
    std::cout.flush();
    done_ = true;
    if (!std::cout) throw OutputError(fmt::format("{}: cannot write to standard output", path_));
    return;
  }
  bool ok = gz_ ? gzclose(static_cast<gzFile>(gz_)) == Z_OK : std::fclose(plain_) == 0;
  gz_ = nullptr;
  plain_ = nullptr;
  ok = ok && ::fsync(fd_) == 0;
  const int err = errno;
  ok = ::close(fd_) == 0 && ok;
  fd_ = -1;
  if (!ok) {
    discard();
    throw OutputError(fmt::format("{}: write failed: {}", path_, std::strerror(err)));
  }
  done_ = true;
  move_into_place(tmp_, path_, force_);
}

bool stderr_is_terminal() { return isatty(STDERR_FILENO) != 0; }

}  // namespace rwcalc
