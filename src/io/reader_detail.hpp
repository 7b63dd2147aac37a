#pragma once
// Internal to the reader: loading raw bytes (files, stdin, gzip) and the number scanners shared by
// the fast and the careful line parsers.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace rwcalc {
class Crew;
}

namespace rwcalc::detail {

/// Bytes of a recording held in memory. Always ends with '\n' (appended when the input does not),
/// so the scanners can run without bounds checks: every field scan stops at the final newline.
/// kPadding zero bytes follow the allocation's last byte, so a scanner may load a whole 8-byte
/// word starting at any byte up to the final newline.
class TextBuffer {
 public:
  static constexpr std::size_t kPadding = 16;
  TextBuffer() = default;
  /// Buffer of `size` bytes plus room for the sentinel newline; contents uninitialised. Its pages
  /// are mapped in one call (prefault) unless map_pages is false. `spare` bytes more are allocated
  /// and never touched (see load_source).
  explicit TextBuffer(std::size_t capacity, bool map_pages = true, std::size_t spare = 0);
  /// Buffer of `capacity` bytes (plus the sentinel and the padding) ending host_capacity(capacity)
  /// elements into the storage of `host`, a vector whose capacity is made at least that first
  /// (its pages are not mapped here). A pulse file's reader then writes the 32-bit cumulative counts from
  /// the storage's start over the text it has already parsed (4 bytes per line, at most one
  /// line per 2 bytes of text, so the writes never reach a byte not yet read): one buffer's
  /// pages serve both, and `host` may be the storage of a previous record's counts, already
  /// mapped. host() gives the vector to the reader.
  TextBuffer(std::vector<std::int32_t>&& host, std::size_t capacity);
  /// The int32 elements a host vector needs for a text of `capacity` bytes (see above).
  static std::size_t host_capacity(std::size_t capacity) noexcept {
    return (2 * capacity + 2 * (1 + kPadding) + 64) / sizeof(std::int32_t) + 16;
  }
  /// The host vector while the text still lies in its storage, else null.
  [[nodiscard]] std::vector<std::int32_t>* host() noexcept {
    return host_.capacity() > 0 && !own_ ? &host_ : nullptr;
  }
  [[nodiscard]] char* data() noexcept { return data_; }
  [[nodiscard]] const char* data() const noexcept { return data_; }
  [[nodiscard]] std::size_t size() const noexcept { return size_; }
  [[nodiscard]] std::size_t capacity() const noexcept { return capacity_; }
  void set_size(std::size_t n) noexcept { size_ = n; }
  /// Grow the capacity (keeping the first size() bytes).
  void reserve(std::size_t capacity);
  /// Append the sentinel newline if the text does not already end with one.
  void terminate();
  [[nodiscard]] std::string_view view() const noexcept { return {data_, size_}; }

  /// Line ends in each whole segment of kSegment bytes from the start, when they were counted (and
  /// the segments found free of control bytes) as the file was loaded: the first
  /// segment_lines.size() segments; the reader counts the rest. Empty when not counted; to be
  /// cleared by whoever changes the bytes.
  static constexpr std::size_t kSegment = 256 * 240;
  std::vector<std::size_t> segment_lines;

 private:
  std::unique_ptr<char[]> own_;          // the bytes, when this buffer owns them
  std::vector<std::int32_t> host_;       // else the vector whose storage holds them
  char* data_ = nullptr;
  std::size_t size_ = 0;
  std::size_t capacity_ = 0;
};

/// The longest line the reader takes, in bytes (its line end not counted). A recording's lines are
/// short; a longer one is refused as soon as it has arrived this far, so that a stream without
/// line ends cannot fill the memory.
constexpr std::size_t kMaxLineBytes = std::size_t{1} << 20;

/// Checks text as it arrives, before the next chunk is read or inflated: binary data (a control
/// byte other than tab, LF and CR, or DEL) and lines longer than kMaxLineBytes are refused at once
/// with an InputError naming the file, the line and (for binary data) the column. The line ends of
/// each whole TextBuffer::kSegment it checks go to the buffer's segment_lines, so that the reader
/// does not count them again.
class ArrivalCheck {
 public:
  explicit ArrivalCheck(std::string name) : name_(std::move(name)) {}
  /// Check buf's bytes from where the last call stopped up to buf.size(). Segments the loader has
  /// already checked and counted (buf.segment_lines) are only checked for line length.
  void advance(TextBuffer& buf);

