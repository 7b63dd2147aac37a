// Getting the bytes of a recording into memory: regular files with read(2); standard input, pipes
// and devices in chunks; gzip data inflated with zlib into a growing buffer. Text is checked as it
// arrives (ArrivalCheck), so that binary data or an endless line is refused before more is read.
// No iostreams.
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/mman.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <limits>
#include <mutex>
#include <utility>
#include <vector>

#include <fmt/format.h>

#include "io/reader_detail.hpp"
#include "rwcalc/crew.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/thread.hpp"

namespace rwcalc::detail {

// Lines ('\n') in [b, end) and whether a control byte other than tab, LF, CR (or DEL) occurs: in
// blocks of 240 bytes (a multiple of the vector width, below 256 so that an 8-bit line counter
// cannot overflow within a block), branch-free inside a block so the compiler vectorises it; an
// AVX2 clone is chosen at run time where the processor has it. Stops after the first block that
// trips, setting `bad` to its start (else nullptr).
__attribute__((target_clones("avx2", "default"))) std::size_t count_lines_checked(const char* b, const char* end,
                                                                                 const char*& bad) {
  constexpr std::size_t kBlock = 240;
  std::size_t lines = 0;
  bad = nullptr;
  for (; b < end; b += kBlock) {
    const char* e = end - b > static_cast<std::ptrdiff_t>(kBlock) ? b + kBlock : end;
    unsigned char trip = 0, nl = 0;
    for (const char* q = b; q < e; ++q) {
      const auto c = static_cast<unsigned char>(*q);
      nl = static_cast<unsigned char>(nl + (c == '\n'));
      trip |= static_cast<unsigned char>(((c < 0x20) & (c != '\t') & (c != '\n') & (c != '\r')) | (c == 0x7f));
    }
    lines += nl;
    if (trip) {
      bad = b;
      return lines;
    }
  }
  return lines;
}


namespace {

bool is_control(unsigned char c) noexcept { return (c < 0x20 && c != '\t' && c != '\n' && c != '\r') || c == 0x7f; }

// The first line end (LF or CR) in [b, e), or null. CR counts too: a file with classic Mac line
// ends has no LF at all.
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

// Line number of the line holding text[at], as the reader numbers lines: by LF, or by CR in a text
// that has no LF before it (classic Mac line ends). Error paths only: it counts from the start.
std::size_t line_at(const char* text, const char* at) noexcept {
  const auto lf = static_cast<std::size_t>(std::count(text, at, '\n'));
  return 1 + (lf > 0 ? lf : static_cast<std::size_t>(std::count(text, at, '\r')));
}

}  // namespace

void ArrivalCheck::advance(TextBuffer& buf) {
  constexpr std::size_t kSeg = TextBuffer::kSegment;
  const char* text = buf.data();
  const std::size_t size = buf.size();
  // Whole segments the loader has checked and counted already (read_halves).
  while (checked_ % kSeg == 0 && checked_ / kSeg < buf.segment_lines.size() && checked_ + kSeg <= size) {
    check_line_lengths(text, checked_, checked_ + kSeg);
    lines_ += buf.segment_lines[checked_ / kSeg];
    checked_ += kSeg;
  }
  // The rest piece by piece, never across a segment's end, so that each whole segment's count is
  // known when its last byte has been checked.
  while (checked_ < size) {
    const std::size_t to = std::min(size, (checked_ / kSeg + 1) * kSeg);
    check_piece(text, checked_, to);
    checked_ = to;
    if (to % kSeg == 0 && buf.segment_lines.size() == to / kSeg - 1) {
      buf.segment_lines.push_back(segment_count_);
      segment_count_ = 0;
    }
  }
}

void ArrivalCheck::check_piece(const char* text, std::size_t from, std::size_t to) {
  const char* bad = nullptr;
  const std::size_t lines = count_lines_checked(text + from, text + to, bad);
  if (bad) {
    // The block that tripped holds a control byte: the first one, after the lines before it.
    while (!is_control(static_cast<unsigned char>(*bad))) ++bad;
    check_line_lengths(text, from, static_cast<std::size_t>(bad - text));
    fail_binary(text, bad);
  }
  check_line_lengths(text, from, to);
  lines_ += lines;
  segment_count_ += lines;
}

// [from, to) is at most one segment, far shorter than kMaxLineBytes: only the line that began
// before it and the one that runs on past it can be too long.
void ArrivalCheck::check_line_lengths(const char* text, std::size_t from, std::size_t to) {
  const char* b = text + from;
  const char* e = text + to;
  const char* first = first_line_end(b, e);
  if (!first) {
    line_bytes_ += to - from;
    if (line_bytes_ > kMaxLineBytes) fail_long_line(text, from);
    return;
  }
  if (line_bytes_ + static_cast<std::size_t>(first - b) > kMaxLineBytes) fail_long_line(text, from);
  line_bytes_ = static_cast<std::size_t>(e - (last_line_end(first, e) + 1));
}

void ArrivalCheck::fail_binary(const char* text, const char* at) const {
  const char* start = at;
  const char end = std::memchr(text, '\n', static_cast<std::size_t>(at - text)) ? '\n' : '\r';
  while (start > text && start[-1] != end) --start;
  // A UTF-8 byte-order mark before the first line is not one of its columns.
  if (start == text && at - text >= 3 && static_cast<unsigned char>(text[0]) == 0xEF &&
      static_cast<unsigned char>(text[1]) == 0xBB && static_cast<unsigned char>(text[2]) == 0xBF)
    start += 3;
  throw InputError(name_, line_at(text, at),
                   fmt::format("binary data (byte 0x{:02x} at column {}): this is not a text recording; a "
                               "compressed file other than gzip?",
                               static_cast<unsigned char>(*at), at - start + 1));
}

void ArrivalCheck::fail_long_line(const char* text, std::size_t from) const {
  // The long line began before text[from] (or at it), and has no line end before text[from].
  throw InputError(name_, line_at(text, text + from),
                   fmt::format("line too long: more than {} bytes (1 MiB) without a line end; this is not a "
                               "text recording",
                               kMaxLineBytes));
}

namespace {

// Pages of the brk heap already mapped by prefault (see remember_mapped_pages): disjoint
// [begin, end) ranges, ascending.
struct MappedPages {
  std::atomic<bool> on{false};
  std::uintptr_t heap_low = 0;
  std::mutex mu;
  std::vector<std::pair<std::uintptr_t, std::uintptr_t>> ranges;
};
MappedPages& mapped_pages() {
  static MappedPages m;
  return m;
}

void populate(std::uintptr_t start, std::uintptr_t end) noexcept {
#ifdef MADV_POPULATE_WRITE
  // In steps of 2 MB: the call holds the process's memory map for reading while it maps, and a
  // thread that changes the map meanwhile (mmap, brk, munmap) waits for it to end, as does every
  // thread queued behind that one; between steps the others get through. (A 40-MB buffer mapped
  // in one call while another thread mapped its own buffer with mmap took them 18 ms for the
  // two; in steps, 9 ms, as for one alone.)
  constexpr std::uintptr_t kStep = std::uintptr_t{2} << 20;
  for (std::uintptr_t a = start; a < end; a += kStep)
    (void)::madvise(reinterpret_cast<void*>(a), std::min(kStep, end - a), MADV_POPULATE_WRITE);
#else
  (void)start;
  (void)end;
#endif
}

}  // namespace

void remember_mapped_pages(bool on) noexcept {
  MappedPages& m = mapped_pages();
  m.heap_low = reinterpret_cast<std::uintptr_t>(::sbrk(0));
  m.on = on;
}

void prefault(void* data, std::size_t bytes) noexcept {
  constexpr std::size_t kMin = std::size_t{1} << 20;  // small buffers: not worth a system call
  if (!data || bytes < kMin) return;
  const auto page = static_cast<std::uintptr_t>(::sysconf(_SC_PAGESIZE));
  const auto a = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t start = (a + page - 1) & ~(page - 1);
  const std::uintptr_t end = (a + bytes) & ~(page - 1);
  if (end <= start) return;
  MappedPages& m = mapped_pages();
  const auto brk = reinterpret_cast<std::uintptr_t>(::sbrk(0));
  if (!m.on || start < m.heap_low || end > brk) {  // not in the heap: a fresh mapping
    populate(start, end);
    return;
  }
  // In the heap: only the pages no earlier buffer mapped (a heap that shrank forgets its top).
  std::vector<std::pair<std::uintptr_t, std::uintptr_t>> todo;
  try {
    const std::lock_guard lock(m.mu);
    auto& r = m.ranges;
    std::erase_if(r, [brk](const auto& x) { return x.first >= brk; });
    for (auto& x : r) x.second = std::min(x.second, brk);
    std::uintptr_t at = start;
    for (const auto& x : r) {
      if (x.second <= at) continue;
      if (x.first >= end) break;
      if (x.first > at) todo.emplace_back(at, x.first);
      at = std::max(at, x.second);
      if (at >= end) break;
    }
    if (at < end) todo.emplace_back(at, end);
    r.emplace_back(start, end);
    std::sort(r.begin(), r.end());
    std::vector<std::pair<std::uintptr_t, std::uintptr_t>> merged;
    for (const auto& x : r) {
      if (!merged.empty() && x.first <= merged.back().second) merged.back().second = std::max(merged.back().second, x.second);
      else merged.push_back(x);
    }
    r = std::move(merged);
  } catch (...) {  // no memory for the list: map the whole buffer
    populate(start, end);
    return;
  }
  for (const auto& [b, e] : todo) populate(b, e);
}

TextBuffer::TextBuffer(std::size_t capacity, bool map_pages, std::size_t spare)
    : own_(std::make_unique_for_overwrite<char[]>(capacity + 1 + kPadding + spare)), data_(own_.get()), capacity_(capacity) {
  if (map_pages) prefault(data_, capacity);
  std::memset(data_ + capacity + 1, 0, kPadding);
}

TextBuffer::TextBuffer(std::vector<std::int32_t>&& host, std::size_t capacity) : host_(std::move(host)), capacity_(capacity) {
  host_.clear();
  const std::size_t need = host_capacity(capacity);
  if (host_.capacity() < need) {
    // 1/16 more than this text needs: the next files of a batch, a little longer or shorter,
    // then find the storage large enough.
    host_ = std::vector<std::int32_t>();
    host_.reserve(need + need / 16);
  }
  // The text ends host_capacity(capacity) elements into the storage (not at the end of a larger
  // one: the pages past it stay untouched); the counts start where the storage starts.
  char* end = reinterpret_cast<char*>(host_.data() + need);
  data_ = end - (capacity + 1 + kPadding);
  std::memset(data_ + capacity + 1, 0, kPadding);
}

void TextBuffer::reserve(std::size_t capacity) {
  if (capacity <= capacity_ && data_) return;
  auto bigger = std::make_unique_for_overwrite<char[]>(capacity + 1 + kPadding);
  prefault(bigger.get() + size_, capacity - size_);
  std::memset(bigger.get() + capacity + 1, 0, kPadding);
  if (size_ > 0) std::memcpy(bigger.get(), data_, size_);
  own_ = std::move(bigger);
  data_ = own_.get();
  capacity_ = capacity;
}

void TextBuffer::terminate() {
  if (size_ > 0 && data_[size_ - 1] == '\n') return;
  if (!data_) reserve(0);
  data_[size_++] = '\n';  // capacity + 1 bytes are always allocated
  capacity_ = std::max(capacity_, size_);
}

std::string display_name(const std::string& path) { return path == "-" ? "<stdin>" : path; }

bool is_gzip(std::string_view bytes) noexcept {
  return bytes.size() >= 2 && static_cast<unsigned char>(bytes[0]) == 0x1f &&
         static_cast<unsigned char>(bytes[1]) == 0x8b;
}

namespace {

class FileDescriptor {
 public:
  explicit FileDescriptor(int fd) : fd_(fd) {}
  ~FileDescriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  FileDescriptor(const FileDescriptor&) = delete;
  FileDescriptor& operator=(const FileDescriptor&) = delete;
  [[nodiscard]] int get() const noexcept { return fd_; }

