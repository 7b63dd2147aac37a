// Each line is split at the delimiter and its selected fields read with std::from_chars (exact int64
// for pulses and counters; correctly rounded doubles otherwise, through read_decimal). A data line of the known layout
// is taken as soon as its fields read; any other is looked at in the order that decides its error.
#include "line_parser.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>

#include <fmt/format.h>

#include "decimal.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/parallel.hpp"

namespace rwcalc::detail {

namespace {

// Does all of t read as a T?
template <class T>
bool reads_whole(std::string_view t, T& v) {
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

std::string_view unquote(std::string_view f) {
  if (f.size() >= 2 && f.front() == '"' && f.back() == '"') f = f.substr(1, f.size() - 2);
  return trim(f);
}

}  // namespace

LineParser::LineParser(std::string file, const ReadOptions& options) : file_(std::move(file)), opt_(options) {
  const int b = options.counter_bits;  // the readings a counter of b bits can give
  counter_lo_ = b >= 64 ? std::numeric_limits<std::int64_t>::min() : -(std::int64_t{1} << (b - 1));
  counter_max_ = b >= 63 ? std::numeric_limits<std::int64_t>::max() : (std::int64_t{1} << b) - 1;
}

void LineParser::fail(const std::string& message) const { throw InputError(file_, line_, message); }

LineKind LineParser::parse(std::string_view text, std::size_t line, Sample& s) {
  line_ = line;
  if (plain_integer(text, s) || delimited_data_line(text, s)) {
    ++content_lines_;
    return LineKind::Data;
  }
  if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
  // One pass over the line for the bytes that need a look: CR, semicolon, tab.
  bool special = false;
  for (const char c : text) special |= c == '\r' || c == ';' || c == '\t';
  if (const auto cr = special ? text.find('\r') : std::string_view::npos; cr != std::string_view::npos)
    fail(trf("stray carriage return (CR) at column {} inside the line", cr + 1));
  const std::string_view t = trim(text);
  if (t.empty()) return LineKind::Blank;
  ++content_lines_;
  if (t.front() == '#') {
    meta_.read(t.substr(1), line, file_);
    return LineKind::Comment;
  }
  if (!layout_known_ && layout_.header.empty()) {
    layout_.delim = Layout::detect_delimiter(t);
    layout_.layout_line = line;
  }
  if (special) check_foreign_delimiters(t);
  split(t);
  if (layout_known_ && fields_.size() == layout_.ncols && read_fields(fields_, s, false)) return LineKind::Data;
  if (header_row(t)) return LineKind::Header;
  if (stop_at_data_) return LineKind::Data;
  if (!layout_known_) {  // the first data line fixes the columns
    layout_.ncols = layout_.header.empty() ? fields_.size() : layout_.header.size();
    layout_known_ = true;
    first_data_line_ = line;
    const std::size_t where = layout_.header_line ? layout_.header_line : line;
    layout_.choose(opt_, where, file_);
    input_ = choose_input(opt_, layout_.header.empty() ? "" : layout_.header[layout_.value_col], file_, where);
  }
  if (fields_.size() != layout_.ncols)
    fail(trf("wrong number of columns: expected {} ({}-separated, as line {} has), found {}: {}", layout_.ncols,
             delim_name(layout_.delim), layout_.header_line ? layout_.header_line : first_data_line_, fields_.size(),
             quoted(t)));
  read_fields(fields_, s, true);
  return LineKind::Data;
}

namespace {

// An optional minus and 1–18 digits (no overflow) from p on, as far as they go; p is left after them.
// Bounded: without checking `end` while at least 20 bytes remain (a sign and 19 digits).
template <bool Bounded = true>
bool plain_value(const char*& p, const char* end, std::int64_t& v) {
  const bool neg = (!Bounded || p < end) && *p == '-';
  const char* digits = p + neg;
  std::uint64_t u = 0;
  const char* q = digits;
  for (; (!Bounded || q < end) && q - digits < 19; ++q) {
    const auto d = static_cast<unsigned char>(*q - '0');
    if (d > 9) break;
    u = u * 10 + d;  // 19 digits may wrap modulo 2^64: refused below
  }
  if (q == digits || q - digits > 18) return false;
  v = neg ? -static_cast<std::int64_t>(u) : static_cast<std::int64_t>(u);
  p = q;
  return true;
}

// [p, end) read by `run(from, to, out)`, which appends the lines it takes to `out` and returns where
// it stopped; with `split`, in two halves on two cores, cut after a line end: the second half's
// lines (gathered in `second`) count only if the first half reached them, so the lines taken and
// where the reading stops are those of one pass.
template <class T, class Run>
const char* in_halves(const char* p, const char* end, bool split, std::vector<T>& out, std::vector<T>& second,
                      const Run& run) {
  const auto half = static_cast<std::size_t>(end - p) / 2;
  const auto* cut = split ? static_cast<const char*>(std::memchr(p + half, '\n', half)) : nullptr;
  if (!cut) return run(p, end, out);
  const char* stop[2] = {};
  second.clear();
  parallel_for(2, [&](std::size_t h) { stop[h] = h == 0 ? run(p, cut + 1, out) : run(cut + 1, end, second); });
  if (stop[0] != cut + 1) return stop[0];
  out.insert(out.end(), second.begin(), second.end());
  return stop[1];
}

}  // namespace

// The one integer column of pulses or a counter, which plain_integer and plain_integer_lines read.
bool LineParser::plain_layout() const noexcept {
  return layout_known_ && layout_.ncols == 1 && layout_.roles[0] == Role::Value && integer_mode();
}

// The common data line, read without splitting: one integer column and the line just an optional
// minus and up to 18 digits (no overflow). Anything else goes the general way, which reports.
bool LineParser::plain_integer(std::string_view t, Sample& s) const {
  if (!plain_layout()) return false;
  const char* p = t.data();
  if (!plain_value(p, t.data() + t.size(), s.integer) || p != t.data() + t.size()) return false;
  return input_.mode != InputMode::Counter || (s.integer >= counter_lo_ && s.integer <= counter_max_);
}

// The lines of [p, end) while they are plain integers (a counter's within its readings), onto
// `out`, `max_lines` at most; returns where the first other line starts.
const char* LineParser::plain_run(const char* p, const char* end, std::vector<std::int64_t>& out,
                                  std::size_t max_lines) const {
  const bool counter = input_.mode == InputMode::Counter;
  const std::size_t before = out.size();
  // Lines with 22 bytes to spare (sign, 19 digits, CR, LF) need no look at `end`.
  const char* roomy = end - p > 22 ? end - 22 : p;
  for (const char* q = p; q < end && out.size() - before < max_lines; p = q) {
    std::int64_t v = 0;
    if (!(q < roomy ? plain_value<false>(q, end, v) : plain_value(q, end, v)) || q == end) break;
    if (*q == '\r' && q + 1 < end) ++q;  // CR LF
    if (*q != '\n' || (counter && (v < counter_lo_ || v > counter_max_))) break;
    ++q;
    out.push_back(v);
  }
  return p;
}

const char* LineParser::plain_integer_lines(const char* p, const char* end, std::size_t& line,
                                            std::vector<std::int64_t>& out, std::size_t max_lines) {
  if (!plain_layout()) return p;
  const std::size_t before = out.size();
  // Every line takes 2 bytes or more: with room for that many, the halves cannot pass max_lines.
  const bool split = end - p >= kSplitBytes && max_lines > static_cast<std::size_t>(end - p) / 2;
  p = in_halves(p, end, split, out, second_half_, [&](const char* from, const char* to, std::vector<std::int64_t>& o) {
    return plain_run(from, to, o, max_lines);
  });
  line += out.size() - before;
  content_lines_ += out.size() - before;
  return p;
}

namespace {

constexpr bool blank(char c) noexcept { return c == ' ' || c == '\t'; }

// A field no column wants, from q to its end (the delimiter, a blank when blank-separated, the line
// end); nullptr at a byte that sends the line the general way (a CR inside it, a foreign delimiter).
const char* skip_field(const char* q, const char* end, char d, bool blanks) noexcept {
  for (; q < end; ++q) {
    const char c = *q;
    if (c == '\n' || (blanks ? blank(c) : c == d)) return q;
    if (c == '\r') return q + 1 < end && q[1] == '\n' ? q : nullptr;
    if (c == ';' || c == '\t') return nullptr;
  }
  return q;
}

// One line of `slot_of_col.size()` fields from q on, its wanted fields' values onto `out`: where the
// next line starts, or nullptr when the general way must take the line (it may still accept it, as
// with blanks around a field or a leading plus, or report it). A value is the whole field read by
// read_decimal, as the general way reads it: the bytes that end a field (delimiter, blank, CR, LF)
// cannot continue a number, so the value read up to them is the field's own.
const char* decimal_line(const char* q, const char* end, char d, bool blanks, const std::vector<int>& slot_of_col,
                         std::vector<double>& out) {
  if (blanks)
    while (q < end && blank(*q)) ++q;
  if (q == end || *q == '#' || blank(*q)) return nullptr;
  for (std::size_t c = 0; c < slot_of_col.size(); ++c) {
    if (c > 0) {
      if (q == end || (blanks ? !blank(*q) : *q != d)) return nullptr;
      ++q;
      if (blanks)
        while (q < end && blank(*q)) ++q;
    }
    if (slot_of_col[c] < 0) {
      if (!(q = skip_field(q, end, d, blanks))) return nullptr;
      continue;
    }
    double v = 0;
    const auto r = read_decimal(q, end, v);
    if (r.ec != std::errc() || !std::isfinite(v)) return nullptr;
    out.push_back(v);
    q = r.ptr;
  }
  if (blanks)
    while (q < end && blank(*q)) ++q;
  else if (blank(q[-1]))  // a blank ending the line: the general way
    return nullptr;
  if (q < end && *q == '\r') ++q;
  return q < end && *q == '\n' ? q + 1 : nullptr;
}

}  // namespace

// The lines of [p, end) while they are common data lines, onto `out`; returns where the first other
// line starts.
const char* LineParser::decimal_run(const char* p, const char* end, const std::vector<int>& slot_of_col,
                                    std::vector<double>& out, std::size_t max_lines) const {
  const bool blanks = layout_.delim == Delim::Blanks;
  const char d = layout_.delim == Delim::Comma ? ',' : layout_.delim == Delim::Semicolon ? ';' : '\t';
  for (std::size_t lines = 0; p < end && lines < max_lines; ++lines) {
    const std::size_t row = out.size();
    const char* next = decimal_line(p, end, d, blanks, slot_of_col, out);
    if (!next) {
      out.resize(row);
      break;
    }
    p = next;
  }
  return p;
}

const char* LineParser::plain_decimal_lines(const char* p, const char* end, std::size_t& line,
                                            const std::vector<int>& slot_of_col, std::size_t slots,
                                            std::vector<double>& rows, std::size_t max_lines) {
  if (!layout_known_ || integer_mode() || slot_of_col.size() != layout_.ncols) return p;
  const std::size_t before = rows.size();
  const bool split = end - p >= kSplitBytes && max_lines > static_cast<std::size_t>(end - p) / 2;
  p = in_halves(p, end, split, rows, second_rows_, [&](const char* from, const char* to, std::vector<double>& o) {
    return decimal_run(from, to, slot_of_col, o, max_lines);
  });
  line += (rows.size() - before) / slots;
  return p;
}

void LineParser::assign(Sample& s, Role role, double v) const noexcept {
  (role == Role::Value     ? s.real
   : role == Role::Time    ? s.time
   : role == Role::Time2   ? s.time2
   : role == Role::Nanosec ? s.nanosec
                           : s.temperature) = v;
}

void LineParser::join_stamp(Sample& s) const noexcept {
  if (layout_.nanosec_col) s.time = s.time * 1e9 + s.nanosec;  // one stamp in ns
}

Sample LineParser::row_sample(const double* row, const std::vector<int>& slot_of_col) const noexcept {
  Sample s;
  for (std::size_t c = 0; c < layout_.ncols; ++c)
    if (layout_.roles[c] != Role::Skip) assign(s, layout_.roles[c], row[slot_of_col[c]]);
  join_stamp(s);
  return s;
}

// The common line of a delimited file whose columns are known, with one look at each byte: split at
// the delimiter and taken when nothing in it needs the general way (a CR inside, another delimiter,
// blanks around the line, a comment) and its selected fields read. Any other line goes the general
// way, which decides and reports it exactly as if this path did not exist. A parser that follows a
// lead reads its fields from the lead's split of the same line.
bool LineParser::delimited_data_line(std::string_view text, Sample& s) {
  if (!layout_known_ || layout_.delim == Delim::Blanks) return false;
  if (lead_ && lead_->split_line_ == line_)
    return lead_->fields_.size() == layout_.ncols && read_fields(lead_->fields_, s, false);
  if (!text.empty() && text.back() == '\r') text.remove_suffix(1);
  const auto edge = [](char c) { return c == ' ' || c == '\t'; };
  if (text.empty() || edge(text.front()) || edge(text.back()) || text.front() == '#') return false;
  const char d = layout_.delim == Delim::Comma ? ',' : layout_.delim == Delim::Semicolon ? ';' : '\t';
  fields_.clear();
  std::size_t start = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == d) {
      fields_.push_back(trim(text.substr(start, i - start), false));
      start = i + 1;
    } else if (c == '\r' || c == ';' || c == '\t') {
      return false;
    }
  }
  fields_.push_back(trim(text.substr(start), false));
  split_line_ = line_;
  return fields_.size() == layout_.ncols && read_fields(fields_, s, false);
}

