// The recording reader: one pass over the bytes in memory with a hand-written scanner.
//
// Every line goes first through a fast path that accepts only the plain form of a data line (the
// detected delimiter, simple numbers, LF or CRLF). Anything else — comments, blank lines, decimal
// commas, exponents, stray text — falls to the careful path, which either accepts the line with
// the same values the fast path would give or throws an InputError that names file, line and the
// offending text. The two paths parse numbers to identical doubles (both correctly rounded).
#include "rwcalc/reader.hpp"

#include <algorithm>
#include <atomic>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <stop_token>
#include <thread>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <fmt/format.h>

#include "io/reader_detail.hpp"
#include "io/reader_simd.hpp"
#include "core/timing.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/limits.hpp"
#include "rwcalc/thread.hpp"
#include "rwcalc/units.hpp"

namespace rwcalc {

namespace {

using detail::is_digit;
using detail::scan_double_fast;
using detail::scan_int_fast;
using detail::count_lines_checked;
using detail::TextBuffer;

enum class Delim { Comma, Semicolon, Tab, Blanks };

std::string_view delim_name(Delim d) {
  switch (d) {
    case Delim::Comma: return "comma";
    case Delim::Semicolon: return "semicolon";
    case Delim::Tab: return "tab";
    case Delim::Blanks: return "blanks";
  }
  return "?";
}

constexpr std::size_t kQuoteLimit = 40;

// The offending text for a message: at most ~40 characters, non-printable bytes escaped.
std::string quoted(std::string_view s) {
  std::string out = "'";
  const std::size_t n = std::min(s.size(), kQuoteLimit);
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 0x20 || c == 0x7f)
      out += fmt::format("\\x{:02x}", c);
    else
      out += static_cast<char>(c);
  }
  if (s.size() > n) out += fmt::format("...' ({} characters)", s.size());
  else out += "'";
  return out;
}

std::string_view trim(std::string_view s, bool tabs = true) {
  auto blank = [tabs](char c) { return c == ' ' || (tabs && c == '\t'); };
  while (!s.empty() && blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && blank(s.back())) s.remove_suffix(1);
  return s;
}

bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return (x | 0x20) == (y | 0x20) && ((x >= 'A' && x <= 'Z') || (x >= 'a' && x <= 'z') || x == y);
         });
}

// A field with the decimal comma turned into a point, when that reading applies: exactly one
// comma, no point, and the delimiter is not a comma.
std::string_view normalise_decimal(std::string_view f, bool comma_ok, std::string& scratch) {
  if (!comma_ok) return f;
  const auto c = f.find(',');
  if (c == std::string_view::npos || f.find(',', c + 1) != std::string_view::npos ||
      f.find('.') != std::string_view::npos)
    return f;
  scratch.assign(f);
  scratch[c] = '.';
  return scratch;
}

// Does the field read as a number (even one out of range, or NaN/Inf)? Decides header rows.
bool looks_numeric(std::string_view f, bool comma_ok) {
  std::string scratch;
  f = normalise_decimal(f, comma_ok, scratch);
  if (!f.empty() && f.front() == '+') f.remove_prefix(1);
  if (f.empty()) return false;
  double v = 0;
  const auto r = std::from_chars(f.data(), f.data() + f.size(), v);
  return r.ptr == f.data() + f.size() && r.ec != std::errc::invalid_argument;
}

// Thrown inside the reader when the time column must be read again in full.
struct NeedTimes {};
// Thrown when the 32-bit read gave up after writing counts over text in the same storage
// (TextBuffer's host): the file is loaded again into a buffer of its own.
struct TextOverwritten {};

// Time2: a second time column, which must agree with the first (Reader::check_time_columns_agree).
enum class Role : unsigned char { Skip, Value, Time, Time2, Temperature };

// What the careful path made of a line.
enum class LineKind { Blank, Comment, Header, Data };

struct Sample {
  std::int64_t integer = 0;  // pulses, or a counter reading's bit pattern
  double real = 0.0;         // angle / rate sample
  double time = 0.0;   // in the time column's own unit (TimeName)
  double time2 = 0.0;  // the second time column's
  double temperature = 0.0;
};

// Names of a time column, with the unit each one is in.
struct TimeName {
  std::string_view name;
  std::string_view unit;
  double per_second;  // units per second
};
constexpr TimeName kTimeNames[] = {
    {"time_s", "s", 1},       {"time", "s", 1},    {"t", "s", 1},        {"t_s", "s", 1},
    {"timestamp", "s", 1},    {"time_sec", "s", 1}, {"time_ms", "ms", 1e3}, {"t_ms", "ms", 1e3},
    {"time_us", "us", 1e6},   {"t_us", "us", 1e6},  {"time_ns", "ns", 1e9}, {"t_ns", "ns", 1e9}};
constexpr TimeName kSeconds = kTimeNames[0];
const char* const kTemperatureNames[] = {"temperature_c", "temperature", "temp_c", "temp", "t_c"};

std::vector<std::string_view> value_names(InputMode m) {
  switch (m) {
    case InputMode::Pulses: return {"pulses", "pulse", "counts", "count"};
    case InputMode::Counter: return {"counter", "count", "counts", "pulses"};
    case InputMode::Angle: return {"angle", "phase"};
    case InputMode::Rate: return {"rate", "gyro", "frequency", "freq"};
  }
  return {};
}

// The time column name a header field is, or null.
const TimeName* time_name(std::string_view field) {
  for (const TimeName& t : kTimeNames)
    if (iequals(field, t.name)) return &t;
  return nullptr;
}

bool any_named(std::string_view field, const auto& names) {
  return std::any_of(std::begin(names), std::end(names), [&](std::string_view n) { return iequals(field, n); });
}

// The header's columns for which `matches` holds, in column order.
std::vector<std::size_t> columns_where(const std::vector<std::string>& header, const auto& matches) {
  std::vector<std::size_t> out;
  for (std::size_t c = 0; c < header.size(); ++c)
    if (matches(header[c])) out.push_back(c);
  return out;
}

class Reader {
 public:
  Reader(TextBuffer& buf, std::string name, const ReadOptions& options)
      : loaded_lines_(&buf.segment_lines),
        name_(std::move(name)),
        opt_(options),
        begin_(buf.data()),
        end_(buf.data() + buf.size()),
        host_(buf.host()) {}

  Recording run(bool store_times);

 private:
  [[noreturn]] void fail(std::size_t line, const std::string& message) const {
    throw InputError(name_, line, message);
  }
  [[nodiscard]] bool integer_mode() const {
    return opt_.mode == InputMode::Pulses || opt_.mode == InputMode::Counter;
  }

  std::size_t check_bytes(const char* text);  // returns the number of '\n'
  // Line ends in [marks_from_, x) for x in the checked text: the count at the last mark before x
  // (one every kMarkBytes from the buffer's start), plus the rest counted (less than kMarkBytes).
  static constexpr auto kMarkBytes = static_cast<std::ptrdiff_t>(TextBuffer::kSegment);
  const char* marks_from_ = nullptr;
  std::vector<std::size_t> line_marks_;
  const std::vector<std::size_t>* loaded_lines_;  // TextBuffer::segment_lines
  [[nodiscard]] std::size_t lines_before(const char* x) const;
  LineKind careful_line(std::string_view line);
  void metadata_line(std::string_view body);
  void detect_delimiter(std::string_view line);
  void split(std::string_view line);
  void check_foreign_delimiters(std::string_view line) const;
  void establish_layout();
  void choose_header_columns(bool value_given);
  [[nodiscard]] std::string column_list(const std::vector<std::size_t>& cols) const;
  void parse_field(std::string_view field, Role role, Sample& s) const;
  void push(const Sample& s);
  template <bool Integer>
  const char* parse_fast(const char* p, Sample& s) const;  // end of the line, or nullptr
  template <bool Integer>
  bool fast_line(const char*& p);
  template <bool Sum, class Vec>
  static const char* int_lines(const char* p, const char* limit, Vec& out, std::uint64_t& acc,
                               std::uint64_t& mag);
  void int_run(const char*& p, const char* limit);
  bool int_run_narrow(const char*& p, const char* limit);
  // The room for every line's 64-bit value, and its pages unless the text is to be parsed in two
  // parts (each thread then maps its own), when they were deferred (run()).
  void map_values(bool pages) {
    if (!values_unmapped_) return;
    values_unmapped_ = false;
    ints_.reserve(lines_ + 1);
    if (pages) prefault_values();
  }
  bool sum_pending();
  // Texts of more than kParallelBytes are parsed in two parts once the layout is known: the
  // second on another thread, from the first line start after kSplitNum/kSplitDen of the rest.
  static constexpr std::ptrdiff_t kParallelBytes = std::ptrdiff_t{1} << 20;
  // Where the text is split: the other thread takes the part after kSplitNum/kSplitDen of it.
  static constexpr std::ptrdiff_t kSplitNum = 11, kSplitDen = 20;
  [[nodiscard]] bool may_split() const {
    const unsigned threads = opt_.threads ? opt_.threads : std::thread::hardware_concurrency();
    return threads > 1 && end_ - begin_ > kParallelBytes;
  }
  void prefault_values() {
    if (integer_mode())
      detail::prefault(ints_.data() + ints_.size(), (ints_.capacity() - ints_.size()) * sizeof(std::int64_t));
    else
      detail::prefault(reals_.data() + reals_.size(), (reals_.capacity() - reals_.size()) * sizeof(double));
  }
  // The second part's integers, written by its thread straight into the room reserved in ints_
  // past the most the first part can hold (one value per line): no buffer of their own, no pages
  // mapped twice, and merge_chunk() offsets them where they are.
  struct IntSink {
    std::int64_t* p = nullptr;
    std::size_t n = 0;
    void push_back(std::int64_t v) noexcept { p[n++] = v; }
    [[nodiscard]] std::size_t size() const noexcept { return n; }
    [[nodiscard]] std::int64_t* data() const noexcept { return p; }
    [[nodiscard]] std::int64_t* begin() const noexcept { return p; }
    [[nodiscard]] std::int64_t* end() const noexcept { return p + n; }
    std::int64_t& operator[](std::size_t i) const noexcept { return p[i]; }
  };
  // Count the k values written past the end (within the reserved room) as appended. For the vector,
  // insert() from that room onto itself moves nothing (memmove of a range onto itself).
  static void grow_in_place(std::vector<std::int64_t>& v, std::size_t k) {
    const std::int64_t* t = v.data() + v.size();
    v.insert(v.end(), t, t + k);
  }
  static void grow_in_place(IntSink& v, std::size_t k) noexcept { v.n += k; }
  struct Chunk {
    IntSink ints;
    // Pulses: ints[0, summed) are already the running sums of the chunk's counts (from pred), acc
    // the last of them and mag the sum of the |counts|; the rest are counts as read.
    std::size_t summed = 0;
    std::uint64_t acc = 0, mag = 0;
    // The running sums start from pred (acc's first value): the first part's total as predicted by
    // digit_sum when its lines are all plain, else 0; the merge adds what the true total differs.
    std::uint64_t pred = 0;
    std::vector<double> reals, times, times2, temps;
    const char* stop = nullptr;  // where the chunk's fast path stopped
  };
  // When the merge has to offset the second part's running sums (the first part's total was not
  // predicted), that part's thread, once its part is parsed, offsets the first half of them while
  // this thread offsets the second half (a pass over ~10 MB on the 2-h file, ~0.8 ms on one
  // thread). Phases: 0 parsing, 1 parsed (waiting), 2 offset d[0, n) by base, 3 nothing more to
  // do (also set when the thread is asked to stop).
  struct MergeHelp {
    std::atomic<int> phase{0};
    std::uint64_t base = 0;
    std::int64_t* d = nullptr;
    std::size_t n = 0;
    void parsed_then_help(const std::stop_token& st) {  // on the second part's thread
      phase.store(1, std::memory_order_release);
      phase.notify_all();
      const std::stop_callback on_stop(st, [this] { dismiss(); });
      int v = 1;
      while ((v = phase.load(std::memory_order_acquire)) == 1) phase.wait(1, std::memory_order_acquire);
      if (v == 2)
        for (std::size_t i = 0; i < n; ++i) d[i] = static_cast<std::int64_t>(base + static_cast<std::uint64_t>(d[i]));
    }
    void wait_parsed() {
      while (phase.load(std::memory_order_acquire) == 0) phase.wait(0, std::memory_order_acquire);
    }
    void give(std::uint64_t b, std::int64_t* at, std::size_t count) {
      base = b;
      d = at;
      n = count;
      phase.store(2, std::memory_order_release);
      phase.notify_all();
    }
    void dismiss() {
      int one = 1;
      phase.compare_exchange_strong(one, 3, std::memory_order_acq_rel);
      phase.notify_all();
    }
  };
  template <bool Integer>
  void scan_chunk(const char* from, Chunk& out, std::stop_token stop) const;
  template <bool Integer>
  void merge_chunk(Chunk& c, MergeHelp& help, Thread& worker);
  template <bool Integer>
  void scan(const char* p);

