#pragma once
// The bytes of a recording as checked text, piece by piece: a file, standard input, a pipe, a
// device or text in memory, gzip-compressed or not (told by content). Nothing holds the whole text.
#include <zlib.h>

#include <cstddef>
#include <string>
#include <string_view>

namespace rwcalc::detail {

/// The longest line the reader takes, in bytes (its line end not counted): a stream without line
/// ends is refused as soon as it has passed this, so it cannot fill the memory.
constexpr std::size_t kMaxLineBytes = std::size_t{1} << 20;

/// Bytes of text handed out at a time; far below kMaxLineBytes.
constexpr std::size_t kPieceBytes = std::size_t{1} << 18;

/// Name used in messages for a path ("<stdin>" for "-").
std::string display_name(const std::string& path);

/// Checks text as it arrives, before the next piece is read or inflated: binary data (a control
/// byte other than tab, LF and CR, or DEL) and lines longer than kMaxLineBytes are refused with an
/// InputError naming the line (and, for binary data, the column). Lines are numbered by LF, or by
/// CR while no LF has come (classic Mac line ends); both end a line for the length limit.
class TextCheck {
 public:
  explicit TextCheck(std::string name) : name_(std::move(name)) {}
  void check(std::string_view piece);  ///< a piece of at most kPieceBytes

 private:
  void check_lengths(const char* b, const char* e);
  void count(const char* b, const char* e, std::size_t lf, std::size_t cr);
  [[nodiscard]] std::size_t line() const noexcept { return 1 + (lf_ > 0 ? lf_ : cr_); }
  [[noreturn]] void fail_binary(unsigned char byte, std::size_t at) const;

  std::string name_;
  std::size_t offset_ = 0;       // bytes checked
  std::size_t lf_ = 0, cr_ = 0;  // LF and CR among them
  std::size_t after_lf_ = 0, after_cr_ = 0;  // offset just after the last LF, the last CR
  std::size_t line_bytes_ = 0;   // bytes of the current line so far
  bool bom_ = false;             // the text starts with a UTF-8 byte-order mark
};

/// A recording's text. Throws InputError (line 0) for a path that cannot be opened or read, a
/// directory, and corrupt or truncated gzip data; TextCheck's errors as the text arrives.
class TextSource {
 public:
  explicit TextSource(const std::string& path);  ///< a file, or standard input for "-"
  TextSource(std::string_view bytes, std::string name);  ///< bytes in memory, which must outlive it
  ~TextSource();
  TextSource(const TextSource&) = delete;
  TextSource& operator=(const TextSource&) = delete;

  /// Append the next piece of checked text to `out`; false once the input has ended.
  bool read(std::string& out);
  [[nodiscard]] const std::string& name() const noexcept { return name_; }

 private:
  std::size_t read_raw(char* to, std::size_t max);
  bool refill();
  bool inflate_piece(std::string& out);
  void check_next_member();

  std::string name_;
  int fd_ = -1;
  bool own_fd_ = false;
  std::string_view memory_;
  bool from_memory_ = false;
  bool started_ = false;
  std::string raw_;  // compressed bytes, or the first bytes before gzip is told from text
  bool gzip_ = false;
  z_stream zs_{};
  bool in_member_ = true;       // between a gzip member's first byte and its end
  std::size_t magic_seen_ = 0;  // bytes of the next member's magic seen since a member ended
  std::size_t inflated_ = 0;    // bytes decompressed
  TextCheck check_;
};

}  // namespace rwcalc::detail
