// Getting the bytes of a recording into memory: regular files with read(2), standard input, and
// gzip data inflated with zlib into a growing buffer. One allocation per file, no iostreams.
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

#include "reader_detail.hpp"
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

TextBuffer inflate_gzip(std::string_view bytes, const std::string& name) {
  z_stream zs{};
  // 16 + MAX_WBITS: gzip wrapper only (the caller checked the magic bytes).
  if (inflateInit2(&zs, 16 + MAX_WBITS) != Z_OK) throw InputError(name, 0, "cannot initialise zlib");
  struct Guard {
    z_stream* z;
    ~Guard() { inflateEnd(z); }
  } guard{&zs};

  // zlib counts in uInt; feed input and output in chunks so files over 4 GiB work too.
  constexpr std::size_t kChunk = std::size_t{1} << 30;
  const auto* in_begin = reinterpret_cast<const Bytef*>(bytes.data());
  zs.next_in = const_cast<Bytef*>(in_begin);
  zs.avail_in = 0;
  auto consumed = [&] { return static_cast<std::size_t>(zs.next_in - in_begin); };

  TextBuffer out(std::max<std::size_t>(bytes.size() * 4, 1 << 16));
  for (;;) {
    if (zs.avail_in == 0) zs.avail_in = static_cast<uInt>(std::min(kChunk, bytes.size() - consumed()));
    if (out.size() == out.capacity()) out.reserve(out.capacity() * 2);
    zs.next_out = reinterpret_cast<Bytef*>(out.data() + out.size());
    zs.avail_out = static_cast<uInt>(std::min(kChunk, out.capacity() - out.size()));
    const std::size_t room = zs.avail_out;
    const int rc = inflate(&zs, Z_NO_FLUSH);
    out.set_size(out.size() + (room - zs.avail_out));
    if (rc == Z_OK) continue;
    if (rc == Z_STREAM_END) {
      const std::size_t pos = consumed();
      if (pos == bytes.size()) break;
      // Concatenated gzip members (as `cat a.gz b.gz` makes) are one stream, as gzip reads them.
      if (!is_gzip(bytes.substr(pos)))
        throw InputError(name, 0, "unexpected bytes after the end of the gzip data");
      inflateReset(&zs);
      continue;
    }
    if (rc == Z_BUF_ERROR && zs.avail_in == 0 && consumed() == bytes.size())
      throw InputError(name, 0,
                       "truncated gzip data: the compressed stream ends before its end marker (" +
                           std::to_string(out.size()) + " bytes decompressed); the file is incomplete");
    if (rc == Z_BUF_ERROR) continue;  // needs more output room or input: the loop provides both
    throw InputError(name, 0, std::string("corrupt gzip data: ") + (zs.msg ? zs.msg : "inflate failed"));
  }
  out.terminate();
  return out;
}

TextBuffer load_text(std::string_view text, const std::string& name) {
  if (is_gzip(text)) return inflate_gzip(text, name);
  TextBuffer buf(text.size());
  if (!text.empty()) std::memcpy(buf.data(), text.data(), text.size());
  buf.set_size(text.size());
  buf.terminate();
  return buf;
}

TextBuffer load_source(const std::string& path, unsigned threads, Crew* crew, std::vector<std::int32_t>* host) {
  const std::string name = display_name(path);
  TextBuffer raw;
  if (path == "-") {
    raw.reserve(1 << 20);
    read_all(STDIN_FILENO, raw, name);
  } else {
    if (path.empty()) throw InputError("(empty path)", 0, "no input file given");
    FileDescriptor fd(::open(path.c_str(), O_RDONLY | O_CLOEXEC));
    if (fd.get() < 0) fail_errno(name, "cannot open", errno);
    struct stat st {};
    if (::fstat(fd.get(), &st) != 0) fail_errno(name, "cannot stat", errno);
    if (S_ISDIR(st.st_mode)) throw InputError(name, 0, "is a directory, not a recording");
    // Regular files: one read of the known size; pipes and devices grow as they go.
    // One spare byte lets the final read(2) see end-of-file without growing the buffer.
    constexpr std::size_t kHalvesBytes = std::size_t{4} << 20;
    const auto size = static_cast<std::size_t>(st.st_size);
    const bool regular = S_ISREG(st.st_mode);
    const bool halves = regular && threads > 1 && size > kHalvesBytes;
    char* front = nullptr;
    std::size_t front_bytes = 0;
    if (regular && host) {
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
      raw.reserve(regular ? size + 1 : std::size_t{1} << 20);
    }
    if (halves && !read_halves(fd.get(), size, raw, name, crew, front, front_bytes) &&
        ::lseek(fd.get(), 0, SEEK_SET) < 0)
      fail_errno(name, "cannot seek", errno);
    read_all(fd.get(), raw, name);
  }
  if (is_gzip(raw.view())) return inflate_gzip(raw.view(), name);
  raw.terminate();
  return raw;
}

}  // namespace rwcalc::detail