  std::size_t line_of_sample(std::size_t k) const;
  void finish_rate();
  void check_unread_keys() const;
  void check_time_columns_agree() const;
  void check_time_column();
  void build_phase(Recording& rec);
  void check_data_magnitude(const PhaseSeries& ph, const char* what) const;

  std::string name_;
  const ReadOptions& opt_;
  const char* begin_;
  const char* end_;
  std::size_t line_ = 0;
  std::size_t lines_ = 0;          // '\n' in the text (from check_bytes)
  std::size_t content_lines_ = 0;  // non-blank lines seen by the careful path

  // Layout, fixed by the header row or the first data line.
  bool layout_known_ = false;
  Delim delim_ = Delim::Blanks;
  std::size_t ncols_ = 0;
  std::vector<std::string> header_;
  std::size_t header_line_ = 0;
  std::size_t layout_line_ = 0;  // line that fixed the delimiter
  std::vector<Role> roles_;
  std::size_t value_col_ = 0;
  std::optional<std::size_t> time_col_, temp_col_;
  std::optional<std::size_t> time2_col_;  // a second time column, checked against the first
  const TimeName* time_unit_ = &kSeconds;
  const TimeName* time2_unit_ = &kSeconds;
  std::array<bool, 256> stop_{};  // bytes that end an unselected field in the fast path
  bool int_lines_ok_ = false;     // one column of pulses: int_lines() may take the data lines
  std::int64_t counter_lo_ = 0, counter_max_ = 0;  // accepted reading range

  std::vector<std::string_view> fields_;  // scratch for the careful path
  mutable std::string scratch_;

  // Collected data.
  std::vector<std::int64_t> ints_;  // pulses/counter: slot 0 reserved for C_0
  // Pulses: ints_[0, summed_) already hold the cumulative counts C_k (summed while parsing, which
  // spares build_phase a second pass over the whole array), acc_ = the last of them (mod 2^64),
  // mag_ = Σ|c_i| over them; build_phase sums the rest.
  std::size_t summed_ = 0;
  std::uint64_t acc_ = 0, mag_ = 0;
  // Pulses held in 32 bits (int_run_narrow): C_0 … C_n when every |C_k| < 2^30, built instead of
  // ints_ when the whole rest of a one-column file is plain lines; then narrow_done_.
  std::vector<std::int32_t> narrow_;
  bool narrow_tried_ = false, narrow_done_ = false;
  // The vector in whose storage the text lies (TextBuffer::host()), or null: int_run_narrow then
  // writes the counts there, over text already parsed.
  std::vector<std::int32_t>* host_ = nullptr;
  // ints_'s room for every line and its pages are taken once it is known that ints_ will hold the
  // values (pulses, see run() and map_values()).
  bool values_unmapped_ = false;
  std::vector<double> reals_;       // angle: samples; rate: slot 0 reserved for x_0
  // The time column is checked from running statistics (first, last, smallest and largest step),
  // so a long record needs no second array; only when a step is out of tolerance is the file read
  // again keeping every time stamp, to name the first bad line.
  bool store_times_ = false;
  std::vector<double> times_;       // every time stamp (only when store_times_)
  std::vector<double> head_times_;  // the first kHeadTimes stamps: the rate estimate
  static constexpr std::size_t kHeadTimes = 102;
  double t_first_ = 0, t_prev_ = 0;
  double min_dt_ = std::numeric_limits<double>::infinity(), max_dt_ = -std::numeric_limits<double>::infinity();
  std::size_t n_times_ = 0;
  void track_time(double t) {
    t /= time_unit_->per_second;
    if (store_times_) times_.push_back(t);
    if (n_times_ == 0) {
      t_first_ = t;
    } else {
      const double dt = t - t_prev_;
      min_dt_ = std::min(min_dt_, dt);
      max_dt_ = std::max(max_dt_, dt);
    }
    if (n_times_ < kHeadTimes) head_times_.push_back(t);
    t_prev_ = t;
    ++n_times_;
  }
  // Two time columns: where they differ most (after track_time for the same sample).
  double time_gap_max_ = 0;
  std::size_t time_gap_sample_ = 0;
  double time_gap_t_ = 0, time_gap_t2_ = 0;  // the two stamps there, each in its own unit
  void track_time_pair(double t, double t2) {
    const double d = std::abs(t / time_unit_->per_second - t2 / time2_unit_->per_second);
    if (!(d <= time_gap_max_)) {
      time_gap_max_ = d;
      time_gap_sample_ = n_times_ - 1;
      time_gap_t_ = t;
      time_gap_t2_ = t2;
    }
  }
  long double temp_sum_ = 0;
  std::size_t temp_n_ = 0;
  std::size_t samples_ = 0;
  std::size_t first_data_line_ = 0, last_data_line_ = 0;
  bool new_run_ = true;
  std::vector<std::pair<std::size_t, std::size_t>> runs_;

  // Metadata and the rate.
  std::map<std::string, std::string> metadata_;
  std::optional<double> meta_rate_, meta_scale_, meta_temp_;
  std::size_t meta_rate_line_ = 0;
  // The first key rwcalc does not read that looks like a sample rate / a pulse weight, and its line.
  std::optional<std::pair<std::string, std::size_t>> unread_rate_key_, unread_scale_key_;
  double rate_hz_ = units::gl2d_rate_hz;
  RateSource rate_source_ = RateSource::Default;
};

// ---- bytes ---------------------------------------------------------------------------------------

std::size_t Reader::check_bytes(const char* text) {
  // Binary data: NUL and other control bytes (tab, LF and CR excepted). Checked, and the lines
  // counted, in one pass (count_lines_checked); the block that trips is searched again for the
  // first bad byte.
  // The count is kept at every kMarkBytes (lines_before()), so that the split of a long text
  // needs no second count of its first part.
  // The segments checked and counted while the file was loaded (from the buffer's start; a
  // byte-order mark before `text` holds no line end and no control byte) are taken as counted.
  const char* bad = nullptr;
  std::size_t lines = 0;
  marks_from_ = begin_;
  line_marks_.clear();
  line_marks_.reserve(static_cast<std::size_t>(end_ - begin_) / kMarkBytes + 1);
  const char* b = begin_;
  for (const std::size_t n : *loaded_lines_) {
    line_marks_.push_back(lines);
    lines += n;
    b += kMarkBytes;
  }
  for (; b < end_ && !bad; b += kMarkBytes) {
    line_marks_.push_back(lines);
    lines += count_lines_checked(b, end_ - b > kMarkBytes ? b + kMarkBytes : end_, bad);
  }
  if (!bad) return lines;
  for (const char* q = bad; q < end_; ++q) {
    const auto c = static_cast<unsigned char>(*q);
    if ((c < 0x20 && c != '\t' && c != '\n' && c != '\r') || c == 0x7f) {
      const auto line = 1 + static_cast<std::size_t>(std::count(text, q, '\n'));
      const char* ls = q;
      while (ls > text && ls[-1] != '\n') --ls;
      fail(line, fmt::format("binary data (byte 0x{:02x} at column {}): this is not a text recording; "
                             "a compressed file other than gzip?",
                             c, q - ls + 1));
    }
  }
  return lines;  // not reached: the block that tripped holds a bad byte
}

std::size_t Reader::lines_before(const char* x) const {
  const auto i = static_cast<std::size_t>((x - marks_from_) / kMarkBytes);
  const char* b = marks_from_ + static_cast<std::ptrdiff_t>(i) * kMarkBytes;
  const char* bad = nullptr;  // every byte has passed check_bytes()
  return line_marks_[i] + count_lines_checked(b, x, bad);
}

// ---- careful path ------------------------------------------------------------------------------

