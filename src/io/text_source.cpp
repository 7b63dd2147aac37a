// A recording's bytes in pieces: read(2) on a descriptor (file, standard input, pipe, device) or
// slices of text in memory, gzip inflated piece by piece. Each piece is checked before the next is
// read: binary data or an endless line is refused before more of it is read.
#include "text_source.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>

#include <fmt/format.h>

#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"

namespace rwcalc::detail {

namespace {

// The first control byte other than tab, LF and CR (or DEL) in [b, e), else null: blocks are
// tested without a branch first, which the compiler vectorises.
const char* first_control(const char* b, const char* e) noexcept {
  auto control = [](char ch) {
    const auto c = static_cast<unsigned char>(ch);
    return ((c < 0x20) & (c != '\t') & (c != '\n') & (c != '\r')) | (c == 0x7f);
  };
  for (; e - b >= 64; b += 64) {
    unsigned char trip = 0;
    for (int i = 0; i < 64; ++i) trip |= static_cast<unsigned char>(control(b[i]));
    if (trip) break;
  }
  const char* bad = std::find_if(b, e, control);
  return bad == e ? nullptr : bad;
}

// How many bytes of [b, e) are c: counted in 8-bit lanes over stretches of 255 bytes (so no lane
// overflows), which the compiler vectorises without widening every comparison to 64 bits.
std::size_t count_byte(const char* b, const char* e, char c) noexcept {
  std::size_t total = 0;
  while (b < e) {
    const auto len = std::min<std::ptrdiff_t>(e - b, 255);
    std::uint8_t n = 0;
    for (std::ptrdiff_t i = 0; i < len; ++i) n = static_cast<std::uint8_t>(n + (b[i] == c));
    total += n;
    b += len;
  }
  return total;
}

// Where [b, e)'s first line (LF or CR) ends, or e.
const char* first_line_end(const char* b, const char* e) noexcept {
  const auto* lf = static_cast<const char*>(std::memchr(b, '\n', static_cast<std::size_t>(e - b)));
  const auto* cr = static_cast<const char*>(std::memchr(b, '\r', static_cast<std::size_t>((lf ? lf : e) - b)));
  return cr ? cr : lf ? lf : e;
}

// Offset just after the last `c` in [b, e) (b at offset `at`), else `last`.
std::size_t after_last(const char* b, const char* e, char c, std::size_t at, std::size_t last) noexcept {
  const auto* p = static_cast<const char*>(::memrchr(b, c, static_cast<std::size_t>(e - b)));
  return p ? at + static_cast<std::size_t>(p - b) + 1 : last;
}

[[noreturn]] void fail_errno(const std::string& name, const char* what, int err) {
  throw InputError(name, 0, std::string(tr(what)) + ": " + std::strerror(err));
}

}  // namespace

std::string display_name(const std::string& path) { return path == "-" ? "<stdin>" : path; }

void TextCheck::check(std::string_view piece) {
  const char* b = piece.data();
  if (offset_ == 0) bom_ = piece.starts_with("\xEF\xBB\xBF");
  const char* bad = first_control(b, b + piece.size());
  const char* stop = bad ? bad : b + piece.size();
  // A piece is shorter than the limit: only the line running on from before it can pass it here.
  const auto reach = offset_ + static_cast<std::size_t>(first_line_end(b, stop) - b) - std::max(after_lf_, after_cr_);
  if (reach > kMaxLineBytes)
    throw InputError(name_, line(),
                     trf("line too long: more than {} bytes (1 MiB) without a line end; this is not a "
                         "text recording",
                         kMaxLineBytes));
  lf_ += count_byte(b, stop, '\n');
  cr_ += count_byte(b, stop, '\r');
  after_lf_ = after_last(b, stop, '\n', offset_, after_lf_);
  after_cr_ = after_last(b, stop, '\r', offset_, after_cr_);
  if (bad) {
    // The line starts after the last LF, or the last CR while no LF has come; a byte-order mark
    // before the first line is not one of its columns.
    const std::size_t at = offset_ + static_cast<std::size_t>(bad - b);
    std::size_t start = lf_ > 0 ? after_lf_ : cr_ > 0 ? after_cr_ : 0;
    if (start == 0 && bom_ && at >= 3) start = 3;
    throw InputError(name_, line(),
                     trf("binary data (byte 0x{:02x} at column {}): this is not a text recording; a "
                         "compressed file other than gzip?",
                         static_cast<unsigned char>(*bad), at - start + 1));
  }
  offset_ += piece.size();
}

TextSource::TextSource(const std::string& path) : name_(display_name(path)), check_(name_) {
  if (path == "-") {
    in_.fd = STDIN_FILENO;
    return;
  }
  if (path.empty()) throw InputError(tr("(empty path)"), 0, tr("no input file given"));
  in_.fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (in_.fd < 0) fail_errno(name_, N_("cannot open"), errno);
  in_.own = true;
  struct stat st {};
  if (::fstat(in_.fd, &st) != 0) fail_errno(name_, N_("cannot stat"), errno);
  if (S_ISDIR(st.st_mode)) throw InputError(name_, 0, tr("is a directory, not a recording"));
  if (S_ISREG(st.st_mode)) bytes_ = static_cast<std::size_t>(st.st_size);
}

TextSource::TextSource(std::string_view bytes, std::string name)
    : name_(std::move(name)), memory_(bytes), bytes_(bytes.size()), check_(name_) {}

TextSource::Descriptor::~Descriptor() {
  if (own) ::close(fd);
}
TextSource::~TextSource() {
  if (gzip_) inflateEnd(&zs_);
}

// Up to `max` raw bytes into `to`; 0 at the end of the input. Every byte passes the digest here.
std::size_t TextSource::read_raw(char* to, std::size_t max) {
  std::size_t n = 0;
  if (in_.fd < 0) {
    n = std::min(max, memory_.size());
    std::memcpy(to, memory_.data(), n);
    memory_.remove_prefix(n);
  } else {
    ssize_t got = -1;
    while ((got = ::read(in_.fd, to, max)) < 0)
      if (errno != EINTR) fail_errno(name_, N_("cannot read"), errno);
    n = static_cast<std::size_t>(got);
  }
  hash_.update(std::string_view(to, n));
  raw_total_ += n;
  return n;
}

bool TextSource::read(std::string& out) {
  if (!started_) return start(out);
  if (gzip_) return inflate_piece(out);
  const std::size_t before = out.size();
  out.resize(before + kPieceBytes);
  out.resize(before + read_raw(out.data() + before, kPieceBytes));
  check_.check(std::string_view(out).substr(before));
  return out.size() > before;
}

// The first bytes tell gzip from text (and hold a whole byte-order mark, if any).
bool TextSource::start(std::string& out) {
  started_ = true;
  raw_.resize(kPieceBytes);
  std::size_t n = 0;
  for (std::size_t k = 1; n < 3 && k > 0; n += k) k = read_raw(raw_.data() + n, kPieceBytes - n);
  raw_.resize(n);
  gzip_ = raw_.starts_with("\x1f\x8b");
  if (!gzip_) {
    check_.check(raw_);
    out += raw_;
    return n > 0;
  }
  // 16 + MAX_WBITS: the gzip wrapper only.
  if (inflateInit2(&zs_, 16 + MAX_WBITS) != Z_OK) throw InputError(name_, 0, tr("cannot initialise zlib"));
  zs_.next_in = reinterpret_cast<Bytef*>(raw_.data());
  zs_.avail_in = static_cast<uInt>(raw_.size());
  return inflate_piece(out);
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
  while (zs_.avail_out > 0 && !(ended = zs_.avail_in == 0 && !refill())) {
    // After a member's end only another member may follow: its magic bytes, maybe split by a read.
    for (uInt i = 0; !in_member_ && magic_seen_ < 2 && i < zs_.avail_in; ++i, ++magic_seen_)
      if (zs_.next_in[i] != (magic_seen_ == 0 ? 0x1f : 0x8b))
        throw InputError(name_, 0, tr("unexpected bytes after the end of the gzip data"));
    in_member_ = in_member_ || magic_seen_ == 2;
    const int rc = inflate(&zs_, Z_NO_FLUSH);
    if (rc == Z_STREAM_END) {
      members_in_ += zs_.total_in;
      inflateReset(&zs_);
      in_member_ = false;
      magic_seen_ = 0;
    } else if (rc != Z_OK && rc != Z_BUF_ERROR) {  // Z_BUF_ERROR: more input is needed
      throw InputError(name_, 0, std::string(tr("corrupt gzip data: ")) + (zs_.msg ? zs_.msg : "inflate failed"));
    }
  }
  const std::size_t n = kPieceBytes - zs_.avail_out;
  if (ended && (in_member_ || magic_seen_ > 0))
    throw InputError(name_, 0,
                     trf("truncated gzip data: the compressed stream ends before its end marker ({} bytes "
                         "decompressed); the file is incomplete",
                         inflated_ + n));
  out.resize(before + n);
  inflated_ += n;
  check_.check(std::string_view(out).substr(before));
  return n > 0 || !ended;
}

}  // namespace rwcalc::detail
