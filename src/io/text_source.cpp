// Reading a recording's bytes in pieces: read(2) on a descriptor (regular file, standard input,
// pipe, device) or slices of text in memory; gzip data inflated piece by piece. Each piece is
// checked (TextCheck) before the next is read, so that binary data or an endless line is refused
// before more of it is read, and memory follows the samples the reader keeps, not the text.
#include "io/text_source.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include <fmt/format.h>

#include "rwcalc/error.hpp"

namespace rwcalc::detail {

namespace {

bool is_control(unsigned char c) noexcept { return (c < 0x20 && c != '\t' && c != '\n' && c != '\r') || c == 0x7f; }

// Line ends (LF, CR) in [b, e) up to the first control byte, which `bad` is set to (else null):
// one pass in blocks without branches, which the compiler can vectorise.
void scan(const char* b, const char* e, std::size_t& lf, std::size_t& cr, const char*& bad) noexcept {
  constexpr std::ptrdiff_t kBlock = 64;
  bad = nullptr;
  for (; e - b >= kBlock; b += kBlock) {
    unsigned char trip = 0, n = 0, r = 0;
    for (std::ptrdiff_t i = 0; i < kBlock; ++i) {
      const auto c = static_cast<unsigned char>(b[i]);
      trip |= static_cast<unsigned char>(((c < 0x20) & (c != '\t') & (c != '\n') & (c != '\r')) | (c == 0x7f));
      n = static_cast<unsigned char>(n + (c == '\n'));
      r = static_cast<unsigned char>(r + (c == '\r'));
    }
    if (trip) break;
    lf += n;
    cr += r;
  }
  for (; b < e; ++b) {
    if (is_control(static_cast<unsigned char>(*b))) {
      bad = b;
      return;
    }
    lf += *b == '\n';
    cr += *b == '\r';
  }
}

// The first line end (LF or CR) in [b, e), or null.
const char* first_line_end(const char* b, const char* e) noexcept {
  const auto* lf = static_cast<const char*>(std::memchr(b, '\n', static_cast<std::size_t>(e - b)));
  const auto* cr = static_cast<const char*>(std::memchr(b, '\r', static_cast<std::size_t>((lf ? lf : e) - b)));
  return cr ? cr : lf;
}

// The last line end (LF or CR) in [b, e), or null.
const char* last_line_end(const char* b, const char* e) noexcept {
  const auto* lf = static_cast<const char*>(::memrchr(b, '\n', static_cast<std::size_t>(e - b)));
  const char* after = lf ? lf + 1 : b;
  const auto* cr = static_cast<const char*>(::memrchr(after, '\r', static_cast<std::size_t>(e - after)));
  return cr ? cr : lf;
}

[[noreturn]] void fail_errno(const std::string& name, const char* what, int err) {
  throw InputError(name, 0, std::string(what) + ": " + std::strerror(err));
}

}  // namespace

std::string display_name(const std::string& path) { return path == "-" ? "<stdin>" : path; }

void TextCheck::check(std::string_view piece) {
  const char* b = piece.data();
  const char* e = b + piece.size();
  if (offset_ < 3) {  // the byte-order mark may arrive in pieces
    static constexpr unsigned char kBom[3] = {0xEF, 0xBB, 0xBF};
    const std::size_t n = std::min<std::size_t>(3 - offset_, piece.size());
    bool same = offset_ == 0 || bom_;
    for (std::size_t i = 0; i < n; ++i) same = same && static_cast<unsigned char>(b[i]) == kBom[offset_ + i];
    bom_ = same;
  }
  std::size_t lf = 0, cr = 0;
  const char* bad = nullptr;
  scan(b, e, lf, cr, bad);
  check_lengths(b, bad ? bad : e);
  count(b, bad ? bad : e, lf, cr);
  if (bad) fail_binary(static_cast<unsigned char>(*bad), offset_ + static_cast<std::size_t>(bad - b));
  offset_ += piece.size();
}

// [b, e) is shorter than kMaxLineBytes: only the line that began before it and the one that runs
// on past it can be too long, and the first is the line holding b.
void TextCheck::check_lengths(const char* b, const char* e) {
  const char* first = first_line_end(b, e);
  const std::size_t reach = line_bytes_ + static_cast<std::size_t>((first ? first : e) - b);
  if (reach > kMaxLineBytes)
    throw InputError(name_, line(),
                     fmt::format("line too long: more than {} bytes (1 MiB) without a line end; this is not a "
                                 "text recording",
                                 kMaxLineBytes));
  line_bytes_ = first ? static_cast<std::size_t>(e - (last_line_end(first, e) + 1)) : reach;
}

void TextCheck::count(const char* b, const char* e, std::size_t lf, std::size_t cr) {
  lf_ += lf;
  cr_ += cr;
  const auto n = static_cast<std::size_t>(e - b);
  if (const auto* p = static_cast<const char*>(::memrchr(b, '\n', n))) after_lf_ = offset_ + static_cast<std::size_t>(p - b) + 1;
  if (const auto* p = static_cast<const char*>(::memrchr(b, '\r', n))) after_cr_ = offset_ + static_cast<std::size_t>(p - b) + 1;
}

void TextCheck::fail_binary(unsigned char byte, std::size_t at) const {
  // The line starts after the last LF, or the last CR while no LF has come; a byte-order mark
  // before the first line is not one of its columns.
  std::size_t start = lf_ > 0 ? after_lf_ : cr_ > 0 ? after_cr_ : 0;
  if (start == 0 && bom_ && at >= 3) start = 3;
  throw InputError(name_, line(),
                   fmt::format("binary data (byte 0x{:02x} at column {}): this is not a text recording; a "
                               "compressed file other than gzip?",
                               byte, at - start + 1));
}

TextSource::TextSource(const std::string& path) : name_(display_name(path)), check_(name_) {
  if (path == "-") {
    fd_ = STDIN_FILENO;
    return;
  }
  if (path.empty()) throw InputError("(empty path)", 0, "no input file given");
  fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd_ < 0) fail_errno(name_, "cannot open", errno);
  own_fd_ = true;
  struct stat st {};
  if (::fstat(fd_, &st) != 0) {
    const int err = errno;
    ::close(fd_);
    fail_errno(name_, "cannot stat", err);
  }
  if (S_ISDIR(st.st_mode)) {
    ::close(fd_);
    throw InputError(name_, 0, "is a directory, not a recording");
  }
}