// A metadata key as the reader compares it: without regard to case, '-' read as '_' ("Rate-Hz" is
// rate_hz).
std::string canonical_key(std::string_view key) {
  std::string k(key);
  for (char& c : k) c = c == '-' ? '_' : (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c;
  return k;
}

// Keys rwcalc does not read but that look like a sample rate or a pulse weight: with them in the
// file, falling back to 400 Hz or 0.92″ would be a silent choice (Reader::check_unread_keys).
bool looks_like_rate_key(const std::string& k) {
  const auto has = [&](std::string_view w) { return k.find(w) != std::string::npos; };
  return k == "rate" || k == "fs" || k == "freq" || k == "frequency" || k == "odr" || k == "data_rate" ||
         k == "output_rate" || has("hz") || (has("sampl") && (has("rate") || has("freq")));
}
bool looks_like_scale_key(const std::string& k) {
  return k.find("scale") != std::string::npos || k.find("arcsec") != std::string::npos ||
         k.find("per_pulse") != std::string::npos;
}

void Reader::metadata_line(std::string_view body) {
  // "# key: value" or "# key = value", with key = letter/underscore then letters, digits, '_',
  // '.', '-'. The known keys are matched without regard to case and with '-' for '_', and kept
  // under their own spelling; other keys are kept as written.
  body = trim(body);
  std::size_t k = 0;
  auto key_char = [](char c, bool first) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_' ||
           (!first && ((c >= '0' && c <= '9') || c == '.' || c == '-'));
  };
  while (k < body.size() && key_char(body[k], k == 0)) ++k;
  if (k == 0) return;
  std::size_t c = k;
  while (c < body.size() && (body[c] == ' ' || body[c] == '\t')) ++c;
  if (c >= body.size() || (body[c] != ':' && body[c] != '=')) return;
  const std::string canonical = canonical_key(body.substr(0, k));
  const bool known = canonical == "rate_hz" || canonical == "scale_arcsec_per_pulse" ||
                     canonical == "temperature_c" || canonical == "serial";
  const std::string key = known ? canonical : std::string(body.substr(0, k));
  const std::string value(trim(body.substr(c + 1)));

  auto number = [&](bool positive) {
    std::string scratch;
    std::string_view v = normalise_decimal(value, true, scratch);
    if (!v.empty() && v.front() == '+') v.remove_prefix(1);
    double x = 0;
    const auto r = std::from_chars(v.data(), v.data() + v.size(), x);
    if (v.empty() || r.ec != std::errc() || r.ptr != v.data() + v.size() || !std::isfinite(x) ||
        (positive && !(x > 0)))
      fail(line_, fmt::format("metadata {}: {} is not a {}number", key, quoted(value),
                              positive ? "positive " : ""));
    return x;
  };
  auto set_known = [&](std::optional<double>& slot, bool positive) {
    const double x = number(positive);
    if (slot && *slot != x)
      fail(line_, fmt::format("metadata {} given twice with different values ({} and {})", key,
                              quoted(metadata_[key]), quoted(value)));
    slot = x;
  };
  // The usable ranges of rwcalc/limits.hpp, as for the options that override these keys.
  auto within = [&](double x, double lo, double hi, const char* unit) {
    if (!(x >= lo && x <= hi))
      fail(line_, fmt::format("metadata {}: {} {} is outside the usable range {:g}..{:g} {}", key, quoted(value), unit,
                              lo, hi, unit));
  };
  if (key == "rate_hz") {
    set_known(meta_rate_, true);
    within(*meta_rate_, kMinRateHz, kMaxRateHz, "Hz");
    meta_rate_line_ = line_;
  } else if (key == "scale_arcsec_per_pulse") {
    set_known(meta_scale_, true);
    within(*meta_scale_, kMinScaleArcsec, kMaxScaleArcsec, "arcsec");
  } else if (key == "temperature_c") {
    set_known(meta_temp_, false);
    within(*meta_temp_, kMinTemperatureC, kMaxTemperatureC, "deg C");
  } else if (!known && looks_like_rate_key(canonical) && !unread_rate_key_) {
    unread_rate_key_ = {key, line_};
  } else if (!known && looks_like_scale_key(canonical) && !unread_scale_key_) {
    unread_scale_key_ = {key, line_};
  }
  auto [it, inserted] = metadata_.try_emplace(key, value);
  if (!inserted && it->second != value) it->second += "; " + value;  // nothing is dropped
}

void Reader::detect_delimiter(std::string_view line) {
  // Tab, then semicolon, then comma; a comma whose pieces contain blanks is a decimal comma in a
  // blank-separated line ("0,0025 3").
  if (line.find('\t') != std::string_view::npos) {
    delim_ = Delim::Tab;
  } else if (line.find(';') != std::string_view::npos) {
    delim_ = Delim::Semicolon;
  } else if (line.find(',') != std::string_view::npos) {
    delim_ = Delim::Comma;
    std::size_t start = 0;
    for (;;) {
      const auto e = line.find(',', start);
      const auto piece = trim(line.substr(start, e == std::string_view::npos ? e : e - start));
      if (piece.find_first_of(" \t") != std::string_view::npos) delim_ = Delim::Blanks;
      if (e == std::string_view::npos) break;
      start = e + 1;
    }
  } else {
    delim_ = Delim::Blanks;
  }
  layout_line_ = line_;
}

void Reader::check_foreign_delimiters(std::string_view line) const {
  std::string_view foreign;
  switch (delim_) {
    case Delim::Comma: foreign = ";\t"; break;
    case Delim::Semicolon: foreign = "\t"; break;
    case Delim::Tab: foreign = ";"; break;
    case Delim::Blanks: foreign = ";"; break;
  }
  const auto at = line.find_first_of(foreign);
  if (at == std::string_view::npos) return;
  fail(line_, fmt::format("mixed delimiters: the file is {}-separated (from line {}) but this line "
                          "has a {} at column {}: {}",
                          delim_name(delim_), layout_line_, line[at] == '\t' ? "tab" : "semicolon",
                          at + 1, quoted(line)));
}

void Reader::split(std::string_view line) {
  fields_.clear();
  if (delim_ == Delim::Blanks) {
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
      if (i >= line.size()) break;
      const std::size_t s = i;
      while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
      fields_.push_back(line.substr(s, i - s));
    }
    return;
  }
  const char d = delim_ == Delim::Comma ? ',' : delim_ == Delim::Semicolon ? ';' : '\t';
  std::size_t start = 0;
  for (;;) {
    const auto e = line.find(d, start);
    fields_.push_back(trim(line.substr(start, e == std::string_view::npos ? e : e - start), false));
    if (e == std::string_view::npos) break;
    start = e + 1;
  }
}

void Reader::parse_field(std::string_view f, Role role, Sample& s) const {
  const std::size_t index = role == Role::Value ? value_col_
                            : role == Role::Time  ? *time_col_
                            : role == Role::Time2 ? *time2_col_
                                                  : *temp_col_;
  const std::string_view kind = role == Role::Value ? "column"
                                : role == Role::Temperature ? "temperature column"
                                                            : "time column";
  const std::string col = header_.empty() ? fmt::format("{} {}", kind, index + 1)
                                          : fmt::format("{} '{}'", kind, header_[index]);
  if (f.empty()) fail(line_, fmt::format("empty field in {}", col));
  std::string_view t = f;
  if (t.size() > 1 && t.front() == '+' && t[1] != '-' && t[1] != '+') t.remove_prefix(1);
  if (role == Role::Value && integer_mode()) {
    std::int64_t v = 0;
    auto r = std::from_chars(t.data(), t.data() + t.size(), v);
    if (r.ec == std::errc() && r.ptr == t.data() + t.size()) {
      if (opt_.mode == InputMode::Counter && (v < counter_lo_ || v > counter_max_))
        fail(line_, fmt::format("counter reading {} does not fit a {}-bit counter", quoted(f),
                                opt_.counter_bits));
      s.integer = v;
      return;
    }
    if (opt_.mode == InputMode::Counter && opt_.counter_bits == 64 && t.front() != '-') {
      std::uint64_t u = 0;
      r = std::from_chars(t.data(), t.data() + t.size(), u);
      if (r.ec == std::errc() && r.ptr == t.data() + t.size()) {
        s.integer = static_cast<std::int64_t>(u);  // same residue modulo 2^64
        return;
      }
    }
    {
      double d = 0;
      std::string scratch;
      const std::string_view n = normalise_decimal(t, delim_ != Delim::Comma, scratch);
      const auto rd = std::from_chars(n.data(), n.data() + n.size(), d);
      if (rd.ptr == n.data() + n.size() && rd.ec == std::errc() && !std::isfinite(d))
        fail(line_, fmt::format("non-finite value in {}: {}", col, quoted(f)));
    }
    const bool digits_only =
        std::all_of(t.begin() + (t.front() == '-'), t.end(), [](char c) { return is_digit(c); }) &&
        t.size() > static_cast<std::size_t>(t.front() == '-');
    if (digits_only)
      fail(line_, fmt::format("number out of range of a 64-bit integer in {}: {}", col, quoted(f)));
    if (looks_numeric(f, delim_ != Delim::Comma))
      fail(line_, fmt::format("{} counts must be integers: {} in {}",
                              opt_.mode == InputMode::Pulses ? "pulse" : "counter", quoted(f), col));
    fail(line_, fmt::format("not a number in {}: {}", col, quoted(f)));
  }
  std::string_view n = normalise_decimal(t, delim_ != Delim::Comma, scratch_);
  double v = 0;
  const auto r = std::from_chars(n.data(), n.data() + n.size(), v);
  if (r.ptr != n.data() + n.size() || r.ec == std::errc::invalid_argument)
    fail(line_, fmt::format("not a number in {}: {}", col, quoted(f)));
  if (r.ec == std::errc::result_out_of_range)
    fail(line_, fmt::format("number out of range in {}: {}", col, quoted(f)));
  if (!std::isfinite(v)) fail(line_, fmt::format("non-finite value in {}: {}", col, quoted(f)));
  (role == Role::Value ? s.real : role == Role::Time ? s.time : role == Role::Time2 ? s.time2 : s.temperature) = v;
}