void LineParser::check_foreign_delimiters(std::string_view line) const {
  const std::string_view foreign = layout_.delim == Delim::Comma       ? ";\t"
                                   : layout_.delim == Delim::Semicolon ? "\t"
                                                                       : ";";
  const auto at = line.find_first_of(foreign);
  if (at == std::string_view::npos) return;
  fail(trf("mixed delimiters: the file is {}-separated (from line {}) but this line has a {} at column {}: {}",
           delim_name(layout_.delim), layout_.layout_line, line[at] == '\t' ? "tab" : "semicolon", at + 1,
           quoted(line)));
}

void LineParser::split(std::string_view line) {
  fields_.clear();
  if (layout_.delim == Delim::Blanks) {
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
  const char d = layout_.delim == Delim::Comma ? ',' : layout_.delim == Delim::Semicolon ? ';' : '\t';
  for (std::size_t start = 0;;) {
    const auto e = line.find(d, start);
    fields_.push_back(trim(line.substr(start, e == std::string_view::npos ? e : e - start), false));
    if (e == std::string_view::npos) break;
    start = e + 1;
  }
}

// An all-text line is the header row before the data. Inside the data it is a second header row
// when it repeats the header or has several fields; a lone word in a one-column file is just text
// in a numeric column.
bool LineParser::header_row(std::string_view t) {
  const bool comma_ok = layout_.delim != Delim::Comma;
  const bool any_numeric =
      std::any_of(fields_.begin(), fields_.end(), [&](std::string_view f) { return looks_numeric(f, comma_ok); });
  const bool any_text = std::any_of(fields_.begin(), fields_.end(), [](std::string_view f) { return !f.empty(); });
  auto repeats_header = [&] {
    const auto& h = layout_.header;
    if (h.empty() || fields_.size() != h.size()) return false;
    for (std::size_t c = 0; c < fields_.size(); ++c)
      if (!iequals(unquote(fields_[c]), h[c])) return false;
    return true;
  };
  if (any_numeric || !any_text || (layout_known_ && fields_.size() < 2 && !repeats_header())) return false;
  if (layout_known_)
    fail(trf("a second header row inside the data: {} (the first is at line {}); were two files joined?", quoted(t),
             layout_.header_line ? layout_.header_line : first_data_line_));
  if (!layout_.header.empty())
    fail(trf("a second header row {} (the first is at line {}); only one is allowed", quoted(t), layout_.header_line));
  for (const auto f : fields_) layout_.header.emplace_back(unquote(f));
  layout_.header_line = line_;
  return true;
}

// The selected fields, in column order: false at the first that does not read (with `report`,
// its InputError instead).
bool LineParser::read_fields(const std::vector<std::string_view>& fields, Sample& s, bool report) {
  for (std::size_t c = 0; c < layout_.ncols; ++c)
    if (layout_.roles[c] != Role::Skip && !read_field(fields[c], layout_.roles[c], s, report)) return false;
  join_stamp(s);
  return true;
}

bool LineParser::read_field(std::string_view f, Role role, Sample& s, bool report) {
  if (f.empty()) {
    if (report) fail(trf("empty field in {}", layout_.describe(role)));
    return false;
  }
  std::string_view t = f;
  if (t.size() > 1 && t.front() == '+' && t[1] != '-' && t[1] != '+') t.remove_prefix(1);
  if (role == Role::Value && integer_mode()) return read_integer(f, t, s, report);
  const std::string_view n = normalise_decimal(t, layout_.delim != Delim::Comma, scratch_);
  double v = 0;
  const auto r = read_decimal(n.data(), n.data() + n.size(), v);
  if (r.ptr == n.data() + n.size() && r.ec == std::errc() && std::isfinite(v)) {
    assign(s, role, v);
    return true;
  }
  if (!report) return false;
  const std::string col = layout_.describe(role);
  if (r.ptr != n.data() + n.size() || r.ec == std::errc::invalid_argument)
    fail(trf("not a number in {}: {}", col, quoted(f)));
  if (r.ec == std::errc::result_out_of_range) fail(trf("number out of range in {}: {}", col, quoted(f)));
  fail(trf("non-finite value in {}: {}", col, quoted(f)));
}

// A pulse count or counter reading: exact, as an int64 (a 64-bit counter's reading above 2^63-1
// as the same residue modulo 2^64).
bool LineParser::read_integer(std::string_view f, std::string_view t, Sample& s, bool report) {
  const bool counter = input_.mode == InputMode::Counter;
  std::uint64_t u = 0;
  if (reads_whole(t, s.integer)) {
    if (!counter || (s.integer >= counter_lo_ && s.integer <= counter_max_)) return true;
    if (report) fail(trf("counter reading {} does not fit a {}-bit counter", quoted(f), opt_.counter_bits));
    return false;
  }
  if (counter && opt_.counter_bits == 64 && t.front() != '-' && reads_whole(t, u)) {
    s.integer = static_cast<std::int64_t>(u);
    return true;
  }
  if (!report) return false;
  const std::string col = layout_.describe(Role::Value);
  double d = 0;
  if (reads_whole(normalise_decimal(t, layout_.delim != Delim::Comma, scratch_), d) && !std::isfinite(d))
    fail(trf("non-finite value in {}: {}", col, quoted(f)));
  const bool neg = t.front() == '-';
  if (t.size() > static_cast<std::size_t>(neg) &&
      std::all_of(t.begin() + neg, t.end(), [](char c) { return c >= '0' && c <= '9'; }))
    fail(trf("number out of range of a 64-bit integer in {}: {}", col, quoted(f)));
  if (looks_numeric(f, layout_.delim != Delim::Comma))
    fail(trf("{} counts must be integers: {} in {}{}", counter ? "counter" : "pulse", quoted(f), col,
             opt_.mode                   ? std::string()
             : !opt_.unit_advice.empty() ? std::string(opt_.unit_advice)
                                         : std::string(" (pulses is the default input; for rate or angle samples give "
                                                       "--input rate or --input angle, or a column name with a unit "
                                                       "such as gyro_x_dps)")));
  fail(trf("not a number in {}: {}", col, quoted(f)));
}

}  // namespace rwcalc::detail
