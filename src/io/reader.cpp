// The recording reader: text arrives in pieces (TextSource), is cut into lines, and each line goes
// through the one LineParser (a stretch of common data lines in bulk, every column at once); the
// reader keeps only the selected column's values (8 bytes per sample) and running statistics of the
// time column, then checks the rate and builds the phase.
// What it keeps grows within the memory ceiling (SampleMemory); a record beyond it is refused.
#include "rwcalc/reader.hpp"
#include "rwcalc/i18n.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <limits>
#include <memory>
#include <span>

#include <fmt/format.h>

#include "bag.hpp"
#include "line_parser.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/limits.hpp"
#include "rwcalc/memory.hpp"
#include "rwcalc/parallel.hpp"
#include "rwcalc/printable.hpp"
#include "rwcalc/progress.hpp"
#include "rwcalc/units.hpp"
#include "sample_memory.hpp"
#include "text_source.hpp"

namespace rwcalc {

namespace {

using detail::Sample;

// The time column, checked without keeping every stamp (all in the column's own unit): its first
// stamps (the rate estimate), its span, each step that is the smallest or the largest so far (the
// first step outside any band around the period is among those, so it is found once the period is
// known), and the jitter against the median of the first steps, counted as the stamps arrive.
struct TimeTrack {
  struct Step {
    std::size_t sample;
    double before, after;  // the stamps of samples `sample` − 1 and `sample`
  };
  static constexpr std::size_t kHead = 102;
  std::vector<double> head;
  double first = 0, last = 0;
  double min_dt = std::numeric_limits<double>::infinity(), max_dt = -std::numeric_limits<double>::infinity();
  std::size_t n = 0;
  std::vector<Step> lows, highs;
  std::vector<Step> long_steps;  // over 1.25 median steps: the candidate gaps of `--gaps segments`
  double max_no_gap = -std::numeric_limits<double>::infinity();  // the longest step below 1.5 median
  double tolerance = 0.01;                                       // fraction of the median step
  double median = 0;                                             // of the first steps; 0 until known
  double shift = 0;  // the first step: Σ(dt − shift) and Σ(dt − shift)² keep their digits
  long double sum1 = 0, sum2 = 0;
  std::size_t off = 0;  // steps off the median by more than the tolerance
  bool median_known = false;
  detail::SampleMemory* memory = nullptr;  // where the lists of steps grow

  void add(double t) {
    if (n == 0) first = t;
    if (n > 0) step(t - last, t);
    if (n < kHead) head.push_back(t);
    last = t;
    ++n;
    if (n == kHead) find_median();
  }
  void step(double dt, double t) {
    if (n == 1) shift = dt;
    if (dt < min_dt) min_dt = dt, memory->keep(lows, {n, last, t});
    if (dt > max_dt) max_dt = dt, memory->keep(highs, {n, last, t});
    const long double d = static_cast<long double>(dt) - shift;
    sum1 += d, sum2 += d * d;
    if (median > 0) count(dt);
    if (median_known && dt > 1.25 * median) memory->keep(long_steps, {n, last, t});
    if (!median_known || dt < 1.5 * median) max_no_gap = std::max(max_no_gap, dt);
  }
  void count(double dt) { off += std::abs(dt - median) > tolerance * median; }
  // The median of the first steps (robust to one bad step); the steps so far are counted against it.
  void find_median() {
    median_known = true;
    const std::size_t k = head.size() - 1;
    std::vector<double> steps(k);
    for (std::size_t i = 0; i < k; ++i) steps[i] = head[i + 1] - head[i];
    std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(k / 2), steps.end());
    median = steps[k / 2];
    if (median > 0)
      for (std::size_t i = 0; i < k; ++i) count(head[i + 1] - head[i]);
    max_no_gap = -std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < k; ++i) {
      const double dt = head[i + 1] - head[i];
      if (dt > 1.25 * median) long_steps.push_back({i + 1, head[i], head[i + 1]});
      if (dt < 1.5 * median) max_no_gap = std::max(max_no_gap, dt);
    }
  }
  // Over the steps that are not gaps (1.5 median steps or more: refused, or segment boundaries).
  [[nodiscard]] TimeJitter jitter() const {
    long double s1 = sum1, s2 = sum2;
    std::size_t steps = n - 1, off_steps = off;
    for (const Step& g : long_steps) {
      const double dt = g.after - g.before;
      if (!(dt >= 1.5 * median)) continue;
      const long double d = static_cast<long double>(dt) - shift;
      s1 -= d, s2 -= d * d, --steps, --off_steps;
    }
    if (steps == 0) return {};
    const auto k = static_cast<long double>(steps), c = static_cast<long double>(median) - shift;
    const long double ss = std::max(0.0L, s2 - 2 * c * s1 + k * c * c);
    const double longest = std::isfinite(max_no_gap) ? max_no_gap : median;
    return {off_steps, std::max(longest - median, median - min_dt) / median,
            static_cast<double>(std::sqrt(ss / k) / static_cast<long double>(median))};
  }
  [[nodiscard]] Step first_outside(double lo, double hi) const {
    const auto low = std::find_if(lows.begin(), lows.end(), [&](const Step& s) { return !(s.after - s.before >= lo); });
    const auto high =
        std::find_if(highs.begin(), highs.end(), [&](const Step& s) { return !(s.after - s.before <= hi); });
    if (low == lows.end()) return *high;
    return high != highs.end() && high->sample < low->sample ? *high : *low;
  }
};

template <class E, std::size_t Size = 4>
using NameTable = std::pair<E, std::string_view>[Size];
constexpr NameTable<InputMode, 5> kModes{{InputMode::Pulses, "pulses"},
                                         {InputMode::Counter, "counter"},
                                         {InputMode::Angle, "angle"},
                                         {InputMode::Rate, "rate"},
                                         {InputMode::Increment, "increment"}};
constexpr NameTable<AngleUnit, 5> kAngleUnits{{AngleUnit::Arcsec, "arcsec"},
                                              {AngleUnit::Deg, "deg"},
                                              {AngleUnit::Rad, "rad"},
                                              {AngleUnit::Second, "s"},
                                              {AngleUnit::MetrePerSecond, "m/s"}};
constexpr NameTable<RateUnit, 8> kRateUnits{{RateUnit::DegPerHour, "deg/h"},
                                            {RateUnit::DegPerSecond, "deg/s"},
                                            {RateUnit::RadPerSecond, "rad/s"},
                                            {RateUnit::Unitless, "1"},
                                            {RateUnit::MetrePerSecond2, "m/s^2"},
                                            {RateUnit::G, "g"},
                                            {RateUnit::MilliG, "mg"},
                                            {RateUnit::MicroG, "ug"}};
// Marked for the catalogue: shown translated (tr) where text names the rate's source.
constexpr NameTable<RateSource> kRateSources{{RateSource::Option, N_("option")},
                                             {RateSource::Metadata, N_("metadata")},
                                             {RateSource::TimeColumn, N_("time column")},
                                             {RateSource::Default, N_("default")}};

