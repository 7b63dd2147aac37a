#pragma once
// The bytes of a recording as checked text, piece by piece: a file, standard input, a pipe, a
// device or text in memory, gzip-compressed or not (told by content). Nothing holds the whole text.
#include <zlib.h>

#include <cstddef>
#include <string>
#include <string_view>

#include "rwcalc/sha256.hpp"

namespace rwcalc::detail {

/// The longest line taken, in bytes without its line end: a stream without line ends is refused
/// as soon as it passes this, so it cannot fill the memory.
constexpr std::size_t kMaxLineBytes = std::size_t{1} << 20;
/// Bytes handed out at a time; far below kMaxLineBytes. Larger pieces (2 MiB) read a day-long IMU
/// text more slowly: a piece's values no longer stay in the core's cache until they are taken.
constexpr std::size_t kPieceBytes = std::size_t{1} << 18;

/// Name used in messages for a path ("<stdin>" for "-").
std::string display_name(const std::string& path);

/// Checks text as it arrives: binary data (a control byte other than tab, LF and CR, or DEL) and
/// lines longer than kMaxLineBytes are an InputError naming the line (and the column of the byte).
/// Lines are numbered by LF, or by CR while no LF has come (classic Mac line ends).
class TextCheck {
 public:
  explicit TextCheck(std::string name) : name_(std::move(name)) {}
  void check(std::string_view piece);  ///< a piece of at most kPieceBytes

 private:
  [[nodiscard]] std::size_t line() const noexcept { return 1 + (lf_ > 0 ? lf_ : cr_); }

  std::string name_;
  std::size_t offset_ = 0, lf_ = 0, cr_ = 0;  // bytes checked, LF and CR among them
  std::size_t after_lf_ = 0, after_cr_ = 0;   // where the last LF, the last CR ends
  bool bom_ = false;                          // the text starts with a UTF-8 byte-order mark
};

/// A recording's text. Throws InputError (line 0) for a path that cannot be opened or read, a
/// directory, and corrupt or truncated gzip data, and TextCheck's errors.
class TextSource {
 public:
  explicit TextSource(const std::string& path);          ///< a file, or standard input for "-"
  TextSource(std::string_view bytes, std::string name);  ///< bytes in memory, which must outlive it
  ~TextSource();
  TextSource(const TextSource&) = delete;
  TextSource& operator=(const TextSource&) = delete;

  /// Append the next piece of checked text to `out`; false once the input has ended.
  bool read(std::string& out);
  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  /// The input's bytes as stored (compressed, for gzip) read so far, and their SHA-256: once read()
  /// has returned false, the file's size and the digest `sha256sum` prints.
  [[nodiscard]] std::size_t raw_bytes() const noexcept { return raw_total_; }
  /// The input's size as stored (compressed, for gzip); 0 when unknown (a pipe).
  [[nodiscard]] std::size_t stored_size() const noexcept { return bytes_; }
  /// The stored bytes taken so far (for gzip, inflated; raw_bytes() runs ahead by what zlib has
  /// not taken yet): how far the reading is.
  [[nodiscard]] std::size_t taken_bytes() const noexcept { return gzip_ ? raw_total_ - zs_.avail_in : raw_total_; }
  [[nodiscard]] std::string sha256() const { return hash_.hex(); }
  /// The text's likely length in bytes: the input's size, for gzip times the ratio inflated so far;
  /// 0 when unknown (a pipe). An estimate only.
  [[nodiscard]] std::size_t size_estimate() const noexcept {
    if (!gzip_) return bytes_;
    const std::size_t in = members_in_ + zs_.total_in;  // zlib counts the current member only
    return in ? static_cast<std::size_t>(static_cast<double>(bytes_) / static_cast<double>(in) *
                                         static_cast<double>(inflated_))
              : 0;
  }

 private:
  struct Descriptor {
    int fd = -1;
    bool own = false;
    ~Descriptor();
  };
  std::size_t read_raw(char* to, std::size_t max);
  bool start(std::string& out);
  bool refill();
  bool inflate_piece(std::string& out);

  std::string name_;
  Descriptor in_;
  std::string_view memory_;  // the bytes not yet read, when there is no descriptor
  std::size_t bytes_ = 0;    // the input's size, if known
  bool started_ = false, gzip_ = false;
  std::string raw_;  // compressed bytes, or the first bytes before gzip is told from text
  z_stream zs_{};
  bool in_member_ = true;       // between a gzip member's first byte and its end
  std::size_t magic_seen_ = 0;  // bytes of the next member's magic seen since a member ended
  std::size_t inflated_ = 0;    // text inflated, every member
  std::size_t members_in_ = 0;  // compressed bytes of the members ended
  TextCheck check_;
  Sha256 hash_;
  std::size_t raw_total_ = 0;
};

}  // namespace rwcalc::detail