LineKind Reader::careful_line(std::string_view line) {
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  if (const auto cr = line.find('\r'); cr != std::string_view::npos)
    fail(line_, fmt::format("stray carriage return (CR) at column {} inside the line", cr + 1));
  const std::string_view t = trim(line);
  if (t.empty()) return LineKind::Blank;
  ++content_lines_;
  if (t.front() == '#') {
    metadata_line(t.substr(1));
    return LineKind::Comment;
  }
  if (!layout_known_ && header_.empty()) detect_delimiter(t);
  check_foreign_delimiters(t);
  split(t);
  const bool comma_ok = delim_ != Delim::Comma;
  const bool any_numeric =
      std::any_of(fields_.begin(), fields_.end(), [&](std::string_view f) { return looks_numeric(f, comma_ok); });
  const bool any_text = std::any_of(fields_.begin(), fields_.end(), [](std::string_view f) { return !f.empty(); });
  // Inside the data, an all-text line is a second header row when it repeats the header or has
  // several fields; a lone word in a one-column file is just text in a numeric column.
  auto repeats_header = [&] {
    if (header_.empty() || fields_.size() != header_.size()) return false;
    for (std::size_t c = 0; c < fields_.size(); ++c) {
      std::string_view f = fields_[c];
      if (f.size() >= 2 && f.front() == '"' && f.back() == '"') f = f.substr(1, f.size() - 2);
      if (!iequals(trim(f), header_[c])) return false;
    }
    return true;
  };
  if (!any_numeric && any_text && (!layout_known_ || fields_.size() >= 2 || repeats_header())) {
    if (layout_known_)
      fail(line_, fmt::format("a second header row inside the data: {} (the first is at line {}); "
                              "were two files joined?",
                              quoted(t), header_line_ ? header_line_ : first_data_line_));
    if (!header_.empty())
      fail(line_, fmt::format("a second header row {} (the first is at line {}); only one is allowed",
                              quoted(t), header_line_));
    for (auto f : fields_) {
      if (f.size() >= 2 && f.front() == '"' && f.back() == '"') f = f.substr(1, f.size() - 2);
      header_.emplace_back(trim(f));
    }
    header_line_ = line_;
    return LineKind::Header;
  }
  if (!layout_known_) {
    ncols_ = header_.empty() ? fields_.size() : header_.size();
    establish_layout();
  }
  if (fields_.size() != ncols_)
    fail(line_, fmt::format("wrong number of columns: expected {} ({}-separated, as line {} has), found {}: {}",
                            ncols_, delim_name(delim_), header_line_ ? header_line_ : first_data_line_,
                            fields_.size(), quoted(t)));
  Sample s;
  for (std::size_t c = 0; c < ncols_; ++c)
    if (roles_[c] != Role::Skip) parse_field(fields_[c], roles_[c], s);
  push(s);
  return LineKind::Data;
}

void Reader::establish_layout() {
  layout_known_ = true;
  first_data_line_ = line_;
  const std::size_t where = header_line_ ? header_line_ : line_;
  auto list_columns = [&] {
    std::vector<std::size_t> all(ncols_);
    for (std::size_t c = 0; c < ncols_; ++c) all[c] = c;
    return column_list(all);
  };

  const std::string& want = opt_.column;
  if (!want.empty()) {
    if (std::all_of(want.begin(), want.end(), [](char c) { return is_digit(c); })) {
      std::size_t idx = 0;
      std::from_chars(want.data(), want.data() + want.size(), idx);
      if (idx < 1 || idx > ncols_)
        fail(where, fmt::format("--column {} is out of range: the file has {} column{}", want, ncols_,
                                ncols_ == 1 ? "" : "s"));
      value_col_ = idx - 1;
    } else if (header_.empty()) {
      fail(where, fmt::format("--column '{}' names a column but the file has no header row; give a "
                              "1-based index instead",
                              want));
    } else {
      const auto named = columns_where(header_, [&](std::string_view h) { return iequals(h, want); });
      if (named.empty())
        fail(header_line_, fmt::format("no column named '{}'; the columns are {}", want, list_columns()));
      if (named.size() > 1)
        fail(header_line_, fmt::format("{} columns are named '{}' (columns {}); choose one by its index with "
                                       "--column",
                                       named.size(), want, column_list(named)));
      value_col_ = named.front();
    }
  }
  if (header_.empty()) {
    // Headerless layouts: [value], [time, value], [time, value, temperature].
    if (want.empty()) {
      if (ncols_ > 3)
        fail(where, fmt::format("{} columns and no header row: choose the column with --column", ncols_));
      value_col_ = ncols_ == 1 ? 0 : 1;
    }
    if ((ncols_ == 2 || ncols_ == 3) && value_col_ == 1) time_col_ = 0;
    if (ncols_ == 3 && value_col_ == 1) temp_col_ = 2;
  } else {
    choose_header_columns(!want.empty());
  }
  roles_.assign(ncols_, Role::Skip);
  roles_[value_col_] = Role::Value;
  if (time_col_) roles_[*time_col_] = Role::Time;
  if (time2_col_) roles_[*time2_col_] = Role::Time2;
  if (temp_col_) roles_[*temp_col_] = Role::Temperature;

  // Bytes that end an unselected field in the fast path: its delimiter, the line end, and the
  // other delimiters (which the careful path reports as mixed).
  stop_.fill(false);
  for (char c : {'\n', '\r', ';', '\t'}) stop_[static_cast<unsigned char>(c)] = true;
  if (delim_ == Delim::Comma) stop_[','] = true;
  if (delim_ == Delim::Blanks) stop_[' '] = true;

  int_lines_ok_ = ncols_ == 1 && opt_.mode == InputMode::Pulses;
  if (!int_lines_ok_) map_values(!may_split());

  if (opt_.mode == InputMode::Counter) {
    const int b = opt_.counter_bits;
    counter_lo_ = b >= 64 ? std::numeric_limits<std::int64_t>::min() : -(std::int64_t{1} << (b - 1));
    counter_max_ = b >= 63 ? std::numeric_limits<std::int64_t>::max() : (std::int64_t{1} << b) - 1;
  }
}

// The columns of a header row: the samples (unless --column chose them), the time column(s) and the
// temperature column. Two columns that could both be the one wanted are an error, never a choice.
void Reader::choose_header_columns(bool value_given) {
  std::vector<std::size_t> times = columns_where(header_, [](std::string_view h) { return time_name(h) != nullptr; });
  std::vector<std::size_t> temps = columns_where(header_, [](std::string_view h) { return any_named(h, kTemperatureNames); });
  if (!value_given && ncols_ == 1) times.clear();  // a lone column named "time" holds the samples
  if (value_given) {
    std::erase(times, value_col_);
    std::erase(temps, value_col_);
  } else {
    const auto names = value_names(opt_.mode);
    const auto named = columns_where(header_, [&](std::string_view h) { return any_named(h, names); });
    if (named.size() > 1)
      fail(header_line_, fmt::format("columns {} could each hold the {} samples; choose one with --column",
                                     column_list(named), to_string(opt_.mode)));
    std::vector<std::size_t> rest;
    for (std::size_t k = 0; k < ncols_; ++k)
      if (std::count(times.begin(), times.end(), k) + std::count(temps.begin(), temps.end(), k) == 0) rest.push_back(k);
    if (named.empty() && rest.size() != 1) {
      std::vector<std::size_t> all(ncols_);
      for (std::size_t c = 0; c < ncols_; ++c) all[c] = c;
      fail(header_line_, fmt::format("cannot tell which column holds the {} samples; choose one with "
                                     "--column (the columns are {})",
                                     to_string(opt_.mode), column_list(all)));
    }
    value_col_ = named.empty() ? rest.front() : named.front();
  }
  if (times.size() > 2)
    fail(header_line_, fmt::format("{} time columns ({}); rwcalc reads one, or two that agree: remove the others",
                                   times.size(), column_list(times)));
  if (temps.size() > 1)
    fail(header_line_, fmt::format("{} temperature columns ({}); rwcalc reports one temperature: remove or "
                                   "rename the others",
                                   temps.size(), column_list(temps)));
  if (!times.empty()) {
    time_col_ = times[0];
    time_unit_ = time_name(header_[times[0]]);
  }
  if (times.size() == 2) {
    time2_col_ = times[1];
    time2_unit_ = time_name(header_[times[1]]);
  }
  if (!temps.empty()) temp_col_ = temps[0];
}

// "'a' (1), 'b' (2)" for header columns, "1, 2" without a header; cut after ~200 characters.
std::string Reader::column_list(const std::vector<std::size_t>& cols) const {
  std::string s;
  for (const std::size_t c : cols) {
    if (!s.empty()) s += ", ";
    if (s.size() > 200) {
      s += "...";
      break;
    }
    s += header_.empty() ? std::to_string(c + 1) : fmt::format("{} ({})", quoted(header_[c]), c + 1);
  }
  return s;
}

void Reader::push(const Sample& s) {
  if (new_run_) {
    runs_.emplace_back(samples_, line_);
    new_run_ = false;
  }
  if (integer_mode())
    ints_.push_back(s.integer);
  else
    reals_.push_back(s.real);
  if (time_col_) track_time(s.time);
  if (time2_col_) track_time_pair(s.time, s.time2);
  if (temp_col_) {
    temp_sum_ += s.temperature;
    ++temp_n_;
  }
  last_data_line_ = line_;
  ++samples_;
}

// ---- fast path -----------------------------------------------------------------------------------

template <bool Integer>
inline __attribute__((always_inline)) const char* Reader::parse_fast(const char* p, Sample& s) const {
  const bool blanks = delim_ == Delim::Blanks;
  const char dc = delim_ == Delim::Comma ? ',' : delim_ == Delim::Semicolon ? ';' : delim_ == Delim::Tab ? '\t' : ' ';
  const bool comma_ok = delim_ != Delim::Comma;
  const char* q = p;
  for (std::size_t c = 0; c < ncols_; ++c) {
    while (*q == ' ' || (blanks && *q == '\t')) ++q;
    switch (roles_[c]) {
      case Role::Value:
        if constexpr (Integer) {
          q = scan_int_fast(q, s.integer);
          if (!q) return nullptr;
          if (opt_.mode == InputMode::Counter && (s.integer < counter_lo_ || s.integer > counter_max_))
            return nullptr;
        } else {
          const char* e = scan_double_fast(q, s.real, comma_ok);
          if (!e) {
            // Long mantissas (full-precision doubles): std::from_chars, still no copy.
            const auto r = std::from_chars(q, end_, s.real);
            if (r.ec != std::errc() || !std::isfinite(s.real)) return nullptr;
            e = r.ptr;
          }
          q = e;
        }
        break;
      case Role::Time:
      case Role::Time2:
      case Role::Temperature: {
        double& v = roles_[c] == Role::Time ? s.time : roles_[c] == Role::Time2 ? s.time2 : s.temperature;
        const char* e = scan_double_fast(q, v, comma_ok);
        if (!e) {
          const auto r = std::from_chars(q, end_, v);
          if (r.ec != std::errc() || !std::isfinite(v)) return nullptr;
          e = r.ptr;
        }
        q = e;
        break;
      }
      case Role::Skip:
        while (!stop_[static_cast<unsigned char>(*q)]) ++q;
        break;
    }
    if (c + 1 < ncols_) {
      if (blanks) {
        if (*q != ' ' && *q != '\t') return nullptr;
      } else {
        while (*q == ' ') ++q;
        if (*q != dc) return nullptr;
        ++q;
      }
    }
  }
  while (*q == ' ' || (blanks && *q == '\t')) ++q;
  if (*q == '\r') ++q;
  if (*q != '\n') return nullptr;
  return q + 1;
}

