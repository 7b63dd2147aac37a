#pragma once
/// @file output.hpp
/// Files written by rwcalc appear whole or not at all: content goes to a temporary file in the
/// target directory, is flushed, and is renamed over the target. An existing target is replaced
/// only with `force`. A ".gz" target is gzip-compressed.
#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>

namespace rwcalc {

/// Write `content` to `path` atomically. "-" writes to standard output. Throws OutputError.
void write_file_atomic(const std::string& path, std::string_view content, bool force);

/// A file written piece by piece under the rules of write_file_atomic: the pieces go to a
/// temporary file in the target directory (gzip-compressed for a ".gz" target), and commit()
/// flushes, syncs and renames it over the target (an existing one only with `force`). Until
/// commit() the target is untouched; an object destroyed uncommitted (an error, an exception)
/// removes its temporary file, so the output appears whole or not at all. "-" writes the pieces
/// to standard output as they come. write_file_atomic(p, c, f) is AtomicOutput(p, f), write(c),
/// commit(). Every member throws OutputError.
class AtomicOutput {
 public:
  /// Checks the target (not a directory; absent unless `force`; its directory exists) and
  /// opens the temporary file.
  AtomicOutput(const std::string& path, bool force);
  ~AtomicOutput();
  AtomicOutput(const AtomicOutput&) = delete;
  AtomicOutput& operator=(const AtomicOutput&) = delete;

  void write(std::string_view chunk);
  void commit();

 private:
  void discard() noexcept;
  std::string path_;
  std::filesystem::path tmp_;
  bool force_ = false;
  bool to_stdout_ = false;
  bool done_ = false;
  int fd_ = -1;            // the temporary file (kept open for the final fsync)
  std::FILE* plain_ = nullptr;
  void* gz_ = nullptr;     // gzFile on a duplicate of fd_ (zlib.h stays out of this header)
};

/// True when stderr is a terminal (progress is shown only then).
bool stderr_is_terminal();

}  // namespace rwcalc