template <class E, std::size_t Size>
E parse_name(const NameTable<E, Size>& table, std::string_view s, std::string_view option) {
  std::string names;
  for (const auto& [value, name] : table) {
    if (name == s) return value;
    names += fmt::format("{}{}", names.empty() ? "" : &name == &table[Size - 1].second ? " or " : ", ", name);
  }
  throw UsageError(trf("unknown {} '{}': expected {}", option, s, names));
}

template <class E, std::size_t Size>
std::string_view name_of(const NameTable<E, Size>& table, E e) {
  for (const auto& [value, name] : table)
    if (value == e) return name;
  return "?";
}

using Runs = std::vector<std::pair<std::size_t, std::size_t>>;

// The largest --time-tolerance the command line takes.
constexpr double kMaxTimeTolerance = 0.5;

// Where a larger --time-tolerance (at most kMaxTimeTolerance) would accept a deviation of
// `fraction` of the period, the hint that says so; else nothing.
std::string tolerance_hint(double fraction) {
  if (!(fraction < kMaxTimeTolerance)) return "";
  return trf(" (a --time-tolerance of {:.3g} or more would accept it)", fraction * 1.001);
}

// The line of sample k in runs of consecutive data lines (Recording::line_runs); 0 if before them.
std::size_t line_in_runs(const Runs& runs, std::size_t k) {
  auto it = std::upper_bound(runs.begin(), runs.end(), k, [](std::size_t v, const auto& run) { return v < run.first; });
  return it == runs.begin() ? 0 : std::prev(it)->second + (k - std::prev(it)->first);
}

class Reader {
 public:
  Reader(const std::string& file, const ReadOptions& o)
      : parser_(file, o), opt_(o), ceiling_(o.memory ? *o.memory : default_memory_ceiling()), memory_(ceiling_.bytes) {
    times_.tolerance = o.time_tolerance;
    times_.memory = &memory_;
  }
  void read(detail::TextSource& src) {
    try {
      read_lines(src);
    } catch (const detail::CeilingReached&) {
      Reader& full = reached_ ? *reached_ : *this;
      full.text_taken_ = text_taken_;
      full.text_estimate_ = text_estimate_;
      full.refuse_memory();
    }
  }
  void read_bag(detail::BagStream& bag);
  /// Read another column of the same text in the same pass: `f` gets every line after this reader.
  void lead(Reader& f) {
    f.parser_.follow(parser_);
    followers_.push_back(&f);
  }
  Recording finish();

 private:
  [[noreturn]] void fail(std::size_t line, const std::string& message) const {
    throw InputError(parser_.file(), line, message);
  }
  [[nodiscard]] const detail::InputChoice& in() const { return parser_.input(); }
  [[nodiscard]] bool integer_mode() const { return in().mode == InputMode::Pulses || in().mode == InputMode::Counter; }
  [[nodiscard]] std::size_t line_of_sample(std::size_t k) const { return line_in_runs(runs_, k); }
  void read_lines(detail::TextSource& src);
  [[noreturn]] void refuse_memory() const;
  [[noreturn]] void refuse_memory_bag(const detail::BagStream& bag) const;
  std::size_t take_lines(std::string& buf, bool at_end);
  bool decide_line_end(std::string_view s, bool at_end);
  std::size_t mac_limit(std::string& buf, std::size_t from, bool at_end) const;
  void line(std::string_view text) {
    Sample s;
    if (parser_.parse(text, ++line_, s) == detail::LineKind::Data)
      push(s);
    else
      new_run_ = true;
    for (Reader* f : followers_) {
      reached_ = f;  // a ceiling reached in here is the follower's
      f->line(text);
    }
    reached_ = nullptr;
  }
  void push(const Sample& s);
  void track(const Sample& s, std::size_t sample);
  [[nodiscard]] bool in_run() const;
  const char* decimal_lines(const char* p, const char* end);
  void take_rows(const std::vector<double>& rows, std::size_t slots, const std::vector<int>& slot_of_col,
                 std::size_t n);
  void bag_message(const detail::ImuMessage& m);
  // Room for the samples the text likely holds, judged from its first lines, so that a long record
  // is not copied as it grows (within the ceiling: only an estimate).
  void reserve(double lines) {
    const auto n = static_cast<std::size_t>(std::min(lines * 1.05 + 2, 0x1p60));
    integer_mode() ? memory_.reserve(ints_, n) : memory_.reserve(reals_, n);
    for (Reader* f : followers_) f->reserve(lines);
  }
  void start_samples(const Sample& s);
  [[nodiscard]] const detail::TimeName* time_unit_of(const detail::TimeName* named, double first,
                                                     detail::Role role) const;
  [[nodiscard]] std::string stamp(double t) const { return fmt::format("{} {}", t, tunit_->unit); }
  void finish_rate();
  void rate_from_time_column();
  void note_time_column(Recording& rec) const;
  [[noreturn]] void fail_step(const TimeTrack::Step& bad, double period) const;
  void check_unread_keys() const;
  void check_time_columns_agree() const;
  void check_time_column() const;
  void split_at_gaps(Recording& rec) const;
  void check_rate_against_time_column(const TimeTrack::Step& bad, double period) const;
  void build_counts(PhaseSeries& ph, std::size_t& wraps);
  void build_values(PhaseSeries& ph);
  void check_data_magnitude(const PhaseSeries& ph, const char* what) const;
  void check_angle_steps(const PhaseSeries& ph, const std::vector<double>& x, double f) const;
  void check_rates(const PhaseSeries& ph, const std::vector<double>& x, double f) const;

  detail::LineParser parser_;
  const ReadOptions& opt_;
  const MemoryCeiling ceiling_;
  detail::SampleMemory memory_;
  std::size_t text_taken_ = 0;     // bytes of text cut into lines so far
  std::size_t text_estimate_ = 0;  // the text's likely length as of the pieces cut into lines
  const detail::Layout& layout_ = parser_.layout();
  bool started_ = false;
  char eol_ = 0;  // the line end: LF, or CR for classic Mac text (no LF but maybe a last one); 0 undecided
  std::size_t first_cr_column_ = 0;  // Mac text: where the first CR is on line 1
  std::size_t line_ = 0, samples_ = 0;
  bool new_run_ = true;
  Runs runs_;
  std::vector<std::int64_t> ints_;  // pulses (after C_0) or counter readings
  std::vector<double> reals_;       // angle samples, or rate samples after x_0
  TimeTrack times_;
  const detail::TimeName *tunit_ = nullptr, *tunit2_ = nullptr;  // the time columns' units
  // Two time columns: where they differ most, and the two stamps there in their own units.
  double gap_max_ = 0, gap_t_ = 0, gap_t2_ = 0;
  std::size_t gap_sample_ = 0;
  long double temp_sum_ = 0;
  std::size_t temp_n_ = 0;
  double rate_hz_ = units::gl2d_rate_hz;
  RateSource rate_source_ = RateSource::Default;
  std::vector<Reader*> followers_;  // other columns read in the same pass
  // The lead's bulk reading of common lines: each column any reader of the pass wants has a slot
  // (−1: none) in the rows of values read.
  std::vector<int> slot_of_col_;
  std::size_t slots_ = 0;
  std::vector<double> rows_;
  Reader* reached_ = nullptr;  // the follower being given a line
};