 private:
  void check_piece(const char* text, std::size_t from, std::size_t to);
  void check_line_lengths(const char* text, std::size_t from, std::size_t to);
  [[noreturn]] void fail_binary(const char* text, const char* at) const;
  [[noreturn]] void fail_long_line(const char* text, std::size_t from) const;

  std::string name_;
  std::size_t checked_ = 0;         // bytes checked so far
  std::size_t lines_ = 0;           // line ends ('\n') in them
  std::size_t segment_count_ = 0;   // line ends in the checked part of the current segment
  std::size_t line_bytes_ = 0;      // bytes of the last line so far (no line end yet)
};

/// Lines ('\n') in [b, end) and whether a control byte other than tab, LF, CR (or DEL) occurs,
/// vectorised (an AVX2 clone where the processor has it). Stops after the first block of 240
/// bytes that trips, setting `bad` to its start (else nullptr).
std::size_t count_lines_checked(const char* b, const char* end, const char*& bad);

/// Name used in messages for a path ("<stdin>" for "-").
std::string display_name(const std::string& path);

/// Read a whole file (or stdin for "-") into memory, inflating gzip data, and check the text as it
/// arrives (ArrivalCheck). Throws InputError (line 0) for a missing or unreadable path or a
/// directory and for corrupt or truncated gzip. Standard input, pipes and devices are read in
/// chunks of at most kStreamChunk, each checked (gzip: inflated and checked) before the next.
/// With threads > 1 a regular file of more than a few MB is read in two halves side by side (each
/// thread maps the pages of its half and copies it). With `host`, a regular file's text is held
/// at the end of that vector's storage (TextBuffer's second constructor: for pulse files, whose
/// counts the reader may then write over it); the vector is moved into the buffer.
TextBuffer load_source(const std::string& path, unsigned threads = 1, Crew* crew = nullptr,
                       std::vector<std::int32_t>* host = nullptr);

/// Bytes read at a time from a stream (standard input, a pipe, a device).
constexpr std::size_t kStreamChunk = std::size_t{1} << 16;

/// Copy in-memory text, inflating it when it starts with the gzip magic bytes; checked as a file is.
TextBuffer load_text(std::string_view text, const std::string& name);

/// True when the bytes start with the gzip magic 1f 8b.
bool is_gzip(std::string_view bytes) noexcept;

/// Inflate a complete gzip stream (one or more members), checking the text as it comes out
/// (ArrivalCheck). Throws InputError naming `name`.
TextBuffer inflate_gzip(std::string_view bytes, const std::string& name);

/// Ask the kernel to map the pages of a fresh buffer in one call (where supported): first-touch page
/// faults otherwise dominate reading a large recording. A hint only; failures are ignored.
void prefault(void* data, std::size_t bytes) noexcept;

/// From now on, prefault maps only the pages of the brk heap that no earlier call mapped: for a
/// process whose heap keeps freed buffers mapped (glibc with a high M_TRIM_THRESHOLD and
/// M_MMAP_THRESHOLD, as src/main.cpp sets them), so that the next file's buffers in `batch` do
/// not walk pages that are already there. A hint only, like prefault itself.
void remember_mapped_pages(bool on) noexcept;

// ---- number scanners ---------------------------------------------------------------------------

inline bool is_digit(char c) noexcept { return static_cast<unsigned char>(c - '0') < 10; }

/// Fast path for a plain integer "[-]d…d" of at most 18 digits at p. Returns the end of the number,
/// or nullptr when the text is not of that simple form (the careful parser then decides).
inline const char* scan_int_fast(const char* p, std::int64_t& out) noexcept {
  const bool neg = *p == '-';
  p += neg;
  const char* start = p;
  std::uint64_t v = 0;
  while (is_digit(*p)) {
    v = v * 10 + static_cast<std::uint64_t>(*p - '0');
    ++p;
  }
  const auto n = p - start;
  if (n == 0 || n > 18) return nullptr;
  out = neg ? -static_cast<std::int64_t>(v) : static_cast<std::int64_t>(v);
  return p;
}

/// Fast path for the commonest data line of all, one plain integer and the line end: "[-]d…d\n" or
/// "[-]d…d\r\n" with 1 to 7 digits, read eight bytes at a time without a loop over the digits
/// (p must be followed by at least 9 readable bytes: TextBuffer's padding). Gives the same value as
/// scan_int_fast. Returns the start of the next line, or nullptr for any other line.
inline const char* scan_int_line_swar(const char* p, std::int64_t& out) noexcept {
  const std::uint64_t neg = *p == '-';
  const char* q = p + neg;
  std::uint64_t w;
  std::memcpy(&w, q, sizeof w);  // little-endian: byte i is q[i]
  const std::uint64_t x = w ^ 0x3030303030303030ULL;  // digits become bytes 0..9
  // High bit of each byte that is not a digit (x ≥ 10). A carry out of a byte only happens when
  // that byte is already marked, so the lowest marked byte is always right.
  const std::uint64_t non_digit = ((x + 0x7676767676767676ULL) | x) & 0x8080808080808080ULL;
  if (non_digit == 0) return nullptr;  // 8 or more digits
  const unsigned len = static_cast<unsigned>(__builtin_ctzll(non_digit)) >> 3;
  if (len == 0) return nullptr;
  const char* e = q + len;
  const char* next = *e == '\n' ? e + 1 : (*e == '\r' && e[1] == '\n') ? e + 2 : nullptr;
  if (!next) return nullptr;
  // The digits moved to the top bytes (leading zeros below), then combined pairwise: 2, 4, 8 digits.
  std::uint64_t v = x << (64 - 8 * len);
  v = (v * 10) + (v >> 8);
  v = (((v & 0x000000FF000000FFULL) * (100 + (1000000ULL << 32))) +
       (((v >> 16) & 0x000000FF000000FFULL) * (1 + (10000ULL << 32)))) >>
      32;
  out = static_cast<std::int64_t>((v ^ (0 - neg)) + neg);
  return next;
}

/// scan_int_line_swar with a shortcut for one digit ("d\n", "-d\n"), the commonest pulse line of
/// all: no word load and no digit arithmetic. Same results as scan_int_line_swar.
inline const char* scan_int_line(const char* p, std::int64_t& out) noexcept {
  const std::uint64_t neg = *p == '-';
  const char* q = p + neg;
  const auto d = static_cast<std::uint64_t>(static_cast<unsigned char>(q[0])) - '0';
  if (d < 10 && q[1] == '\n') [[likely]] {
    out = static_cast<std::int64_t>((d ^ (0 - neg)) + neg);
    return q + 2;
  }
  return scan_int_line_swar(p, out);
}

/// Fast path for a plain decimal "[-]d…d[.d…d]" whose digits form an integer ≤ 2^53 with at most
/// 22 fraction digits (a decimal comma stands for the point when comma_ok). Then m / 10^k of two exact doubles is the correctly rounded value, the same
/// double std::from_chars gives (Clinger's fast path). Returns nullptr for anything else.
inline const char* scan_double_fast(const char* p, double& out, bool comma_ok) noexcept {
  static constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                      1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                      1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  const bool neg = *p == '-';
  p += neg;
  const char* start = p;
  std::uint64_t m = 0;
  while (is_digit(*p)) {
    m = m * 10 + static_cast<std::uint64_t>(*p - '0');
    ++p;
  }
  auto digits = p - start;
  std::ptrdiff_t frac = 0;
  if (*p == '.' || (comma_ok && *p == ',')) {
    ++p;
    const char* f = p;
    while (is_digit(*p)) {
      m = m * 10 + static_cast<std::uint64_t>(*p - '0');
      ++p;
    }
    frac = p - f;
    digits += frac;
  }
  if (digits == 0 || digits > 19 || frac > 22 || m > (std::uint64_t{1} << 53)) return nullptr;
  if (*p == 'e' || *p == 'E') return nullptr;
  const double v = static_cast<double>(m) / kPow10[frac];
  out = neg ? -v : v;
  return p;
}

}  // namespace rwcalc::detail