template <bool Integer>
bool Reader::fast_line(const char*& p) {
  Sample s;
  const char* next = parse_fast<Integer>(p, s);
  if (!next) return false;
  if (new_run_) {
    runs_.emplace_back(samples_, line_);
    new_run_ = false;
  }
  if constexpr (Integer)
    ints_.push_back(s.integer);
  else
    reals_.push_back(s.real);
  if (time_col_) track_time(s.time);
  if (time2_col_) track_time_pair(s.time, s.time2);
  if (temp_col_) {
    temp_sum_ += s.temperature;
    ++temp_n_;
  }
  ++samples_;
  p = next;
  return true;
}

// The fastest path, for a file of one pulse column: a run of lines that are each one plain integer
// of at most 7 digits (scan_int_line), the lines that start before `limit`, up to the first other
// line, whose start it returns; that line then takes the per-line paths. Per line: no loop over
// the digits, a few predictable branches, no copy.
// Σ|c| may grow to this and no further (every second difference of the sums stays exact).
constexpr auto kSumLimit = static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
// Largest |count| int_lines accepts (7 digits): bounds Σ|c| over a run of lines before it starts.
constexpr std::uint64_t kLineMax = 9'999'999;

template <bool Sum, class Vec>
inline const char* Reader::int_lines(const char* p, const char* limit, Vec& out, std::uint64_t& acc,
                                     std::uint64_t& mag) {
  std::uint64_t a = acc, m = mag;
  auto emit = [&](std::int64_t v) {
    if constexpr (Sum) {
      // The running sum C_k and Σ|c|, as build_phase forms them (modulo 2^64).
      const auto u = static_cast<std::uint64_t>(v);
      const std::uint64_t sign = 0 - (u >> 63);
      a += u;
      m += (u ^ sign) - sign;
      out.push_back(static_cast<std::int64_t>(a));
    } else {
      out.push_back(v);
    }
  };
#if defined(__SSE2__)
  // Windows of 64 bytes. Runs of windows made only of one-digit lines ("0", "1", "-1": nearly every
  // line of a pulse file) go to detail::digit_windows, which takes a window's lines together and
  // writes their values (or running sums) straight into the room reserved past out's end; then
  // they are appended in place (a move of nothing). The first window it does not take comes here.
  // After a window it refused at once, the next kDigitBackoff windows skip it (files of longer
  // counts do not pay a classification per window for nothing).
  constexpr int kDigitBackoff = 8;
  int skip = 0;
  while (limit - p >= 64) {
    if (skip == 0) {
      std::size_t n = 0;
      std::int64_t* tail = out.data() + out.size();
      const char* q = detail::digit_windows<Sum>(p, limit, tail, n, a, m);
      if (n > 0) grow_in_place(out, n);
      if (q == p) skip = kDigitBackoff;
      p = q;
      if (limit - p < 64) break;
    } else {
      --skip;
    }
    // The line ends come from one compare per 16 bytes, so where a line starts does not wait for
    // the previous line's bytes to be read and tested (the scalar loop below is a chain of
    // dependent loads, one per line); each line is then taken by scan_int_line as there, and must
    // end at the newline found. Any other outcome leaves that line to the scalar loop.
    std::uint64_t nl = 0;
    const __m128i lf = _mm_set1_epi8('\n');
    for (int k = 0; k < 4; ++k) {
      const __m128i b = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + 16 * k));
      nl |= static_cast<std::uint64_t>(static_cast<std::uint32_t>(_mm_movemask_epi8(_mm_cmpeq_epi8(b, lf))))
            << (16 * k);
    }
    const char* s = p;
    bool stop = false;
    for (; nl != 0; nl &= nl - 1) {
      const char* e = p + __builtin_ctzll(nl);  // this line's newline
      std::int64_t v;
      if (detail::scan_int_line(s, v) != e + 1) {
        stop = true;
        break;
      }
      emit(v);
      s = e + 1;
    }
    if (stop || s == p) {
      p = s;
      break;
    }
    p = s;  // the line the window cut goes into the next window
  }
#endif
  while (p < limit) {
    std::int64_t v;
    const char* next = detail::scan_int_line(p, v);
    if (!next) break;
    emit(v);
    p = next;
  }
  acc = a;
  mag = m;
  return p;
}

// Turn the counts read since the last summed run into cumulative counts. Stops where Σ|c| would
// pass kSumLimit, leaving the rest to build_phase, which names that line.
bool Reader::sum_pending() {
  for (; summed_ < ints_.size(); ++summed_) {
    const auto v = static_cast<std::uint64_t>(ints_[summed_]);
    const std::uint64_t m = mag_ + (ints_[summed_] < 0 ? ~v + 1 : v);
    if (m > kSumLimit) return false;
    mag_ = m;
    acc_ += v;
    ints_[summed_] = static_cast<std::int64_t>(acc_);
  }
  return true;
}

// The first run of plain lines of a one-column pulse file, when it reaches the end of the text
// (no second part on another thread): the values are parsed in slices of 64 KiB into a small
// buffer (in cache) and kept as 32-bit cumulative counts, when every |C_k| < 2^30 — the 64-bit
// array is then never written, and the record takes half the memory. Any other line, or counts
// too large, gives up: nothing is kept and the run is read by int_run as before.
bool Reader::int_run_narrow(const char*& p, const char* limit) {
  narrow_tried_ = true;
  constexpr std::uint64_t kNarrowLimit = std::uint64_t{1} << 30;
  if (limit != end_ || !sum_pending() || mag_ >= kNarrowLimit) return false;
  constexpr std::ptrdiff_t kSlice = std::ptrdiff_t{1} << 16;
  // One slot per line to come, and the counts already summed (C_0 and any careful lines).
  const std::size_t slots = ints_.size() + (lines_ - lines_before(p)) + 1;
  // In the text's own storage when it lies in a host vector that has room (TextBuffer): the
  // counts then overwrite text already parsed, so a read that gives up after writing into the
  // text cannot go back to it (TextOverwritten: the caller loads the file again).
  std::vector<std::int32_t> local;
  const bool hosted = host_ && host_->capacity() >= slots;
  std::vector<std::int32_t>& out = hosted ? *host_ : local;
  const char* text = begin_;  // the text's first byte in the host's storage (when hosted)
  auto written_end = [&out] { return reinterpret_cast<const char*>(out.data() + out.size()); };
  auto give_up = [&] {
    if (hosted && written_end() > text) throw TextOverwritten{};
    out.clear();
    return false;
  };
  out.clear();
  out.reserve(slots);
  // Its pages in a few calls; in a host, those before the text (the text's are mapped already).
  const char* storage = reinterpret_cast<const char*>(out.data());
  detail::prefault(out.data(), hosted ? static_cast<std::size_t>(std::max(text - storage, std::ptrdiff_t{0}))
                                      : out.capacity() * sizeof(std::int32_t));
  out.insert(out.end(), ints_.begin(), ints_.end());  // each value's low 32 bits (below: why they suffice)
  if (hosted && written_end() > p) return give_up();
  std::vector<std::int64_t> part;
  part.reserve(static_cast<std::size_t>(kSlice / 2 + 64));  // a line has at least 2 bytes
  std::uint64_t acc = acc_, mag = mag_;
  const char* q = p;
  while (q < limit) {
    const char* slice = limit - q > kSlice ? q + kSlice : limit;
    part.clear();
    const char* r = int_lines<true>(q, slice, part, acc, mag);
    if (r < slice || mag >= kNarrowLimit) return give_up();  // a line of another form, or too large
    // Never past the first byte not yet parsed (a host sized by TextBuffer::host_capacity
    // always has the room).
    if (hosted && written_end() + part.size() * sizeof(std::int32_t) > r) return give_up();
    // Σ|c| < 2^30 bounds every |C_k|: the low 32 bits are the counts.
    out.insert(out.end(), part.begin(), part.end());
    q = r;
  }
  const std::size_t k = out.size() - ints_.size();
  if (k > 0) {
    if (new_run_) {
      runs_.emplace_back(samples_, line_ + 1);
      new_run_ = false;
    }
    samples_ += k;
    line_ += k;
  }
  acc_ = acc;
  mag_ = mag;
  narrow_ = std::move(out);
  narrow_done_ = true;
  p = q;
  return true;
}

void Reader::int_run(const char*& p, const char* limit) {
  if (!narrow_tried_) {
    if (int_run_narrow(p, limit)) return;
    // Not kept in 32 bits: a long text is now split (scan()), which maps the values' pages.
    if (may_split() && limit == end_) return;
  }
  map_values(true);
  const std::size_t before = ints_.size();
  // Sum while parsing when everything before is summed and Σ|c| cannot pass the limit in this run
  // (a line has at least 2 bytes; any real record is many orders of magnitude below the bound).
  if (sum_pending() && (kSumLimit - mag_) / kLineMax > static_cast<std::uint64_t>(limit - p)) {
    p = int_lines<true>(p, limit, ints_, acc_, mag_);
    summed_ = ints_.size();
  } else {
    std::uint64_t unused_acc = 0, unused_mag = 0;
    p = int_lines<false>(p, limit, ints_, unused_acc, unused_mag);
  }
  const std::size_t k = ints_.size() - before;
  if (k == 0) return;
  if (new_run_) {
    runs_.emplace_back(samples_, line_ + 1);
    new_run_ = false;
  }
  samples_ += k;
  line_ += k;
}

// The second half of a long text, parsed on another thread while the first half is read: plain
// data lines only, from `from` up to the first line the fast path does not take (or the end). It
// keeps the values, time stamps and temperatures in order; merge_chunk() then adds them to the
// record as the serial loop would have, and the serial loop goes on from where the chunk stopped
// (that line gets the careful path: errors name the right line, and the earliest one wins).
template <bool Integer>
void Reader::scan_chunk(const char* from, Chunk& out, std::stop_token stop) const {
  const char* p = from;
  Sample s;
  std::size_t k = 0;
  while (p < end_) {
    if constexpr (Integer) {
      if (int_lines_ok_) {
        // Slices of 64 KiB, so that a stop request is seen soon; a line not of the plain form
        // falls to parse_fast below.
        if (stop.stop_requested()) break;
        const char* slice = end_ - p > 65536 ? p + 65536 : end_;
        if (out.summed == out.ints.size() && (kSumLimit - out.mag) / kLineMax > 65536) {
          p = int_lines<true>(p, slice, out.ints, out.acc, out.mag);
          out.summed = out.ints.size();
        } else {
          std::uint64_t unused_acc = 0, unused_mag = 0;
          p = int_lines<false>(p, slice, out.ints, unused_acc, unused_mag);
        }
        if (p >= slice) continue;
      }
    }
    if ((++k & 0xfff) == 0 && stop.stop_requested()) break;
    const char* next = parse_fast<Integer>(p, s);
    if (!next) break;
    if constexpr (Integer)
      out.ints.push_back(s.integer);
    else
      out.reals.push_back(s.real);
    if (time_col_) out.times.push_back(s.time);
    if (time2_col_) out.times2.push_back(s.time2);
    if (temp_col_) out.temps.push_back(s.temperature);
    p = next;
  }
  out.stop = p;
}