void Reader::read_lines(detail::TextSource& src) {
  Progress progress(trf("reading {}", printable(src.name())), src.stored_size(), opt_.progress,
                    Progress::Measure::Bytes);
  std::string buf, next;
  // The next piece is read, checked and digested beside the parsing of this one (src is touched
  // by that stage alone while it runs); its error, if any, comes after this piece's.
  for (bool more = src.read(buf), first = true;;) {
    progress.advance(src.taken_bytes() - progress.done());
    text_estimate_ = src.size_estimate();  // as of the pieces parsed, not the one read ahead
    const auto estimate = static_cast<double>(text_estimate_);
    bool ahead = false;
    std::size_t taken = 0;
    run_beside([&] { taken = take_lines(buf, !more); },
               [&] {
                 next.clear();
                 ahead = more && src.read(next);
               });
    text_taken_ += taken;
    if (first && parser_.layout_known()) reserve(estimate / static_cast<double>(taken) * static_cast<double>(line_));
    first = first && !parser_.layout_known();
    buf.erase(0, taken);
    if (!more) break;
    buf += next;
    more = ahead;
  }
  if (!buf.empty()) line(buf);  // the last line, without a line end
}

// A bag reads as the `rostopic echo -p` CSV of its Imu topic: the header row and the first message
// go through the one parser as text (which fixes the columns, units and notes as for the CSV), every
// later message goes in as the Sample that parsing its line would give (numbers printed shortest
// round-trip read back exactly), each message one line.
void Reader::read_bag(detail::BagStream& bag) {
  try {
    Progress progress(trf("reading {}", printable(bag.name())), bag.size(), opt_.progress, Progress::Measure::Bytes);
    std::string header(detail::kBagStampColumn);
    header += fmt::format(",{}", detail::kBagReceiveColumn);
    for (const std::string_view f : detail::kImuFieldColumns) header += fmt::format(",{}", f);
    line(header);
    std::vector<detail::ImuMessage> batch;
    while (bag.next(batch)) {
      for (const detail::ImuMessage& m : batch) {
        if (samples_ > 0) {
          bag_message(m);
          continue;
        }
        const double* v = m.values;
        line(fmt::format("{},{},{},{},{},{},{},{}", m.stamp_ns, m.receive_ns, v[0], v[1], v[2], v[3], v[4], v[5]));
        if (integer_mode()) fail(line_, tr("a bag's channels are rates (rad/s, m/s^2), not pulse counts"));
        reserve(static_cast<double>(bag.topic().messages));
      }
      progress.advance(bag.taken() - std::min(bag.taken(), progress.done()));
    }
    if (samples_ == 0) fail(0, trf("topic '{}' of this {} has no messages", bag.topic().name, bag.format()));
  } catch (const detail::CeilingReached&) {
    Reader& full = reached_ ? *reached_ : *this;
    full.refuse_memory_bag(bag);
  }
}

void Reader::bag_message(const detail::ImuMessage& m) {
  ++line_;
  const auto field = [&m](std::size_t col) {
    return col == 0   ? static_cast<double>(m.stamp_ns)
           : col == 1 ? static_cast<double>(m.receive_ns)
                      : m.values[col - 2];
  };
  Sample s;
  s.real = field(layout_.value_col);
  if (layout_.time_col) s.time = field(*layout_.time_col);
  if (layout_.time2_col) s.time2 = field(*layout_.time2_col);
  push(s);
  for (Reader* f : followers_) {
    reached_ = f;
    f->bag_message(m);
  }
  reached_ = nullptr;
}

// The samples kept have reached the ceiling: the memory the whole record needs, judged from the
// input's size (the text read so far gave the samples kept), else only "more than". The room made
// ahead of a piece is not counted: it is not the record's.
void Reader::refuse_memory() const {
  const double part = static_cast<double>(text_estimate_) / static_cast<double>(std::max<std::size_t>(text_taken_, 1));
  const std::size_t kept = ints_.size() * sizeof(std::int64_t) + reals_.size() * sizeof(double);
  const double needed = static_cast<double>(kept) * part;
  const std::string ceiling =
      trf("the memory ceiling of {} ({})", format_memory(static_cast<double>(ceiling_.bytes)), ceiling_.origin);
  const std::string remedy = trf("give {} SIZE if the machine has the memory, or cut the record", kMaxMemoryOption);
  if (needed > static_cast<double>(ceiling_.bytes))
    fail(line_, trf("the record needs about {} of memory for its samples (about {:.0f} samples, judged from the "
                    "file's size), more than {}; {}",
                    format_memory(needed), static_cast<double>(samples_) * part, ceiling, remedy));
  fail(line_, trf("the record needs more than {} of memory for its samples: {} is reached at this line, sample "
                  "{}; {}",
                  format_memory(static_cast<double>(ceiling_.bytes)), ceiling, samples_, remedy));
}

void Reader::refuse_memory_bag(const detail::BagStream& bag) const {
  const double messages = static_cast<double>(bag.topic().messages);
  const std::string remedy = trf("give {} SIZE if the machine has the memory, or cut the record", kMaxMemoryOption);
  fail(line_, trf("the record needs more than {} of memory for its samples ({}): reached at message {} of {}; {}",
                  format_memory(static_cast<double>(ceiling_.bytes)), ceiling_.origin, samples_,
                  messages > 0 ? fmt::format("{:.0f}", messages) : std::string("?"), remedy));
}

// Take the complete lines of buf; returns the bytes taken.
std::size_t Reader::take_lines(std::string& buf, bool at_end) {
  std::size_t p = 0;
  if (!started_) {
    if (buf.size() < 3 && !at_end) return 0;
    started_ = true;
    if (buf.starts_with("\xEF\xBB\xBF")) p = 3;  // a UTF-8 byte-order mark
  }
  if (!eol_ && !decide_line_end(std::string_view(buf).substr(p), at_end)) return p;
  const std::size_t end = eol_ == '\r' ? mac_limit(buf, p, at_end) : buf.size();
  while (p < end) {
    if (eol_ == '\n' && in_run() && !integer_mode()) {  // every column's common lines, in bulk
      p = static_cast<std::size_t>(decimal_lines(buf.data() + p, buf.data() + end) - buf.data());
      if (p == end) break;
    }
    if (eol_ == '\n' && in_run() && integer_mode() && followers_.empty()) {  // one integer column's lines, in bulk
      // Room first, within the memory ceiling: a line takes at least 2 bytes; the bulk read stops
      // where the room does, and the next pass asks for more (CeilingReached when none is left).
      memory_.make_room(ints_, (end - p) / 2 + 1);
      const std::size_t before = ints_.size();
      p = static_cast<std::size_t>(
          parser_.plain_integer_lines(buf.data() + p, buf.data() + end, line_, ints_, ints_.capacity() - before) -
          buf.data());
      samples_ += ints_.size() - before;
      if (p == end) break;
    }
    const auto* e = static_cast<const char*>(std::memchr(buf.data() + p, eol_, end - p));
    if (!e) break;
    const auto n = static_cast<std::size_t>(e - buf.data()) - p;
    line(std::string_view(buf).substr(p, n));
    p += n + 1;
  }
  return p;
}

