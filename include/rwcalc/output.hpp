#pragma once
/// @file output.hpp
/// Files written by rwcalc appear whole or not at all: content goes to a temporary file in the
/// target's directory, is flushed and synced, renamed over the target, and the directory is
/// synced. An existing target is replaced only with `force`; the new file keeps the replaced
/// file's permissions (and, when permitted, its owner). A ".gz" target is gzip-compressed.
///
/// What the target is decides how it is written:
/// - "-": standard output.
/// - a character device or a FIFO (/dev/null, /dev/stdout, a named pipe): written straight into,
///   without a temporary file and without `force` (nothing is replaced);
/// - a symbolic link: followed; its final target is written by the rules here (a regular file is
///   replaced by a rename in the target's directory, so the link stays a link). The link counts
///   as an existing file, dangling or not: it needs `force`, and a dangling link's target is
///   then created;
/// - a directory, block device, socket: refused.
#include <memory>
#include <cstddef>
#include <ostream>
#include <streambuf>
#include <string>
#include <string_view>
#include <vector>

namespace rwcalc {

/// One output being written, in pieces: the streaming form of write_file_atomic.
///
///     AtomicOutput out(path, force);   // checks the target, opens the temporary file
///     out.write(chunk); …              // as many pieces as needed
///     out.commit();                    // flush, sync, rename into place, sync the directory
///
/// Without commit() (an exception, an early return) the destructor removes the temporary file
/// and the target stays as it was. A device, FIFO or standard output receives the pieces as
/// they come (there is nothing to take back). Every failure throws OutputError naming the
/// path and the reason.
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

/// Write `content` to `path` atomically. "-" writes to standard output. Throws OutputError.
void write_file_atomic(const std::string& path, std::string_view content, bool force);

/// One output of a command: the option that names it (for messages) and its path.
struct OutputTarget {
  std::string option;  ///< e.g. "-o", "--plot", "--truth"
  std::string path;    ///< empty: not asked for
};

/// Check all outputs of one command before any is written, so that a refused one leaves nothing
/// written: no two name the same file (also as different spellings or through symbolic links;
/// two "-" both mean standard output) — UsageError; each can be written as the rules above say
/// (existing without `force`, a directory, a missing directory…) — OutputError.
void check_output_targets(const std::vector<OutputTarget>& targets, bool force);

/// Flush `out` (standard output) and throw OutputError naming standard output when a write to
/// it failed (a full device, a closed descriptor): output that did not arrive is never a success.
void flush_standard_output(std::ostream& out);

/// The stream buffer main() puts under std::cout: it writes to a file descriptor and keeps the
/// reason of the first failed write, so that flush_standard_output can say why (a stream only
/// knows that something failed).
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