template <bool Integer>
void Reader::merge_chunk(Chunk& c, MergeHelp& help, Thread& worker) {
  // Until `finish` the other thread may still be running: it reads nothing of the chunk and writes
  // only the values given to it.
  const auto finish = [&] {
    help.dismiss();
    if (worker.joinable()) worker.join();
  };
  const struct Finish {
    const decltype(finish)& f;
    ~Finish() { f(); }
  } at_exit{finish};
  const std::size_t k = Integer ? c.ints.size() : c.reals.size();
  if (k == 0) return;
  if (new_run_) {
    runs_.emplace_back(samples_, line_ + 1);
    new_run_ = false;
  }
  if constexpr (Integer) {
    auto from = c.ints.begin();
    if (c.summed > 0) {
      if (sum_pending() && c.mag <= kSumLimit - mag_) {
        // The chunk's running sums, offset where they are by what the sum so far differs from the
        // one they started from (nothing when it was predicted; else a vectorised add, half of it
        // on the other thread): C_k without a second pass. They sit in ints_'s reserved room at
        // its end, or after it when the first part held lines without a value; insert() then
        // moves them down over that gap (an overlapping move), or has nothing to move.
        const std::uint64_t offset = acc_ - c.pred;
        std::int64_t* d = c.ints.data();
        if (offset != 0) {
          const std::size_t half = c.summed / 2;
          help.give(offset, d, half);  // the other thread offsets the first half
          for (std::size_t i = half; i < c.summed; ++i)
            d[i] = static_cast<std::int64_t>(offset + static_cast<std::uint64_t>(d[i]));
        }
        finish();
        ints_.insert(ints_.end(), d, d + c.summed);
        acc_ = c.acc + offset;
        mag_ += c.mag;
        summed_ = ints_.size();
      } else {
        finish();
        // Back to the counts as read (exact modulo 2^64); build_phase sums them and names the line
        // where Σ|c| passes the limit.
        for (std::size_t i = c.summed; i-- > 1;)
          c.ints[i] = static_cast<std::int64_t>(static_cast<std::uint64_t>(c.ints[i]) -
                                                static_cast<std::uint64_t>(c.ints[i - 1]));
        c.ints[0] = static_cast<std::int64_t>(static_cast<std::uint64_t>(c.ints[0]) - c.pred);
        ints_.insert(ints_.end(), c.ints.begin(), c.ints.begin() + static_cast<std::ptrdiff_t>(c.summed));
      }
      from += static_cast<std::ptrdiff_t>(c.summed);
    }
    ints_.insert(ints_.end(), from, c.ints.end());
  } else
    reals_.insert(reals_.end(), c.reals.begin(), c.reals.end());
  if (time_col_)
    for (std::size_t i = 0; i < c.times.size(); ++i) {
      track_time(c.times[i]);
      if (time2_col_) track_time_pair(c.times[i], c.times2[i]);
    }
  if (temp_col_)
    for (double t : c.temps) temp_sum_ += t;
  if (temp_col_) temp_n_ += k;
  samples_ += k;
  line_ += k;
}

template <bool Integer>
void Reader::scan(const char* p) {
  // Texts of more than kParallelBytes are parsed in two parts once the layout is known: the
  // second on another thread, from the first line start after 55 % of the rest.
  bool split_pending = may_split();
  const char* limit = end_;
  Chunk chunk;
  MergeHelp help;  // before the thread, which may still use it when an exception unwinds this frame
  Thread worker;
  for (;;) {
    while (p < limit) {
      // A one-column pulse file is first read whole on this thread, to be kept in 32 bits
      // (int_run_narrow, faster than two parts writing 64 bits); it is split only if it is not.
      bool narrow_first = false;
      if constexpr (Integer) narrow_first = int_lines_ok_ && !narrow_tried_;
      if (split_pending && layout_known_ && !narrow_first) {
        split_pending = false;
        if (end_ - p > kParallelBytes) {
          // The other thread takes the last 45 %: with one-digit lines taken by the vectorised
          // path, mapping the values' pages is most of either part's time, and the other thread
          // first sums this part's counts (Chunk::pred) so that the merge has nothing to add;
          // 55/45 balances that on the 2-h file (halves: it waited ~0.8 ms for the other thread).
          const char* mid = p + (end_ - p) / kSplitDen * kSplitNum;
          const char* nl = static_cast<const char*>(std::memchr(mid, '\n', static_cast<std::size_t>(end_ - mid)));
          if (nl && nl + 1 < end_) {
            limit = nl + 1;
            if constexpr (Integer) {
              map_values(false);
              // The first part adds at most one value per line before `limit`: the second part's
              // values go right after that (ints_ holds one slot per line of the text, so both
              // fit and it is never reallocated). Each thread maps the pages it will write.
              const std::size_t at = ints_.size() + (lines_before(limit) - lines_before(p));
              chunk.ints.p = ints_.data() + at;
              const std::size_t room = ints_.capacity() - at;
              // The total the first part will end with, when its lines are all plain and
              // everything before is summed: then the other part's running sums start from it,
              // and the merge has nothing to add to them (the same values either way: the merge
              // adds the difference, modulo 2^64). Only with the AVX-512 kernel, which sums the
              // 2-h file's first part in ~0.7 ms; the portable one takes longer than the merge.
              const bool base_known = detail::digit_kernel() == detail::DigitKernel::Avx512 && sum_pending();
              worker = Thread([this, &chunk, &help, room, first = p, from = limit, base = acc_,
                                     base_known](std::stop_token st) {
                std::uint64_t first_sum = 0;
                if (base_known && detail::digit_sum(first, from, first_sum)) chunk.acc = chunk.pred = base + first_sum;
                detail::prefault(chunk.ints.p, room * sizeof(std::int64_t));
                scan_chunk<Integer>(from, chunk, st);
                help.parsed_then_help(st);
              });
              detail::prefault(ints_.data() + ints_.size(), (at - ints_.size()) * sizeof(std::int64_t));
            } else {
              const auto share = static_cast<double>(end_ - limit) / static_cast<double>(end_ - begin_);
              const auto expect = static_cast<std::size_t>(share * static_cast<double>(lines_) * 1.05) + 64;
              worker = Thread([this, &chunk, expect, from = limit](std::stop_token st) {
                // Room for the part's values, its pages mapped in one call on this thread.
                chunk.reals.reserve(expect);
                detail::prefault(chunk.reals.data(), expect * sizeof(double));
                scan_chunk<Integer>(from, chunk, st);
              });
              // The pages of the whole record's values, mapped here rather than before the scan,
              // so that the other part is parsed meanwhile.
              prefault_values();
            }
          }
        }
      }
      if constexpr (Integer) {
        if (int_lines_ok_) {
          int_run(p, limit);
          if (p >= limit) break;
        }
      }
      ++line_;
      if (layout_known_ && fast_line<Integer>(p)) continue;
      const char* eol = static_cast<const char*>(std::memchr(p, '\n', static_cast<std::size_t>(end_ - p)));
      if (careful_line(std::string_view(p, static_cast<std::size_t>(eol - p))) != LineKind::Data)
        new_run_ = true;
      else
        last_data_line_ = line_;
      p = eol + 1;
    }
    if (!worker.joinable()) break;
    {
      detail::ScopedTimer tj("read: join");
      // p == limit: the first part is done. Integers: wait until the other part is parsed (its
      // thread then waits to help with the merge); else for the thread's end.
      if constexpr (Integer)
        help.wait_parsed();
      else
        worker.join();
    }
    detail::ScopedTimer tm("read: merge");
    merge_chunk<Integer>(chunk, help, worker);  // the thread has ended when it returns
    p = chunk.stop;
    chunk = Chunk{};
    help.phase.store(0, std::memory_order_relaxed);
    limit = end_;
  }
  if (samples_ > 0 && runs_.empty()) runs_.emplace_back(0, first_data_line_);
}

// ---- after the scan -----------------------------------------------------------------------------

std::size_t Reader::line_of_sample(std::size_t k) const {
  auto it = std::upper_bound(runs_.begin(), runs_.end(), k,
                             [](std::size_t v, const auto& run) { return v < run.first; });
  if (it == runs_.begin()) return 0;
  --it;
  return it->second + (k - it->first);
}

void Reader::finish_rate() {
  if (opt_.rate_hz) {
    rate_hz_ = *opt_.rate_hz;
    rate_source_ = RateSource::Option;
  } else if (meta_rate_) {
    rate_hz_ = *meta_rate_;
    rate_source_ = RateSource::Metadata;
  } else if (time_col_) {
    // Candidate period: the median of the first steps (robust to one bad step); refined by the
    // whole span when that agrees, so long records give the rate to many digits.
    const std::vector<double>& h = head_times_;
    const std::size_t k = h.size() - 1;
    std::vector<double> steps(k);
    for (std::size_t i = 0; i < k; ++i) steps[i] = h[i + 1] - h[i];
    std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(k / 2), steps.end());
    const double candidate = steps[k / 2];
    if (!(candidate > 0)) {
      for (std::size_t i = 1; i < h.size(); ++i)
        if (!(h[i] > h[i - 1]))
          fail(line_of_sample(i), fmt::format("the time column does not increase: {} s at line {}, then {} s",
                                              h[i - 1], line_of_sample(i - 1), h[i]));
    }
    const double span = (t_prev_ - t_first_) / static_cast<double>(n_times_ - 1);
    const double period = std::abs(span - candidate) <= opt_.time_tolerance * candidate ? span : candidate;
    double rate = 1.0 / period;
    // A rate within 1 ppm of a whole number of Hz is that number (time stamps are printed rounded).
    if (rate >= 1 && std::abs(rate - std::round(rate)) <= 1e-6 * rate) rate = std::round(rate);
    rate_hz_ = rate;
    rate_source_ = RateSource::TimeColumn;
    if (!(rate >= kMinRateHz && rate <= kMaxRateHz))
      fail(first_data_line_, fmt::format("the time column's step of {:g} s gives a sample rate of {:g} Hz, outside the "
                                         "usable range {:g}..{:g} Hz",
                                         period, rate, kMinRateHz, kMaxRateHz));
  }
}