// Text whose first line end is a CR not followed by LF is read with CR line ends; false while
// the bytes seen do not tell.
bool Reader::decide_line_end(std::string_view s, bool at_end) {
  const auto i = s.find_first_of("\r\n");
  if (i == std::string_view::npos || s[i] == '\n' || (i + 1 < s.size() && s[i + 1] == '\n')) {
    if (i != std::string_view::npos || at_end) eol_ = '\n';
    return eol_ != 0;
  }
  if (i + 1 == s.size() && !at_end) return false;
  eol_ = '\r';
  first_cr_column_ = i + 1;
  return true;
}

// CR-ended text may end with one LF, which ends the last line; an LF anywhere else makes it
// LF-ended text after all, whose first line holds a stray CR.
std::size_t Reader::mac_limit(std::string& buf, std::size_t from, bool at_end) const {
  const auto lf = buf.find('\n', from);
  if (lf == std::string::npos) return buf.size();
  if (lf + 1 == buf.size()) return at_end ? (buf[lf] = '\r', buf.size()) : lf;  // else told by what follows
  fail(1, trf("stray carriage return (CR) at column {} inside the line", first_cr_column_));
}

// The first sample: the phase's starting point, and the time columns' units. Rate and angle
// samples whose rate neither the options, the metadata before them nor a time column give are
// refused here, before the samples are read, rather than after a long record has been.
void Reader::start_samples(const Sample& s) {
  if (!integer_mode() && !opt_.rate_hz && !parser_.metadata().rate_hz && !layout_.time_col) check_unread_keys();
  if (in().mode == InputMode::Pulses) memory_.keep(ints_, std::int64_t{0});                          // C_0
  if (in().mode == InputMode::Rate || in().mode == InputMode::Increment) memory_.keep(reals_, 0.0);  // x_0
  if (layout_.time_col) tunit_ = time_unit_of(layout_.time_unit, s.time, detail::Role::Time);
  if (layout_.time2_col) tunit2_ = time_unit_of(layout_.time2_unit, s.time2, detail::Role::Time2);
}

const detail::TimeName* Reader::time_unit_of(const detail::TimeName* named, double first, detail::Role role) const {
  if (named->per_second > 0) return named;
  if (const detail::TimeName* u = detail::time_unit_of_stamp(first)) return u;
  fail(line_, trf("cannot tell the unit of the {} from its stamps: the first, {}, is neither near 0 (seconds) "
                  "nor like Unix time (~1.7e9 s, 1.7e12 ms, 1.7e15 us, 1.7e18 ns); name the column time_s, "
                  "time_ms, time_us or time_ns",
                  layout_.describe(role), first));
}

void Reader::push(const Sample& s) {
  if (samples_ == 0) start_samples(s);
  if (new_run_) {
    memory_.keep(runs_, {samples_, line_});
    new_run_ = false;
  }
  integer_mode() ? memory_.keep(ints_, s.integer) : memory_.keep(reals_, s.real);
  track(s, samples_);
  ++samples_;
}

// What a sample adds besides its value: the time columns' checks, the temperature's mean.
void Reader::track(const Sample& s, std::size_t sample) {
  if (layout_.time_col) times_.add(s.time);
  if (layout_.time2_col) {
    const double d = std::abs(s.time / tunit_->per_second - s.time2 / tunit2_->per_second);
    if (!(d <= gap_max_)) gap_max_ = d, gap_sample_ = sample, gap_t_ = s.time, gap_t2_ = s.time2;
  }
  if (layout_.temp_col) temp_sum_ += s.temperature, ++temp_n_;
}

// Every reader of the pass is past its first sample and inside a run of data lines: the lines
// that follow may be read in bulk.
bool Reader::in_run() const {
  const auto ready = [](const Reader* r) { return r->samples_ > 0 && !r->new_run_; };
  return ready(this) && std::all_of(followers_.begin(), followers_.end(), ready);
}

// The common lines of a text for every column of the pass at once: the lead's parser reads them
// into rows of the wanted columns' values (split in two halves on two cores), then each reader
// takes its own as push() would. Room comes first, within each reader's ceiling: the bulk read
// stops where the room does, and the next asks for more (CeilingReached when none is left).
const char* Reader::decimal_lines(const char* p, const char* end) {
  if (slot_of_col_.empty()) {
    slot_of_col_.assign(layout_.ncols, -1);
    for (std::size_t c = 0; c < layout_.ncols; ++c) {
      bool wanted = layout_.roles[c] != detail::Role::Skip;
      for (const Reader* f : followers_) wanted = wanted || f->layout_.roles[c] != detail::Role::Skip;
      if (wanted) slot_of_col_[c] = static_cast<int>(slots_++);
    }
  }
  std::size_t max_lines = std::numeric_limits<std::size_t>::max();
  const auto room = [&](Reader& r) {
    r.memory_.make_room(r.reals_, static_cast<std::size_t>(end - p) / 2 + 1);
    max_lines = std::min(max_lines, r.reals_.capacity() - r.reals_.size());
  };
  room(*this);
  for (Reader* f : followers_) reached_ = f, room(*f);
  reached_ = nullptr;
  rows_.clear();
  std::size_t line = line_;
  p = parser_.plain_decimal_lines(p, end, line, slot_of_col_, slots_, rows_, max_lines);
  const std::size_t n = line - line_;
  take_rows(rows_, slots_, slot_of_col_, n);
  for (Reader* f : followers_) reached_ = f, f->take_rows(rows_, slots_, slot_of_col_, n);
  reached_ = nullptr;
  return p;
}

// `n` lines read in bulk (rows of `slots` values), each taken as push() takes its sample.
void Reader::take_rows(const std::vector<double>& rows, std::size_t slots, const std::vector<int>& slot_of_col,
                       std::size_t n) {
  const auto value = static_cast<std::size_t>(slot_of_col[layout_.value_col]);
  for (std::size_t i = 0; i < n; ++i) reals_.push_back(rows[i * slots + value]);  // within the room made
  if (layout_.time_col || layout_.time2_col || layout_.temp_col)
    for (std::size_t i = 0; i < n; ++i) track(parser_.row_sample(&rows[i * slots], slot_of_col), samples_ + i);
  samples_ += n;
  line_ += n;
  parser_.count_lines(n);
}

void Reader::finish_rate() {
  const detail::Metadata& meta = parser_.metadata();
  if (layout_.time_col && !times_.median_known) times_.find_median();
  if (opt_.rate_hz) {
    rate_hz_ = *opt_.rate_hz;
    rate_source_ = RateSource::Option;
  } else if (meta.rate_hz) {
    rate_hz_ = *meta.rate_hz;
    rate_source_ = RateSource::Metadata;
  } else if (layout_.time_col) {
    rate_from_time_column();
  }
}