TextSource::TextSource(std::string_view bytes, std::string name)
    : name_(std::move(name)), memory_(bytes), from_memory_(true), check_(name_) {}

TextSource::~TextSource() {
  if (gzip_) inflateEnd(&zs_);
  if (own_fd_) ::close(fd_);
}

// Up to `max` raw bytes into `to`; 0 at the end of the input.
std::size_t TextSource::read_raw(char* to, std::size_t max) {
  if (from_memory_) {
    const std::size_t n = std::min(max, memory_.size());
    std::memcpy(to, memory_.data(), n);
    memory_.remove_prefix(n);
    return n;
  }
  for (;;) {
    const ssize_t n = ::read(fd_, to, max);
    if (n >= 0) return static_cast<std::size_t>(n);
    if (errno != EINTR) fail_errno(name_, "cannot read", errno);
  }
}

bool TextSource::read(std::string& out) {
  if (!started_) {  // the first two bytes tell gzip from text
    started_ = true;
    raw_.resize(kPieceBytes);
    std::size_t n = 0;
    for (std::size_t k = 1; n < 2 && k > 0; n += k) k = read_raw(raw_.data() + n, kPieceBytes - n);
    raw_.resize(n);
    gzip_ = n >= 2 && static_cast<unsigned char>(raw_[0]) == 0x1f && static_cast<unsigned char>(raw_[1]) == 0x8b;
    if (gzip_) {
      // 16 + MAX_WBITS: the gzip wrapper only.
      if (inflateInit2(&zs_, 16 + MAX_WBITS) != Z_OK) throw InputError(name_, 0, "cannot initialise zlib");
      zs_.next_in = reinterpret_cast<Bytef*>(raw_.data());
      zs_.avail_in = static_cast<uInt>(raw_.size());
    } else if (n > 0) {
      check_.check(raw_);
      out += raw_;
      return true;
    }
  }
  if (gzip_) return inflate_piece(out);
  const std::size_t before = out.size();
  out.resize(before + kPieceBytes);
  const std::size_t n = read_raw(out.data() + before, kPieceBytes);
  out.resize(before + n);
  check_.check(std::string_view(out).substr(before));
  return n > 0;
}

// More compressed input into raw_; false at the end of the input.
bool TextSource::refill() {
  raw_.resize(kPieceBytes);
  raw_.resize(read_raw(raw_.data(), kPieceBytes));
  zs_.next_in = reinterpret_cast<Bytef*>(raw_.data());
  zs_.avail_in = static_cast<uInt>(raw_.size());
  return !raw_.empty();
}

// Inflate up to kPieceBytes of text onto `out` (one or more gzip members, as `cat a.gz b.gz`
// makes them); false once the data have ended.
bool TextSource::inflate_piece(std::string& out) {
  const std::size_t before = out.size();
  out.resize(before + kPieceBytes);
  zs_.next_out = reinterpret_cast<Bytef*>(out.data() + before);
  zs_.avail_out = static_cast<uInt>(kPieceBytes);
  bool ended = false;
  while (zs_.avail_out > 0 && !ended) {
    if (zs_.avail_in == 0 && !refill()) {
      if (in_member_ || magic_seen_ > 0)
        throw InputError(name_, 0,
                         fmt::format("truncated gzip data: the compressed stream ends before its end marker ({} "
                                     "bytes decompressed); the file is incomplete",
                                     inflated_ + (kPieceBytes - zs_.avail_out)));
      ended = true;
      break;
    }
    if (!in_member_) check_next_member();
    const int rc = inflate(&zs_, Z_NO_FLUSH);
    if (rc == Z_STREAM_END) {
      inflateReset(&zs_);
      in_member_ = false;
      magic_seen_ = 0;
    } else if (rc != Z_OK && rc != Z_BUF_ERROR) {  // Z_BUF_ERROR: more input is needed
      throw InputError(name_, 0, std::string("corrupt gzip data: ") + (zs_.msg ? zs_.msg : "inflate failed"));
    }
  }
  const std::size_t n = kPieceBytes - zs_.avail_out;
  out.resize(before + n);
  inflated_ += n;
  check_.check(std::string_view(out).substr(before));
  return n > 0 || !ended;
}

// After a member's end only another member may follow: its magic bytes, which may arrive split
// between two reads.
void TextSource::check_next_member() {
  static constexpr unsigned char kMagic[2] = {0x1f, 0x8b};
  for (uInt i = 0; magic_seen_ < 2 && i < zs_.avail_in; ++i, ++magic_seen_)
    if (zs_.next_in[i] != kMagic[magic_seen_])
      throw InputError(name_, 0, "unexpected bytes after the end of the gzip data");
  if (magic_seen_ == 2) in_member_ = true;
}

}  // namespace rwcalc::detail