// A key that looks like a sample rate (or a pulse weight) but is not the one rwcalc reads, when
// nothing else gives the rate (or the weight): using 400 Hz (0.92″) then would be a silent choice.
void Reader::check_unread_keys() const {
  if (rate_source_ == RateSource::Default && unread_rate_key_)
    fail(unread_rate_key_->second,
         fmt::format("metadata '{}' looks like the sample rate, but rwcalc reads the rate from rate_hz, a time "
                     "column or --rate, and would otherwise use {:g} Hz; write '# rate_hz: VALUE' or give --rate",
                     unread_rate_key_->first, units::gl2d_rate_hz));
  if (integer_mode() && !opt_.scale_arcsec && !meta_scale_ && unread_scale_key_)
    fail(unread_scale_key_->second,
         fmt::format("metadata '{}' looks like the pulse weight, but rwcalc reads it from scale_arcsec_per_pulse "
                     "or --scale, and would otherwise use {:g} arcsec; write '# scale_arcsec_per_pulse: VALUE' or "
                     "give --scale",
                     unread_scale_key_->first, units::gl2d_arcsec_per_pulse));
}

// Two time columns are used only when they agree, every line, within the time tolerance.
void Reader::check_time_columns_agree() const {
  if (!time2_col_) return;
  const double period = 1.0 / rate_hz_;
  if (time_gap_max_ <= opt_.time_tolerance * period) return;
  fail(line_of_sample(time_gap_sample_),
       fmt::format("the time columns '{}' and '{}' disagree: {} {} and {} {} differ by {:g} s here (their largest "
                   "difference), more than the time tolerance ({} of the {:g}-s period); remove one of them",
                   header_[*time_col_], header_[*time2_col_], time_gap_t_, time_unit_->unit, time_gap_t2_,
                   time2_unit_->unit, time_gap_max_, opt_.time_tolerance, period));
}

void Reader::check_time_column() {
  if (!time_col_ || n_times_ < 2) return;
  const double period = 1.0 / rate_hz_;
  const double tol = opt_.time_tolerance * period;
  const double lo = period - tol, hi = period + tol;
  if (min_dt_ >= lo && max_dt_ <= hi) return;
  if (!store_times_) throw NeedTimes{};
  const std::size_t n = times_.size();
  const double* t = times_.data();
  // Branch-free check in blocks; locate the first bad step only when a block trips.
  constexpr std::size_t kBlock = 4096;
  for (std::size_t b = 1; b < n; b += kBlock) {
    const std::size_t e = std::min(n, b + kBlock);
    bool bad = false;
    for (std::size_t i = b; i < e; ++i) bad |= !((t[i] - t[i - 1]) >= lo && (t[i] - t[i - 1]) <= hi);
    if (!bad) continue;
    for (std::size_t i = b; i < e; ++i) {
      const double dt = t[i] - t[i - 1];
      if (dt >= lo && dt <= hi) continue;
      const std::size_t line = line_of_sample(i), prev = line_of_sample(i - 1);
      const std::string tcol = header_.empty() ? "column 1" : "'" + header_[*time_col_] + "'";
      if (rate_source_ == RateSource::Option || rate_source_ == RateSource::Metadata) {
        const double est = (t[n - 1] - t[0]) / static_cast<double>(n - 1);
        if (std::abs(est - period) > tol)
          fail(line, fmt::format("the sample rate {} Hz (from {}) is inconsistent with the time column {}, "
                                 "which steps by {} s (~{:.6g} Hz), e.g. {} s at line {} then {} s",
                                 rate_hz_, rate_source_ == RateSource::Option ? "--rate" : fmt::format("metadata at line {}", meta_rate_line_),
                                 tcol, est, 1.0 / est, t[i - 1], prev, t[i]));
      }
      if (dt == 0)
        fail(line, fmt::format("repeated time stamp {} s (also at line {}); no resampling is done", t[i], prev));
      if (dt < 0)
        fail(line, fmt::format("time goes backwards: {} s at line {}, then {} s", t[i - 1], prev, t[i]));
      if (dt > period)
        fail(line, fmt::format("gap in the time column: {} s at line {}, then {} s (a step of {:.6g} periods of "
                               "{} s; tolerance {}); no resampling is done",
                               t[i - 1], prev, t[i], dt / period, period, opt_.time_tolerance));
      fail(line, fmt::format("time step too short: {} s at line {}, then {} s (a step of {:.6g} periods of {} s; "
                             "tolerance {})",
                             t[i - 1], prev, t[i], dt / period, period, opt_.time_tolerance));
    }
  }
  fail(0, "the time column does not step by the sample period");  // not reached: a step tripped above
}

/// The mean of the rate samples x[1…] (x[0] is the phase's origin), rounded to a double.
double mean_rate_sample(const std::vector<double>& x) {
  long double sum = 0;
  for (std::size_t i = 1; i < x.size(); ++i) sum += x[i];
  return x.size() > 1 ? static_cast<double>(sum / static_cast<long double>(x.size() - 1)) : 0.0;
}

/// Floating data whose phase steps are all below kMinDataStep (limits.hpp) but not all zero:
/// the Allan variance would square them to zero and call the record noiseless.
void Reader::check_data_magnitude(const PhaseSeries& ph, const char* what) const {
  double largest = 0;
  for (std::size_t i = 1; i < ph.values.size(); ++i) largest = std::max(largest, std::abs(ph.values[i] - ph.values[i - 1]));
  if (largest > 0 && largest < kMinDataStep)
    fail(0, fmt::format("the {} data are too small to analyse: the largest step between samples is {:g} {}, below "
                        "{:g}, where the squares in the Allan variance underflow; give the data in a larger unit",
                        what, largest, ph.kind == PhaseKind::Clock ? "s" : "arcsec", kMinDataStep));
}

void Reader::build_phase(Recording& rec) {
  PhaseSeries& ph = rec.phase;
  ph.tau0_s = 1.0 / rate_hz_;
  const bool clock = (opt_.mode == InputMode::Angle && opt_.angle_unit == AngleUnit::Second) ||
                     (opt_.mode == InputMode::Rate && opt_.rate_unit == RateUnit::Unitless);
  ph.kind = clock ? PhaseKind::Clock : PhaseKind::Gyro;
  constexpr auto kLimit = static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
  // Floating phase beyond this (arcsec, or s for clocks) would overflow the squares of second
  // differences (|Δ²x| ≤ 4·max|x|) in the Allan variance; no instrument comes near it.
  constexpr double kMaxPhase = 1e150;

  switch (opt_.mode) {
    case InputMode::Pulses: {
      // C_0 = 0, C_k = Σ c_i, wrapping modulo 2^64 (PhaseSeries differences are modular, so an offset
      // never matters). Every second difference stays exact while Σ|c_i| < 2^63; beyond that the
      // record is refused.
      // ints_[0, summed_) are summed already (while parsing); acc_ and mag_ carry on from there.
      if (narrow_done_) {  // already summed, and every |C_k| < 2^30
        ph.counts32 = std::move(narrow_);
        break;
      }
      std::vector<std::int64_t>& c = ints_;
      std::uint64_t acc = acc_, mag = mag_;
      for (std::size_t i = std::max<std::size_t>(summed_, 1); i < c.size(); ++i) {
        const auto v = static_cast<std::uint64_t>(c[i]);
        acc += v;
        mag += c[i] < 0 ? (~v + 1) : v;
        c[i] = static_cast<std::int64_t>(acc);
        if (mag > kLimit) [[unlikely]]
          fail(line_of_sample(i - 1),
               "pulse counts too large to be summed exactly: the sum of |counts| exceeds 2^63-1 here");
      }
      ph.counts = std::move(c);
      break;
    }
    case InputMode::Counter: {
      // Unwrap: each step is (R_k − R_{k−1}) mod 2^B in [0, 2^B), so a backwards step counts as a wrap.
      std::vector<std::int64_t>& c = ints_;
      const int b = opt_.counter_bits;
      const std::uint64_t mask = b >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << b) - 1;
      std::uint64_t prev = static_cast<std::uint64_t>(c[0]) & mask, acc = 0, total = 0;
      std::size_t wraps = 0;
      c[0] = 0;
      for (std::size_t i = 1; i < c.size(); ++i) {
        const std::uint64_t r = static_cast<std::uint64_t>(c[i]) & mask;
        const std::uint64_t step = (r - prev) & mask;
        wraps += r < prev;
        prev = r;
        acc += step;
        c[i] = static_cast<std::int64_t>(acc);
        if (step > kLimit - total) [[unlikely]]
          fail(line_of_sample(i), fmt::format("the unwrapped counter advances by more than 2^63-1 counts here "
                                              "(a backwards step counts as a wrap of the {}-bit counter)",
                                              b));
        total += step;
      }
      rec.counter_wraps = wraps;
      ph.counts = std::move(c);
      break;
    }
    case InputMode::Angle: {
      double f = 1.0;
      switch (opt_.angle_unit) {
        case AngleUnit::Arcsec: case AngleUnit::Second: f = 1.0; break;
        case AngleUnit::Deg: f = units::arcsec_per_deg; break;
        case AngleUnit::Rad: f = units::arcsec_per_rad; break;
      }
      if (f != 1.0)
        for (double& v : reals_) v *= f;
      for (std::size_t i = 0; i < reals_.size(); ++i)
        if (!(std::abs(reals_[i]) <= kMaxPhase)) [[unlikely]]
          fail(line_of_sample(i), fmt::format("angle out of range: {} is beyond ±{:g} arcsec, where the Allan "
                                              "variance of the record would overflow",
                                              quoted(fmt::format("{:g}", reals_[i] / f)), kMaxPhase));
      ph.values = std::move(reals_);
      check_data_magnitude(ph, "angle");
      break;
    }
    case InputMode::Rate: {
      double f = 1.0;  // to ″/s (= °/h) for gyro data
      switch (opt_.rate_unit) {
        case RateUnit::DegPerHour: case RateUnit::Unitless: f = 1.0; break;
        case RateUnit::DegPerSecond: f = units::arcsec_per_deg; break;
        case RateUnit::RadPerSecond: f = units::arcsec_per_rad; break;
      }
      // SP 1065 phase from frequency: x_0 = 0, x_j = τ0·Σ_{i<j} (y_i − ȳ), accumulated in long
      // double. The mean rate ȳ goes into rate_offset (series.hpp): a phase that kept it would
      // grow to ȳ·T and round its noise away once the offset is many orders above the noise.
      std::vector<double>& x = reals_;
      const long double k = static_cast<long double>(ph.tau0_s) * f;
      const double mean = mean_rate_sample(x);
      long double acc = 0;
      for (std::size_t i = 1; i < x.size(); ++i) {
        const double y = x[i];
        acc += (static_cast<long double>(y) - mean) * k;
        x[i] = static_cast<double>(acc);
        const long double whole = acc + static_cast<long double>(mean) * k * static_cast<long double>(i);
        if (!(std::abs(whole) <= kMaxPhase)) [[unlikely]]
          fail(line_of_sample(i - 1),
               fmt::format("rate out of range: the accumulated phase reaches {:g} arcsec (beyond ±{:g}, where the "
                           "Allan variance would overflow) at this sample, {}",
                           static_cast<double>(whole), kMaxPhase, quoted(fmt::format("{:g}", y))));
      }
      ph.values = std::move(x);
      ph.rate_offset = mean * f;
      check_data_magnitude(ph, "rate");
      break;
    }
  }
}