// The period is the median of the first steps, refined by the whole span when that agrees and no
// step is a gap, so long records give the rate to many digits.
void Reader::rate_from_time_column() {
  const std::vector<double>& h = times_.head;
  const double candidate = times_.median;
  for (std::size_t i = 1; !(candidate > 0) && i < h.size(); ++i)
    if (!(h[i] > h[i - 1]))
      fail(line_of_sample(i), trf("the time column does not increase: {} at line {}, then {}", stamp(h[i - 1]),
                                  line_of_sample(i - 1), stamp(h[i])));
  const double span = (times_.last - times_.first) / static_cast<double>(times_.n - 1);
  const bool gapless = times_.min_dt > 0.5 * candidate && times_.max_dt < 1.5 * candidate;
  const double period = gapless && std::abs(span - candidate) <= opt_.time_tolerance * candidate ? span : candidate;
  double rate = tunit_->per_second / period;
  // A rate within 1 ppm of a whole number of Hz is that number (time stamps are printed rounded).
  if (rate >= 1 && std::abs(rate - std::round(rate)) <= 1e-6 * rate) rate = std::round(rate);
  rate_hz_ = rate;
  rate_source_ = RateSource::TimeColumn;
  if (!(rate >= kMinRateHz && rate <= kMaxRateHz))
    fail(parser_.first_data_line(),
         trf("the time column's step of {:g} {} gives a sample rate of {:g} Hz, outside the usable range "
             "{:g}..{:g} Hz",
             period, tunit_->unit, rate, kMinRateHz, kMaxRateHz));
}

// A key that looks like a sample rate (or a pulse weight) but is not the one rwcalc reads, when
// nothing else gives the rate (or the weight): using 400 Hz (0.92″) then would be a silent choice.
void Reader::check_unread_keys() const {
  const detail::Metadata& meta = parser_.metadata();
  if (rate_source_ == RateSource::Default && meta.unread_rate_key)
    fail(meta.unread_rate_key->second,
         trf("metadata '{}' looks like the sample rate, but rwcalc reads the rate from rate_hz, a time "
             "column or --rate{}; write '# rate_hz: VALUE' or give --rate",
             meta.unread_rate_key->first,
             integer_mode() ? trf(", and would otherwise use {:g} Hz", units::gl2d_rate_hz) : ""));
  // Rate and angle samples carry no GL-2D default: 400 Hz would put every τ off by the ratio.
  if (rate_source_ == RateSource::Default && !integer_mode())
    fail(0, trf("no sample rate: {} input takes it from --rate HZ, a '# rate_hz: HZ' metadata line before the "
                "data or a time column (time_s, time_ms, time_us, time_ns, timestamp, %time, ...); the {:g}-Hz "
                "GL-2D default applies to pulse and counter input only",
                to_string(in().mode), units::gl2d_rate_hz));
  if (integer_mode() && !opt_.scale_arcsec && !meta.scale_arcsec && meta.unread_scale_key)
    fail(meta.unread_scale_key->second,
         trf("metadata '{}' looks like the pulse weight, but rwcalc reads it from scale_arcsec_per_pulse "
             "or --scale, and would otherwise use {:g} arcsec; write '# scale_arcsec_per_pulse: VALUE' or "
             "give --scale",
             meta.unread_scale_key->first, units::gl2d_arcsec_per_pulse));
}

// Two time columns are used only when they agree, every line, within the time tolerance.
void Reader::check_time_columns_agree() const {
  const double period = 1.0 / rate_hz_;
  if (!layout_.time2_col || gap_max_ <= opt_.time_tolerance * period) return;
  fail(line_of_sample(gap_sample_),
       trf("the time columns '{}' and '{}' disagree: {} {} and {} {} differ by {:g} s here (their largest "
           "difference), more than the time tolerance ({} of the {:g}-s period); remove one of them{}",
           layout_.header[*layout_.time_col], layout_.header[*layout_.time2_col], gap_t_, tunit_->unit, gap_t2_,
           tunit2_->unit, gap_max_, opt_.time_tolerance, period, tolerance_hint(gap_max_ / period)));
}

// Every step must lie within half a period of the period: within the time tolerance it is exact,
// beyond it jitter (accepted, and reported). A step of 1.5 periods or more is a gap, one of half a
// period or less (repeated and backward stamps among them) an error: nothing is resampled.
void Reader::check_time_column() const {
  if (!layout_.time_col || times_.n < 2) return;
  const double period = tunit_->per_second / rate_hz_;
  const double tol = opt_.time_tolerance * period;
  if (times_.min_dt >= period - tol && times_.max_dt <= period + tol) return;
  check_rate_against_time_column(times_.first_outside(period - tol, period + tol), period);
  const double lo = std::nextafter(0.5 * period, period), hi = std::nextafter(1.5 * period, period);
  if (times_.min_dt >= lo && times_.max_dt <= hi) return;
  if (opt_.gaps_as_segments) {  // gaps split the record; a step too short is still an error
    if (times_.min_dt < lo) fail_step(times_.first_outside(lo, std::numeric_limits<double>::infinity()), period);
    return;
  }
  fail_step(times_.first_outside(lo, hi), period);
}

// `--gaps segments`: the segments between the time column's gaps (steps of 1.5 periods or more).
void Reader::split_at_gaps(Recording& rec) const {
  if (!opt_.gaps_as_segments || !layout_.time_col || times_.n < 2) return;
  const double period = tunit_->per_second / rate_hz_;
  std::vector<Recording::Segment> segs{{0, 0, 0, parser_.first_data_line()}};
  for (const TimeTrack::Step& s : times_.long_steps) {
    if (!(s.after - s.before >= 1.5 * period)) continue;
    segs.back().samples = s.sample - segs.back().first;
    segs.push_back({s.sample, 0, (s.after - s.before - period) / tunit_->per_second, line_of_sample(s.sample)});
  }
  if (segs.size() == 1) return;
  segs.back().samples = samples_ - segs.back().first;
  rec.segments = std::move(segs);
}

// --rate or rate_hz against the mean step of the time column.
void Reader::check_rate_against_time_column(const TimeTrack::Step& bad, double period) const {
  if (rate_source_ != RateSource::Option && rate_source_ != RateSource::Metadata) return;
  // The mean step over the steps that are not gaps (1.5 median steps or more): a gap is said as such.
  double gaps = 0;
  std::size_t gap_steps = 0;
  for (const TimeTrack::Step& s : times_.long_steps)
    if (s.after - s.before >= 1.5 * times_.median) gaps += s.after - s.before, ++gap_steps;
  const double est = (times_.last - times_.first - gaps) / static_cast<double>(times_.n - 1 - gap_steps);
  if (std::abs(est - period) <= opt_.time_tolerance * period) return;
  const std::string tcol = layout_.header.empty() ? "column 1" : "'" + layout_.header[*layout_.time_col] + "'";
  fail(line_of_sample(bad.sample),
       trf("the sample rate {} Hz (from {}) is inconsistent with the time column {}, which steps by {} {} "
           "(~{:.6g} Hz), e.g. {} at line {} then {}{}",
           rate_hz_,
           rate_source_ == RateSource::Option ? "--rate"
                                              : fmt::format("metadata at line {}", parser_.metadata().rate_line),
           tcol, est, tunit_->unit, tunit_->per_second / est, stamp(bad.before), line_of_sample(bad.sample - 1),
           stamp(bad.after), tolerance_hint(std::abs(est - period) / period)));
}

