#include "rwcalc/output.hpp"

#include <fcntl.h>
#include <fmt/format.h>
#include <stdio.h>
#include <unistd.h>
#include <zlib.h>

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

bool stderr_is_terminal() { return isatty(STDERR_FILENO) != 0; }

}  // namespace rwcalc