 private:
  int fd_;
};

[[noreturn]] void fail_errno(const std::string& name, const char* what, int err) {
  throw InputError(name, 0, std::string(what) + ": " + std::strerror(err));
}

// Read everything from fd into buf, starting at buf.size(), growing as needed.
void read_all(int fd, TextBuffer& buf, const std::string& name) {
  for (;;) {
    if (buf.size() == buf.capacity()) buf.reserve(std::max<std::size_t>(buf.capacity() * 2, 1 << 16));
    const ssize_t n = ::read(fd, buf.data() + buf.size(), buf.capacity() - buf.size());
    if (n < 0) {
      if (errno == EINTR) continue;
      fail_errno(name, "cannot read", errno);
    }
    if (n == 0) return;
    buf.set_size(buf.size() + static_cast<std::size_t>(n));
  }
}

// Read exactly `count` bytes at `offset` into dst (its pages mapped first). False when the file
// ended early; err holds errno when the read failed.
bool pread_exact(int fd, char* dst, std::size_t count, off_t offset, int& err) noexcept {
  prefault(dst, count);
  while (count > 0) {
    const ssize_t n = ::pread(fd, dst, count, offset);
    if (n < 0) {
      if (errno == EINTR) continue;
      err = errno;
      return false;
    }
    if (n == 0) return false;
    dst += n;
    count -= static_cast<std::size_t>(n);
    offset += n;
  }
  return true;
}

// Count the line ends of the whole segments (TextBuffer::kSegment) in [lo, hi) of buf into
// lines[k] (the part of a segment that [lo, hi) holds); the first segment holding a control byte
// sets bad (the lowest index).
void count_segments(const char* buf, std::size_t lo, std::size_t hi, std::vector<std::size_t>& lines,
                    std::size_t& bad) noexcept {
  constexpr std::size_t m = TextBuffer::kSegment;
  for (std::size_t k = lo / m; k < lines.size() && k * m < hi; ++k) {
    const char* trip = nullptr;
    lines[k] = count_lines_checked(buf + std::max(lo, k * m), buf + std::min(hi, (k + 1) * m), trip);
    if (trip) {
      bad = k;
      return;
    }
  }
}

// A regular file of `size` bytes in two halves, the second on another thread. False (the buffer
// then holds nothing) when the file turned out shorter than its size. Each thread checks and
// counts the lines of its half while its bytes are in the cache (TextBuffer::segment_lines), then
// maps the pages of its half of `front` (a hosted text's counts storage before the text, which the
// pulse reader writes next: mapped here by two threads rather than there by one).
bool read_halves(int fd, std::size_t size, TextBuffer& buf, const std::string& name, Crew* crew,
                 char* front = nullptr, std::size_t front_bytes = 0) {
  const std::size_t half = (size / 2) & ~std::size_t{4095};
  const std::size_t segments = size / TextBuffer::kSegment;
  std::vector<std::size_t> lines1(segments), lines2(segments);
  std::size_t bad1 = segments, bad2 = segments;
  int err1 = 0, err2 = 0;
  bool ok2 = false;
  {
    bool ok1 = false;
    const std::size_t front_half = (front_bytes / 2) & ~std::size_t{4095};
    auto second = [&] {
      ok2 = pread_exact(fd, buf.data() + half, size - half, static_cast<off_t>(half), err2);
      if (ok2) count_segments(buf.data(), half, size, lines2, bad2);
      if (front) prefault(front + front_half, front_bytes - front_half);
    };
    auto first = [&] {
      ok1 = pread_exact(fd, buf.data(), half, 0, err1);
      if (ok1) count_segments(buf.data(), 0, half, lines1, bad1);
      if (front) prefault(front, front_half);
    };
    if (crew) {  // the second half to a lender (or to this thread after the first, if none is free)
      crew->share(2, [&](std::size_t k) { k == 0 ? first() : second(); });
    } else {
      Thread other(second);
      first();
    }
    if (err1 || err2) fail_errno(name, "cannot read", err1 ? err1 : err2);
    if (!ok1 || !ok2) return false;
  }
  // The segments before the first one with a control byte (the reader searches that one again
  // and names the line); one segment straddles the halves, counted in two parts.
  const std::size_t counted = std::min(bad1, bad2);
  buf.segment_lines.resize(counted);
  for (std::size_t k = 0; k < counted; ++k) buf.segment_lines[k] = lines1[k] + lines2[k];
  buf.set_size(size);
  // The file may have grown meanwhile: read on from its known size to the end, as read_all does.
  if (::lseek(fd, static_cast<off_t>(size), SEEK_SET) < 0) fail_errno(name, "cannot seek", errno);
  return true;
}

}  // namespace

namespace {

// Inflates gzip data fed in pieces (one or more members, as `cat a.gz b.gz` makes) into a growing
// text, checking the text after each inflate call (ArrivalCheck), before more is inflated: a
// small file that inflates to gigabytes of binary data or of one line is refused at its first
// megabyte. Throws InputError naming the file for corrupt or truncated data.
class GzipInflater {
 public:
  GzipInflater(const std::string& name, std::size_t capacity) : name_(name), out_(capacity), check_(name) {
    // 16 + MAX_WBITS: gzip wrapper only (the caller checked the magic bytes).
    if (inflateInit2(&zs_, 16 + MAX_WBITS) != Z_OK) throw InputError(name, 0, "cannot initialise zlib");
  }
  ~GzipInflater() { inflateEnd(&zs_); }
  GzipInflater(const GzipInflater&) = delete;
  GzipInflater& operator=(const GzipInflater&) = delete;