[[noreturn]] void Reader::fail_step(const TimeTrack::Step& bad, double period) const {
  const double t0 = bad.before, t1 = bad.after, dt = t1 - t0;
  const std::size_t line = line_of_sample(bad.sample), prev = line_of_sample(bad.sample - 1);
  if (dt == 0) fail(line, trf("repeated time stamp {} (also at line {}); no resampling is done", stamp(t1), prev));
  if (dt < 0) fail(line, trf("time goes backwards: {} at line {}, then {}", stamp(t0), prev, stamp(t1)));
  const double p_s = period / tunit_->per_second;
  if (dt < period)
    fail(line, trf("time step too short: {} at line {}, then {} (a step of {:.6g} periods of {:g} s; steps "
                   "within half a period of it are accepted as jitter); no resampling is done",
                   stamp(t0), prev, stamp(t1), dt / period, p_s));
  const double missing = std::round(dt / period - 1);
  fail(line, trf("gap in the time column: {} at line {}, then {}: {:.6g} s missing (~{:g} sample{}; a step "
                 "of {:.6g} periods of {:g} s); rwcalc does not resample: give --gaps segments to analyse the "
                 "stretches between gaps as segments (no difference spans a gap), or cut the record at this line "
                 "(--time-tolerance only sets which steps within half a period count as jitter)",
                 stamp(t0), prev, stamp(t1), (dt - period) / tunit_->per_second, missing, missing == 1 ? "" : "s",
                 dt / period, p_s));
}

/// Floating data whose rates between samples are all below kMinDataRate (limits.hpp) but not all
/// zero: the noise fit would square their variances to nothing and call the record noiseless.
void Reader::check_data_magnitude(const PhaseSeries& ph, const char* what) const {
  double largest = 0;
  for (std::size_t i = 1; i < ph.values.size(); ++i)
    largest = std::max(largest, std::abs(ph.values[i] - ph.values[i - 1]));
  largest /= ph.tau0_s;
  if (largest > 0 && largest < kMinDataRate)
    fail(0, trf("the {} data are too small to analyse: the largest rate between samples is {:g} {}, below "
                "{:g} {}, where the squares of the variances in the noise fit underflow; give the data in a larger "
                "unit",
                what, largest, ph.deviation_unit(), kMinDataRate, ph.deviation_unit()));
}

/// Angle samples (already in phase units) whose step, as a rate, passes ±kMaxDataRate.
void Reader::check_angle_steps(const PhaseSeries& ph, const std::vector<double>& x, double f) const {
  for (std::size_t i = 1; i < x.size(); ++i) {
    const double rate = (x[i] - x[i - 1]) / ph.tau0_s;
    if (!(std::abs(rate) <= kMaxDataRate)) [[unlikely]]
      fail(line_of_sample(i),
           trf("angle step out of range: from {} to {} {} in one sample is a rate of {:g} {}, beyond ±{:g} {}, "
               "where the variances the noise fit squares would overflow",
               detail::quoted(fmt::format("{:g}", x[i - 1] / f)), detail::quoted(fmt::format("{:g}", x[i] / f)),
               to_string(in().angle_unit), rate, ph.deviation_unit(), kMaxDataRate, ph.deviation_unit()));
  }
}

/// Rate samples x[1..] (x[0] is x_0), or increments, whose rate passes ±kMaxDataRate: `f` turns a
/// sample into its rate in phase units per second.
void Reader::check_rates(const PhaseSeries& ph, const std::vector<double>& x, double f) const {
  const bool increments = in().mode == InputMode::Increment;
  for (std::size_t i = 1; i < x.size(); ++i) {
    const double rate = x[i] * f;
    if (std::abs(rate) <= kMaxDataRate) [[likely]]
      continue;
    const std::string as_rate = f == 1 ? "" : fmt::format(" ({:g} {})", rate, ph.deviation_unit());
    fail(line_of_sample(i - 1),
         trf_either(increments,
                    N_("increment out of range: {} {}{} is beyond ±{:g} {}, where the variances the noise fit "
                       "squares would overflow"),
                    N_("rate out of range: {} {}{} is beyond ±{:g} {}, where the variances the noise fit squares "
                       "would overflow"),
                    detail::quoted(fmt::format("{:g}", x[i])),
                    increments ? to_string(in().angle_unit) : to_string(in().rate_unit), as_rate, kMaxDataRate,
                    ph.deviation_unit()));
  }
}

// C_0 = 0, C_k = Σ c_i modulo 2^64 for pulses (PhaseSeries differences are modular, so an offset
// never matters); every second difference stays exact while Σ|c_i| < 2^63, beyond it is refused.
// A counter is unwrapped: each step is (R_k − R_{k−1}) mod 2^B, so a backwards step is a wrap.
void Reader::build_counts(PhaseSeries& ph, std::size_t& wraps) {
  constexpr auto kLimit = static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
  std::vector<std::int64_t>& c = ints_;
  std::uint64_t acc = 0, total = 0;
  if (in().mode == InputMode::Pulses) {
    for (std::size_t i = 1; i < c.size(); ++i) {
      const auto v = static_cast<std::uint64_t>(c[i]);
      acc += v;
      total += c[i] < 0 ? (~v + 1) : v;
      c[i] = static_cast<std::int64_t>(acc);
      if (total > kLimit) [[unlikely]]
        fail(line_of_sample(i - 1),
             "pulse counts too large to be summed exactly: the sum of |counts| exceeds 2^63-1 here");
    }
  } else {
    const int b = opt_.counter_bits;
    const std::uint64_t mask = b >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << b) - 1;
    std::uint64_t prev = static_cast<std::uint64_t>(c[0]) & mask;
    c[0] = 0;
    for (std::size_t i = 1; i < c.size(); ++i) {
      const std::uint64_t r = static_cast<std::uint64_t>(c[i]) & mask;
      const std::uint64_t step = (r - prev) & mask;
      wraps += r < prev;
      prev = r;
      c[i] = static_cast<std::int64_t>(acc += step);
      if (step > kLimit - total) [[unlikely]]
        fail(line_of_sample(i), trf("the unwrapped counter advances by more than 2^63-1 counts here (a "
                                    "backwards step counts as a wrap of the {}-bit counter)",
                                    b));
      total += step;
    }
  }
  ph.counts = std::move(c);
}

// Phase units per unit of angle input: arcsec, clock seconds, or velocity in 1/3600 m/s (units.hpp).
double phase_factor(AngleUnit u) {
  switch (u) {
    case AngleUnit::Deg: return units::arcsec_per_deg;
    case AngleUnit::Rad: return units::arcsec_per_rad;
    case AngleUnit::MetrePerSecond: return units::velocity_units_per_mps;
    case AngleUnit::Arcsec:
    case AngleUnit::Second: break;
  }
  return 1.0;
}

// Phase units per second per unit of rate input: ″/s = °/h for gyros, (1/3600 m/s)/s = m/s/h for
// accelerometers.
double phase_factor(RateUnit u) {
  constexpr double g = units::standard_gravity * units::velocity_units_per_mps;
  switch (u) {
    case RateUnit::DegPerSecond: return units::arcsec_per_deg;
    case RateUnit::RadPerSecond: return units::arcsec_per_rad;
    case RateUnit::MetrePerSecond2: return units::velocity_units_per_mps;
    case RateUnit::G: return g;
    case RateUnit::MilliG: return g * 1e-3;
    case RateUnit::MicroG: return g * 1e-6;
    case RateUnit::DegPerHour:
    case RateUnit::Unitless: break;
  }
  return 1.0;
}

