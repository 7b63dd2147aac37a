#pragma once
/// @file output.hpp
/// Files written by rwcalc appear whole or not at all: a temporary file in the target's
/// directory is written, synced, renamed over the target, and the directory synced. An existing
/// target is replaced only with `force` and keeps its permissions (and, when permitted, owner);
/// a ".gz" target is gzip-compressed. "-" is standard output; a character device or FIFO is
/// written straight into; a symbolic link is followed (it counts as existing, dangling or not);
/// a directory, block device or socket is refused.
#include <cstddef>
#include <memory>
#include <ostream>
#include <streambuf>
#include <string>
#include <string_view>
#include <vector>

namespace rwcalc {

/// One output written in pieces: write() as often as needed, then commit(). Without commit()
/// the destructor removes the temporary file and the target stays as it was. Every failure
/// throws OutputError naming the path and the reason.
class AtomicOutput {
 public:
  AtomicOutput(const std::string& path, bool force);
  ~AtomicOutput();
  AtomicOutput(const AtomicOutput&) = delete;
  AtomicOutput& operator=(const AtomicOutput&) = delete;

  void write(std::string_view chunk);
  void commit();
  [[nodiscard]] const std::string& path() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

/// Write `content` to `path` atomically. Throws OutputError.
void write_file_atomic(const std::string& path, std::string_view content, bool force);

/// One output of a command: the option that names it (for messages) and its path (empty: none).
struct OutputTarget {
  std::string option;
  std::string path;
};

/// Checks all outputs of a command before any is written: no two name the same file (also
/// through other spellings or links) — UsageError; each can be written — OutputError.
void check_output_targets(const std::vector<OutputTarget>& targets, bool force);

/// Flush standard output; OutputError when a write to it failed (output that did not arrive is
/// never a success).
void flush_standard_output(std::ostream& out);

/// The stream buffer main() puts under std::cout: it writes to a descriptor and keeps the reason
/// of the first failed write, so that flush_standard_output can say why.
class DescriptorBuffer : public std::streambuf {
 public:
  explicit DescriptorBuffer(int fd) : fd_(fd) { setp(buffer_, buffer_ + sizeof buffer_); }
  ~DescriptorBuffer() override { (void)sync(); }
  DescriptorBuffer(const DescriptorBuffer&) = delete;
  DescriptorBuffer& operator=(const DescriptorBuffer&) = delete;
  [[nodiscard]] int error() const { return error_; }  ///< errno of the first failed write; 0: none

 protected:
  int_type overflow(int_type c) override;
  std::streamsize xsputn(const char* s, std::streamsize n) override;
  int sync() override;

 private:
  bool put(const char* data, std::size_t size);
  int fd_;
  int error_ = 0;
  char buffer_[1 << 16];
};

/// True when stderr is a terminal (progress is shown only then).
bool stderr_is_terminal();

}  // namespace rwcalc