  void feed(std::string_view bytes);
  TextBuffer finish();

 private:
  void check_next_member();

  // zlib counts in uInt: input in pieces of at most kInPiece; output in steps of at most kOutStep,
  // each checked before the next.
  static constexpr std::size_t kInPiece = std::size_t{1} << 30;
  static constexpr std::size_t kOutStep = std::size_t{1} << 20;
  std::string name_;
  z_stream zs_{};
  TextBuffer out_;
  ArrivalCheck check_;
  bool in_member_ = true;     // between a member's first byte and its end
  std::size_t magic_seen_ = 0;  // bytes of the next member's magic seen since a member ended
};

void GzipInflater::feed(std::string_view bytes) {
  zs_.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
  zs_.avail_in = 0;
  std::size_t left = bytes.size();
  for (;;) {
    if (zs_.avail_in == 0) {
      if (left == 0) return;
      const std::size_t piece = std::min(kInPiece, left);
      zs_.avail_in = static_cast<uInt>(piece);
      left -= piece;
    }
    if (!in_member_) check_next_member();
    if (out_.size() == out_.capacity()) out_.reserve(out_.capacity() * 2);
    zs_.next_out = reinterpret_cast<Bytef*>(out_.data() + out_.size());
    zs_.avail_out = static_cast<uInt>(std::min(kOutStep, out_.capacity() - out_.size()));
    const std::size_t room = zs_.avail_out;
    const int rc = inflate(&zs_, Z_NO_FLUSH);
    out_.set_size(out_.size() + (room - zs_.avail_out));
    check_.advance(out_);
    if (rc == Z_STREAM_END) {
      inflateReset(&zs_);
      in_member_ = false;
      magic_seen_ = 0;
      continue;
    }
    // Z_BUF_ERROR: no progress without more input or more room; the loop provides both.
    if (rc == Z_OK || rc == Z_BUF_ERROR) continue;
    throw InputError(name_, 0, std::string("corrupt gzip data: ") + (zs_.msg ? zs_.msg : "inflate failed"));
  }
}

// After a member's end only another member may follow: its magic bytes, which may arrive split
// between two pieces.
void GzipInflater::check_next_member() {
  static constexpr unsigned char kMagic[2] = {0x1f, 0x8b};
  for (uInt i = 0; magic_seen_ < 2 && i < zs_.avail_in; ++i, ++magic_seen_)
    if (zs_.next_in[i] != kMagic[magic_seen_])
      throw InputError(name_, 0, "unexpected bytes after the end of the gzip data");
  if (magic_seen_ == 2) in_member_ = true;
}

TextBuffer GzipInflater::finish() {
  if (in_member_ || magic_seen_ > 0)
    throw InputError(name_, 0,
                     "truncated gzip data: the compressed stream ends before its end marker (" +
                         std::to_string(out_.size()) + " bytes decompressed); the file is incomplete");
  out_.terminate();
  return std::move(out_);
}

}  // namespace

TextBuffer inflate_gzip(std::string_view bytes, const std::string& name) {
  GzipInflater z(name, std::max<std::size_t>(bytes.size() * 4, 1 << 16));
  z.feed(bytes);
  return z.finish();
}

TextBuffer load_text(std::string_view text, const std::string& name) {
  if (is_gzip(text)) return inflate_gzip(text, name);
  TextBuffer buf(text.size());
  if (!text.empty()) std::memcpy(buf.data(), text.data(), text.size());
  buf.set_size(text.size());
  ArrivalCheck(name).advance(buf);
  buf.terminate();
  return buf;
}

namespace {

// One read(2) of at most kStreamChunk bytes appended to buf (grown as needed): the byte count,
// 0 at the end of the stream.
std::size_t read_chunk(int fd, TextBuffer& buf, const std::string& name) {
  if (buf.capacity() - buf.size() < kStreamChunk) buf.reserve(std::max(buf.capacity() * 2, buf.size() + kStreamChunk));
  for (;;) {
    const ssize_t n = ::read(fd, buf.data() + buf.size(), kStreamChunk);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail_errno(name, "cannot read", errno);
    buf.set_size(buf.size() + static_cast<std::size_t>(n));
    return static_cast<std::size_t>(n);
  }
}

// Standard input, a pipe or a device (/dev/zero never ends): read chunk by chunk, each checked
// (gzip: inflated and checked) before the next is read, so that memory follows the text that
// passed the checks, never the length of the stream.
TextBuffer read_stream(int fd, const std::string& name) {
  TextBuffer text;
  // The first two bytes tell gzip from text.
  while (text.size() < 2 && read_chunk(fd, text, name) > 0) {
  }
  if (is_gzip(text.view())) {
    GzipInflater z(name, std::size_t{1} << 20);
    TextBuffer in = std::move(text);
    do {
      z.feed(in.view());
      in.set_size(0);
    } while (read_chunk(fd, in, name) > 0);
    return z.finish();
  }
  ArrivalCheck check(name);
  do check.advance(text);
  while (read_chunk(fd, text, name) > 0);
  text.terminate();
  return text;
}

}  // namespace

TextBuffer load_source(const std::string& path, unsigned threads, Crew* crew, std::vector<std::int32_t>* host) {
  const std::string name = display_name(path);
  TextBuffer raw;
  if (path == "-") return read_stream(STDIN_FILENO, name);
  {  // a named file
    if (path.empty()) throw InputError("(empty path)", 0, "no input file given");
    FileDescriptor fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
    if (fd.get() < 0) fail_errno(name, "cannot open", errno);
    struct stat st {};
    if (::fstat(fd.get(), &st) != 0) fail_errno(name, "cannot stat", errno);
    if (S_ISDIR(st.st_mode)) throw InputError(name, 0, "is a directory, not a recording");
    if (!S_ISREG(st.st_mode)) return read_stream(fd.get(), name);
    // A regular file: one read of the known size.
    // One spare byte lets the final read(2) see end-of-file without growing the buffer.
    constexpr std::size_t kHalvesBytes = std::size_t{4} << 20;
    const auto size = static_cast<std::size_t>(st.st_size);
    const bool halves = threads > 1 && size > kHalvesBytes;
    char* front = nullptr;
    std::size_t front_bytes = 0;
    if (host) {
      // A pulse file: the text at the end of the counts' storage (TextBuffer's host); its pages
      // are mapped here, or by each loading thread for its half, with half of the storage before
      // it each (the reader maps what is left when it writes the counts there).
      raw = TextBuffer(std::move(*host), size + 1);
      if (!halves) prefault(raw.data(), size + 1);
      front = reinterpret_cast<char*>(raw.host()->data());
      front_bytes = static_cast<std::size_t>(raw.data() - front);
    } else if (halves) {
      // Twice the file's size is allocated and only its first half used: once the text is freed,
      // the int32 view of the counts (4 bytes per line, at most 2 per byte of a pulse file) fits
      // in the freed block and reuses the pages the text mapped instead of mapping fresh ones
      // (the heap keeps blocks below M_MMAP_THRESHOLD mapped, src/main.cpp). The untouched half
      // costs address space only. Performance only: nothing depends on where the view lives.
      raw = TextBuffer(size + 1, false, size);
    } else {
      raw.reserve(size + 1);
    }
    if (halves && !read_halves(fd.get(), size, raw, name, crew, front, front_bytes) &&
        ::lseek(fd.get(), 0, SEEK_SET) < 0)
      fail_errno(name, "cannot seek", errno);
    read_all(fd.get(), raw, name);
  }
  if (is_gzip(raw.view())) return inflate_gzip(raw.view(), name);
  // A regular file is read whole (its size is known and bounds the memory), then checked.
  ArrivalCheck(name).advance(raw);
  raw.terminate();
  return raw;
}

}  // namespace rwcalc::detail