// Angle samples in arcsec (or s); rate samples integrated to phase as in SP 1065. Every rate, given
// or between two angle samples, lies within ±kMaxDataRate (limits.hpp).
void Reader::build_values(PhaseSeries& ph) {
  // Floating phase beyond this (arcsec, or s for clocks) would overflow the squares of second
  // differences (|Δ²x| ≤ 4·max|x|) in the Allan variance; no instrument comes near it.
  constexpr double kMaxPhase = 1e150;
  std::vector<double>& x = reals_;
  const bool angle = in().mode == InputMode::Angle;
  const bool increments = in().mode == InputMode::Increment;  // summed like rates, without the τ0
  const double f = angle || increments ? phase_factor(in().angle_unit) : phase_factor(in().rate_unit);
  for (std::size_t i = 0; angle && i < x.size(); ++i)
    if (!(std::abs(x[i] *= f) <= kMaxPhase)) [[unlikely]]
      fail(line_of_sample(i), trf("angle out of range: {} is beyond ±{:g} arcsec, where the Allan "
                                  "variance of the record would overflow",
                                  detail::quoted(fmt::format("{:g}", x[i] / f)), kMaxPhase));
  if (angle) {
    check_angle_steps(ph, x, f);
  } else {
    check_rates(ph, x, increments ? f / ph.tau0_s : f);
    // x_0 = 0, x_j = τ0·Σ_{i<j} (y_i − ȳ), accumulated in long double. The mean rate ȳ goes into
    // rate_offset (series.hpp): a phase that kept it would grow to ȳ·T and round its noise away
    // once the offset is many orders above the noise.
    const long double k = increments ? static_cast<long double>(f) : static_cast<long double>(ph.tau0_s) * f;
    long double sum = 0, acc = 0;
    for (std::size_t i = 1; i < x.size(); ++i) sum += x[i];
    const double mean = x.size() > 1 ? static_cast<double>(sum / static_cast<long double>(x.size() - 1)) : 0.0;
    for (std::size_t i = 1; i < x.size(); ++i) {
      acc += (static_cast<long double>(x[i]) - mean) * k;
      x[i] = static_cast<double>(acc);
    }
    ph.rate_offset = increments ? mean * f / ph.tau0_s : mean * f;
  }
  ph.values = std::move(x);
  check_data_magnitude(ph, angle ? "angle" : "rate");
}

Recording Reader::finish() {
  if (samples_ == 0) {
    if (layout_.header_line) fail(layout_.header_line, "no samples: the file has a header row but no data lines");
    fail(0, parser_.content_lines() == 0 ? "empty file: no samples"
                                         : "no samples: the file holds only comments and blank lines");
  }
  if (samples_ < 2) fail(parser_.first_data_line(), "only one sample; at least 2 are needed");
  finish_rate();
  check_unread_keys();
  check_time_columns_agree();
  check_time_column();

  Recording rec;
  rec.samples = samples_;
  PhaseSeries& ph = rec.phase;
  ph.tau0_s = 1.0 / rate_hz_;
  const bool clock =
      ((in().mode == InputMode::Angle || in().mode == InputMode::Increment) && in().angle_unit == AngleUnit::Second) ||
      (in().mode == InputMode::Rate && in().rate_unit == RateUnit::Unitless);
  const bool accel = ((in().mode == InputMode::Angle || in().mode == InputMode::Increment) &&
                      is_accelerometer_unit(in().angle_unit)) ||
                     (in().mode == InputMode::Rate && is_accelerometer_unit(in().rate_unit));
  ph.kind = clock ? PhaseKind::Clock : accel ? PhaseKind::Accelerometer : PhaseKind::Gyro;
  if (integer_mode())
    build_counts(ph, rec.counter_wraps);
  else
    build_values(ph);
  detail::Metadata& meta = parser_.metadata();
  rec.phase.arcsec_per_count = opt_.scale_arcsec   ? *opt_.scale_arcsec
                               : meta.scale_arcsec ? *meta.scale_arcsec
                                                   : units::gl2d_arcsec_per_pulse;
  rec.rate_hz = rate_hz_;
  rec.rate_source = rate_source_;
  rec.metadata = std::move(meta.all);
  rec.temperature_c = temp_n_ > 0 ? std::optional(static_cast<double>(temp_sum_ / static_cast<long double>(temp_n_)))
                                  : meta.temperature_c;
  const auto& h = layout_.header;
  rec.column_name = h.empty() ? fmt::format("column {}", layout_.value_col + 1) : h[layout_.value_col];
  rec.column_index = layout_.value_col + 1;
  if (layout_.time_col) rec.time_column = h.empty() ? std::string("column 1") : h[*layout_.time_col];
  rec.mode = in().mode;
  rec.angle_unit = in().angle_unit;
  rec.rate_unit = in().rate_unit;
  rec.notes = in().notes;
  rec.notes.insert(rec.notes.end(), layout_.notes.begin(), layout_.notes.end());
  rec.warnings = in().warnings;
  for (const auto& [key, value] : opt_.identification) {
    auto& slot = rec.metadata[key];
    if (!slot.empty() && slot != value)
      rec.notes.push_back(trf("{} '{}' from the command line, not the file's '{}'", key, value, slot));
    slot = value;
  }
  note_time_column(rec);
  split_at_gaps(rec);
  rec.line_runs = std::move(runs_);
  return rec;
}

// The time column's unit (a note when its magnitude decided it) and the jitter. The rate's source
// is in every output already ("(time column)", "(default)").
void Reader::note_time_column(Recording& rec) const {
  if (!layout_.time_col) return;
  const bool by_name = layout_.time_unit->per_second > 0;
  rec.time_unit = tunit_->unit;
  rec.time_unit_source = by_name ? "name" : "magnitude";
  const double t0 = times_.first;
  if (!by_name)
    rec.notes.push_back(trf("time column '{}' in {} (by magnitude: {})", *rec.time_column, tunit_->unit,
                            std::abs(t0) >= 1e8 ? trf("the first stamp {:.4g} is Unix time in {}", t0, tunit_->unit)
                                                : tr("the stamps start near 0")));
  if (times_.n >= 2 && times_.median > 0) rec.jitter = times_.jitter();
  if (rec.jitter.steps > 0)
    rec.notes.push_back(
        trf("jitter: {} time step{} off the period by more than the time tolerance ({:g} %), "
            "by up to {:.3g} % of the period (rms {:.2g} %)",
            rec.jitter.steps, rec.jitter.steps == 1 ? "" : "s", 100 * opt_.time_tolerance,
            100 * rec.jitter.max_fraction, 100 * rec.jitter.rms_fraction));
}

// One pass over a text for some columns: the first reader leads, the others follow it line by line.
// A bag is read in one pass over its messages for all columns, its digest taken beside it.
struct Pass {
  std::unique_ptr<detail::TextSource> src;
  std::unique_ptr<detail::BagStream> bag;
  std::string bag_sha256;
  std::vector<std::unique_ptr<Reader>> readers;