Recording Reader::run(bool store_times) {
  store_times_ = store_times;
  const char* p = begin_;
  if (end_ - p >= 3 && static_cast<unsigned char>(p[0]) == 0xEF && static_cast<unsigned char>(p[1]) == 0xBB &&
      static_cast<unsigned char>(p[2]) == 0xBF)
    p += 3;
  // Room for every line at once: one '\n' per line.
  detail::LapTimer lt("read");
  const std::size_t lines = check_bytes(p);
  lines_ = lines;
  lt.lap("check bytes");
  // Slot 0 holds C_0 = 0 (pulses) or x_0 = 0 (rate); counter and angle samples are points already.
  // Their pages are mapped in one call: here, or, when the text may be parsed in two halves, once
  // the other half's thread has started (scan()).
  // Pulses may be kept in 32 bits (int_run_narrow): their 64-bit room is taken only once it is
  // known that they are not (map_values()).
  const bool defer = opt_.mode == InputMode::Pulses;
  if (integer_mode()) {
    ints_.reserve(defer ? 64 : lines + 1);
    if (opt_.mode == InputMode::Pulses) {
      ints_.push_back(0);
      summed_ = 1;
    }
  } else {
    reals_.reserve(lines + 1);
    if (opt_.mode == InputMode::Rate) reals_.push_back(0.0);
  }
  if (defer)
    values_unmapped_ = true;
  else if (!may_split())
    prefault_values();
  if (store_times_) times_.reserve(lines);
  lt.lap("reserve");

  // Header region and the first data line go through the careful path; it fixes the layout.
  if (integer_mode())
    scan<true>(p);
  else
    scan<false>(p);

  if (samples_ == 0) {
    if (header_line_)
      fail(header_line_, "no samples: the file has a header row but no data lines");
    fail(0, content_lines_ == 0 ? "empty file: no samples"
                                : "no samples: the file holds only comments and blank lines");
  }
  if (samples_ < 2)
    fail(first_data_line_, "only one sample; at least 2 are needed");

  lt.lap("scan");
  finish_rate();
  check_unread_keys();
  check_time_columns_agree();
  check_time_column();

  Recording rec;
  rec.samples = samples_;
  build_phase(rec);
  lt.lap("build phase");
  rec.phase.arcsec_per_count = opt_.scale_arcsec ? *opt_.scale_arcsec
                               : meta_scale_     ? *meta_scale_
                                                 : units::gl2d_arcsec_per_pulse;
  rec.rate_hz = rate_hz_;
  rec.rate_source = rate_source_;
  rec.metadata = std::move(metadata_);
  if (temp_n_ > 0)
    rec.temperature_c = static_cast<double>(temp_sum_ / static_cast<long double>(temp_n_));
  else if (meta_temp_)
    rec.temperature_c = meta_temp_;
  rec.column_name = header_.empty() ? fmt::format("column {}", value_col_ + 1) : header_[value_col_];
  if (time_col_) rec.time_column = header_.empty() ? std::string("column 1") : header_[*time_col_];
  rec.mode = opt_.mode;
  rec.line_runs = std::move(runs_);
  return rec;
}

void validate(const ReadOptions& o) {
  if (o.rate_hz && !(std::isfinite(*o.rate_hz) && *o.rate_hz > 0))
    throw UsageError(fmt::format("--rate must be a positive number of Hz, got {}", *o.rate_hz));
  if (o.scale_arcsec && !(std::isfinite(*o.scale_arcsec) && *o.scale_arcsec > 0))
    throw UsageError(fmt::format("--scale must be a positive number of arcsec, got {}", *o.scale_arcsec));
  if (o.counter_bits < 1 || o.counter_bits > 64)
    throw UsageError(fmt::format("--counter-bits must be 1..64, got {}", o.counter_bits));
  if (!(o.time_tolerance >= 0 && o.time_tolerance < 1))
    throw UsageError(fmt::format("--time-tolerance must be in [0, 1), got {}", o.time_tolerance));
}

Recording read_buffer(TextBuffer& buf, const std::string& source, const ReadOptions& options) {
  // Classic Mac line ends (CR only, no LF before the sentinel): read CR as the line end.
  if (buf.size() > 1 && !std::memchr(buf.data(), '\n', buf.size() - 1) && std::memchr(buf.data(), '\r', buf.size())) {
    std::replace(buf.data(), buf.data() + buf.size(), '\r', '\n');
    buf.segment_lines.clear();  // counted before the line ends changed
  }
  Recording rec;
  try {
    rec = Reader(buf, detail::display_name(source), options).run(false);
  } catch (const NeedTimes&) {
    // A time step is out of tolerance: read again keeping every stamp to name the first bad line.
    rec = Reader(buf, detail::display_name(source), options).run(true);
  }
  rec.source = source;
  return rec;
}

}  // namespace

// ---- public API ------------------------------------------------------------------------------------

Recording read_recording(const std::string& path, const ReadOptions& options) {
  validate(options);
  const unsigned threads = options.threads ? options.threads : std::thread::hardware_concurrency();
  // With a crew, a long regular file is loaded in halves by this thread and whichever lender is
  // free (this thread does both when none is).
  const unsigned load_threads = options.crew ? std::max(threads, 2u) : threads;
  // Pulses: the text goes to the end of the storage the 32-bit counts will take (TextBuffer's
  // host), the caller's when it lends one. A text with lines of other forms, or counts too large,
  // is read as before; only when the 32-bit read has already written over text is the file
  // loaded a second time (TextOverwritten).
  std::vector<std::int32_t> fresh;
  std::vector<std::int32_t>* host = nullptr;
  if (options.mode == InputMode::Pulses && path != "-") host = options.reuse ? options.reuse : &fresh;
  TextBuffer buf = [&] {
    detail::ScopedTimer t("read: load");
    return detail::load_source(path, load_threads, options.crew, host);
  }();
  try {
    return read_buffer(buf, path, options);
  } catch (const TextOverwritten&) {
  }
  buf = TextBuffer{};
  TextBuffer again = detail::load_source(path, load_threads, options.crew);
  return read_buffer(again, path, options);
}

Recording read_recording_text(std::string_view text, const std::string& name, const ReadOptions& options) {
  validate(options);
  TextBuffer buf = detail::load_text(text, detail::display_name(name));
  return read_buffer(buf, name, options);
}

std::vector<double> Recording::rates() const {
  const std::size_t n = phase.points() > 0 ? phase.points() - 1 : 0;
  std::vector<double> r(n);
  for (std::size_t i = 0; i < n; ++i) r[i] = phase.rate(i);
  return r;
}

std::size_t Recording::line_of_sample(std::size_t k) const noexcept {
  if (k >= samples) return 0;
  auto it = std::upper_bound(line_runs.begin(), line_runs.end(), k,
                             [](std::size_t v, const auto& run) { return v < run.first; });
  if (it == line_runs.begin()) return 0;
  --it;
  return it->second + (k - it->first);
}

std::size_t Recording::line_of_rate(std::size_t i) const noexcept {
  const bool readings = mode == InputMode::Counter || mode == InputMode::Angle;
  return line_of_sample(readings ? i + 1 : i);
}

InputMode parse_input_mode(std::string_view s) {
  if (s == "pulses") return InputMode::Pulses;
  if (s == "counter") return InputMode::Counter;
  if (s == "angle") return InputMode::Angle;
  if (s == "rate") return InputMode::Rate;
  throw UsageError(fmt::format("unknown --input '{}': expected pulses, counter, angle or rate", s));
}

AngleUnit parse_angle_unit(std::string_view s) {
  if (s == "arcsec") return AngleUnit::Arcsec;
  if (s == "deg") return AngleUnit::Deg;
  if (s == "rad") return AngleUnit::Rad;
  if (s == "s") return AngleUnit::Second;
  throw UsageError(fmt::format("unknown --angle-unit '{}': expected arcsec, deg, rad or s", s));
}

RateUnit parse_rate_unit(std::string_view s) {
  if (s == "deg/h") return RateUnit::DegPerHour;
  if (s == "deg/s") return RateUnit::DegPerSecond;
  if (s == "rad/s") return RateUnit::RadPerSecond;
  if (s == "1") return RateUnit::Unitless;
  throw UsageError(fmt::format("unknown --rate-unit '{}': expected deg/h, deg/s, rad/s or 1", s));
}

std::string_view to_string(InputMode m) {
  switch (m) {
    case InputMode::Pulses: return "pulses";
    case InputMode::Counter: return "counter";
    case InputMode::Angle: return "angle";
    case InputMode::Rate: return "rate";
  }
  return "?";
}

std::string_view to_string(RateSource s) {
  switch (s) {
    case RateSource::Option: return "option";
    case RateSource::Metadata: return "metadata";
    case RateSource::TimeColumn: return "time column";
    case RateSource::Default: return "default";
  }
  return "?";
}

std::string_view to_string(AngleUnit u) {
  switch (u) {
    case AngleUnit::Arcsec: return "arcsec";
    case AngleUnit::Deg: return "deg";
    case AngleUnit::Rad: return "rad";
    case AngleUnit::Second: return "s";
  }
  return "?";
}

std::string_view to_string(RateUnit u) {
  switch (u) {
    case RateUnit::DegPerHour: return "deg/h";
    case RateUnit::DegPerSecond: return "deg/s";
    case RateUnit::RadPerSecond: return "rad/s";
    case RateUnit::Unitless: return "1";
  }
  return "?";
}

}  // namespace rwcalc