  Pass(std::unique_ptr<detail::TextSource> text, std::span<const ReadOptions> columns) : src(std::move(text)) {
    add(src->name(), columns);
  }
  Pass(std::unique_ptr<detail::BagStream> b, std::span<const ReadOptions> columns) : bag(std::move(b)) {
    add(bag->name(), columns);
  }
  void add(const std::string& name, std::span<const ReadOptions> columns) {
    for (const ReadOptions& o : columns) {
      require_valid(o);
      readers.push_back(std::make_unique<Reader>(name, o));
      if (readers.size() > 1) readers.front()->lead(*readers.back());
    }
  }
  void read() {
    if (!bag) return readers.front()->read(*src);
    parallel_for(2,
                 [&](std::size_t i) { i == 0 ? readers.front()->read_bag(*bag) : void(bag_sha256 = bag->sha256()); });
  }
  Recording finish(std::size_t i, const std::string& source) {
    Recording rec = readers[i]->finish();
    rec.source = source;
    rec.file_bytes = bag ? bag->size() : src->raw_bytes();
    rec.sha256 = bag ? bag_sha256 : src->sha256();
    if (bag)
      rec.notes.insert(rec.notes.begin(),
                       trf("{} topic '{}' ({})", bag->format(), bag->topic().name, bag->topic().type));
    return rec;
  }
};

// Every column's read in one pass (which reads each stretch of common lines in two halves on two
// cores), then each column finished, in parallel; an error is the first column's.
std::vector<Recording> read_pass(Pass& pass, const std::string& source) {
  pass.read();
  const std::size_t n = pass.readers.size();
  std::vector<Recording> recs(n);
  std::vector<std::exception_ptr> failed(n);
  parallel_for(n, [&](std::size_t k) {
    try {
      recs[k] = pass.finish(k, source);
    } catch (...) {
      failed[k] = std::current_exception();
    }
  });
  for (const std::exception_ptr& e : failed)
    if (e) std::rethrow_exception(e);
  return recs;
}

}  // namespace

Recording read_recording(const std::string& path, const ReadOptions& options) {
  if (auto bag = detail::BagStream::open(path)) {
    bag->select(options.topic);
    Pass pass(std::move(bag), std::span(&options, 1));
    return std::move(read_pass(pass, path).front());
  }
  Pass pass(std::make_unique<detail::TextSource>(path), std::span(&options, 1));
  return std::move(read_pass(pass, path).front());
}

std::vector<Recording> read_recordings(const std::string& path, std::span<const ReadOptions> columns) {
  if (columns.empty()) throw UsageError("no column to read");
  if (auto bag = detail::BagStream::open(path)) {
    bag->select(columns.front().topic);
    Pass pass(std::move(bag), columns);
    return read_pass(pass, path);
  }
  Pass pass(std::make_unique<detail::TextSource>(path), columns);
  return read_pass(pass, path);
}

Recording read_recording_text(std::string_view text, const std::string& name, const ReadOptions& options) {
  Pass pass(std::make_unique<detail::TextSource>(text, detail::display_name(name)), std::span(&options, 1));
  return std::move(read_pass(pass, name).front());
}

namespace {

// The header row of a text file, read up to its first data line.
std::vector<std::string> header_row(const std::string& path, const ReadOptions& options) {
  detail::TextSource src(path);
  detail::LineParser parser(src.name(), options);
  parser.stop_at_first_data();
  std::string buf;
  std::size_t line = 0;
  Sample s;
  for (bool more = true; more;) {
    more = src.read(buf);
    std::size_t p = 0;
    for (std::size_t e; (e = buf.find('\n', p)) != std::string::npos; p = e + 1)
      if (parser.parse(std::string_view(buf).substr(p, e - p), ++line, s) == detail::LineKind::Data)
        return parser.layout().header;
    buf.erase(0, p);
  }
  return parser.layout().header;
}

}  // namespace

ImuColumnNames imu_column_names(const std::string& path, const ReadOptions& options) {
  std::vector<std::string> names;
  if (detail::BagStream::open(path)) {
    for (const std::string_view f : detail::kImuFieldColumns) names.emplace_back(f);
  } else if (path != "-") {
    names = header_row(path, options);
  }
  ImuColumnNames out;
  for (const std::string& n : names) {
    const detail::InputChoice c = detail::choose_input(ReadOptions{}, n, path, 0);
    const bool rate = c.mode == InputMode::Rate, angle = c.mode == InputMode::Angle;
    if ((rate && is_accelerometer_unit(c.rate_unit)) || (angle && is_accelerometer_unit(c.angle_unit)))
      out.accel.push_back(n);
    else if ((rate && c.rate_unit != RateUnit::Unitless) || angle)
      out.gyro.push_back(n);
  }
  return out;
}

std::vector<double> Recording::rates() const {
  const std::size_t n = phase.points() > 0 ? phase.points() - 1 : 0;
  std::vector<double> r(n);
  for (std::size_t i = 0; i < n; ++i) r[i] = phase.rate(i);
  return r;
}

std::size_t Recording::line_of_sample(std::size_t k) const noexcept {
  return k < samples ? line_in_runs(line_runs, k) : 0;
}

std::size_t Recording::line_of_rate(std::size_t i) const noexcept {
  const bool readings = mode == InputMode::Counter || mode == InputMode::Angle;
  return line_of_sample(readings ? i + 1 : i);
}

std::string_view input_unit(const Recording& rec) {
  switch (rec.mode) {
    case InputMode::Pulses: return "pulse";
    case InputMode::Counter: return "count";
    case InputMode::Angle:
    case InputMode::Increment: return to_string(rec.angle_unit);
    case InputMode::Rate: return to_string(rec.rate_unit);
  }
  return "?";
}

std::string describe_input(const Recording& rec) {
  if (rec.mode == InputMode::Pulses || rec.mode == InputMode::Counter)
    return trf_either(rec.mode == InputMode::Pulses, N_("column '{}': pulse counts, {:g} arcsec per pulse"),
                      N_("column '{}': counter readings, {:g} arcsec per count"), rec.column_name,
                      rec.phase.arcsec_per_count);
  return trf("column '{}': {} samples in {}", rec.column_name, to_string(rec.mode), input_unit(rec));
}

InputMode parse_input_mode(std::string_view s) { return parse_name(kModes, s, "--input"); }
AngleUnit parse_angle_unit(std::string_view s) { return parse_name(kAngleUnits, s, "--angle-unit"); }
RateUnit parse_rate_unit(std::string_view s) {
  if (s == "m/s2" || s == "mps2") return RateUnit::MetrePerSecond2;
  if (s == "µg") return RateUnit::MicroG;
  return parse_name(kRateUnits, s, "--rate-unit");
}
bool is_accelerometer_unit(RateUnit u) noexcept {
  return u == RateUnit::MetrePerSecond2 || u == RateUnit::G || u == RateUnit::MilliG || u == RateUnit::MicroG;
}
bool is_accelerometer_unit(AngleUnit u) noexcept { return u == AngleUnit::MetrePerSecond; }
std::string_view to_string(InputMode m) { return name_of(kModes, m); }
std::string_view to_string(RateSource s) { return name_of(kRateSources, s); }
std::string_view to_string(AngleUnit u) { return name_of(kAngleUnits, u); }
std::string_view to_string(RateUnit u) { return name_of(kRateUnits, u); }

}  // namespace rwcalc
