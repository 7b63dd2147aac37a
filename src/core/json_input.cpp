// Typed, located reading of JSON input (json_input.hpp).
#include "rwcalc/json_input.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>
#include <utility>

#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"

namespace rwcalc::json_input {

namespace {

using nlohmann::json;

std::string where(const std::string& path) {
  return path.empty() ? std::string("the document") : fmt::format("\"{}\"", path);
}

/// nlohmann's message without its exception tag, and with the column only: the line it counts
/// is that of the parsed text, not of the file (a JSON line is parsed on its own).
std::string plain_message(std::string m) {
  if (m.rfind("[json.exception.", 0) == 0) m.erase(0, m.find("] ") + 2);
  const auto at = m.find("parse error at line ");
  const auto column = m.find(", column ", at);
  if (at != std::string::npos && column != std::string::npos) m.replace(at, column + 2 - at, "parse error at ");
  return m;
}

std::string shown(const json& j) {
  std::string s = j.dump(-1, ' ', false, json::error_handler_t::replace);
  return s.size() > 40 ? s.substr(0, 37) + "..." : s;
}

/// An iterator over the text that records how far the parser has read: nlohmann's SAX events
/// carry no position, but each arrives just after its token was read.
class TrackedIterator {
 public:
  using iterator_category = std::input_iterator_tag;
  using value_type = char;
  using difference_type = std::ptrdiff_t;
  using pointer = const char*;
  using reference = const char&;

  TrackedIterator(const char* p, const char** read_to) : p_(p), read_to_(read_to) {}
  reference operator*() const { return *p_; }
  TrackedIterator& operator++() {
    *read_to_ = ++p_;
    return *this;
  }
  TrackedIterator operator++(int) {
    auto old = *this;
    ++*this;
    return old;
  }
  bool operator==(const TrackedIterator& o) const { return p_ == o.p_; }
  bool operator!=(const TrackedIterator& o) const { return p_ != o.p_; }

 private:
  const char* p_;
  const char** read_to_;
};

/// Builds the DOM (nlohmann's own SAX DOM builder) and notes the line of every value by key path.
class LocatingHandler {
 public:
  LocatingHandler(json& root, std::string_view text, const char* const& read_to, std::string file,
                  std::size_t first_line, std::unordered_map<std::string, std::size_t>& lines)
      : dom_(root, true),
        text_(text),
        read_to_(read_to),
        file_(std::move(file)),
        first_line_(first_line),
        lines_(lines) {}

  bool null() { return value() && dom_.null(); }
  bool boolean(bool b) { return value() && dom_.boolean(b); }
  bool number_integer(json::number_integer_t v) { return value() && dom_.number_integer(v); }
  bool number_unsigned(json::number_unsigned_t v) { return value() && dom_.number_unsigned(v); }
  bool number_float(json::number_float_t v, const json::string_t& s) {
    value();
    if (!std::isfinite(v))
      throw InputError(file_, current_line(),
                       trf("{}: the number {} is beyond the range of a double", where(last_path_), s));
    return dom_.number_float(v, s);
  }
  bool string(json::string_t& s) { return value() && dom_.string(s); }
  bool binary(json::binary_t& b) { return value() && dom_.binary(b); }
  bool start_object(std::size_t n) { return value() && push(false) && dom_.start_object(n); }
  bool key(json::string_t& k) {
    frames_.back().key = k;
    // nlohmann keeps the last of two equal keys: a second "p_meets" would silently replace the first.
    if (lines_.count(path_of_next()) != 0)
      throw InputError(file_, current_line(), trf("{} is given twice in one object", where(path_of_next())));
    return dom_.key(k);
  }
  bool end_object() { return pop() && dom_.end_object(); }
  bool start_array(std::size_t n) { return value() && push(true) && dom_.start_array(n); }
  bool end_array() { return pop() && dom_.end_array(); }
  bool parse_error(std::size_t position, const std::string& token, const nlohmann::detail::exception& e) {
    const std::size_t line = line_at(position > 0 ? position - 1 : 0);
    // nlohmann refuses a number beyond a double (1e400) as out_of_range 406.
    if (e.id == 406)
      throw InputError(file_, line,
                       trf("{}: the number {} is beyond the range of a double", where(path_of_next()), token));
    throw InputError(file_, line, trf("not valid JSON: {}", plain_message(e.what())));
  }

 private:
  struct Frame {
    bool array;
    std::string path;
    std::string key;
    std::size_t index = 0;
  };

  /// Records the line of the value just read, under its path; always true.
  bool value() {
    last_path_ = path_of_next();
    lines_.emplace(last_path_, current_line());
    if (!frames_.empty() && frames_.back().array) ++frames_.back().index;
    return true;
  }
  /// Enters an object or array (always true).
  bool push(bool array) {
    if (frames_.size() >= kMaxDepth)
      throw InputError(file_, current_line(), trf("nested deeper than {} levels", kMaxDepth));
    frames_.push_back({array, last_path_, {}, 0});
    return true;
  }
  bool pop() {
    frames_.pop_back();
    return true;
  }
  std::string path_of_next() const {
    if (frames_.empty()) return {};
    const auto& f = frames_.back();
    if (f.array) return fmt::format("{}[{}]", f.path, f.index);
    return f.path.empty() ? f.key : f.path + "." + f.key;
  }
  /// Line of the last byte of the token just read (a number's terminator is read too, so skip
  /// trailing white space).
  std::size_t current_line() const {
    std::size_t end = static_cast<std::size_t>(read_to_ - text_.data());
    while (end > 1 && std::isspace(static_cast<unsigned char>(text_[end - 1]))) --end;
    return line_at(end > 0 ? end - 1 : 0);
  }
  /// Line of byte `byte`: the newlines before it are counted from the last byte asked for, which
  /// the parser's progress keeps close, so a document is scanned about once.
  std::size_t line_at(std::size_t byte) const {
    byte = std::min(byte, text_.size());
    auto newlines = [&](std::size_t from, std::size_t to) {
      return static_cast<std::size_t>(std::count(text_.begin() + static_cast<std::ptrdiff_t>(from),
                                                 text_.begin() + static_cast<std::ptrdiff_t>(to), '\n'));
    };
    if (byte >= counted_to_)
      newlines_before_ += newlines(counted_to_, byte);
    else
      newlines_before_ -= newlines(byte, counted_to_);
    counted_to_ = byte;
    return first_line_ + newlines_before_;
  }

  nlohmann::detail::json_sax_dom_parser<json> dom_;
  std::string_view text_;
  const char* const& read_to_;
  std::string file_;
  std::size_t first_line_;
  std::unordered_map<std::string, std::size_t>& lines_;
  std::vector<Frame> frames_;
  std::string last_path_;
  mutable std::size_t counted_to_ = 0;       ///< byte up to which newlines are counted
  mutable std::size_t newlines_before_ = 0;  ///< newlines before counted_to_
};

}  // namespace

std::string_view type_name(const json& j) { return j.type_name(); }

Document::Document(std::string_view text, std::string file, std::size_t first_line) : file_(std::move(file)) {
  const char* read_to = text.data();
  LocatingHandler handler(root_, text, read_to, file_, first_line, lines_);
  const TrackedIterator begin(text.data(), &read_to), end(text.data() + text.size(), &read_to);
  json::sax_parse(begin, end, &handler);
}

void require_schema_version(const Value& root) {
  const auto v = root.find("schema_version");
  if (v && v->json().is_number_integer() && v->json().get<std::int64_t>() == kResultSchemaVersion) return;
  const std::string todo =
      trf("this rwcalc reads result schema version {} (docs/result.schema.json): write the result again with it "
          "(e.g. `rwcalc analyze --json`)",
          kResultSchemaVersion);
  if (!v)
    root.fail(
        trf("has no \"schema_version\" (a result of an rwcalc before schema version 2, which named "
            "units in its keys); {}",
            todo));
  v->fail(trf("is {}; {}", v->json().dump(), todo));
}

void require_gyro_units(const Value& analysis, std::string_view consumer) {
  static constexpr std::pair<const char*, const char*> kUsual[] = {{"rate", "deg/h"},      {"Q", "arcsec"},
                                                                   {"N", "deg/sqrt(h)"},   {"B", "deg/h"},
                                                                   {"K", "deg/h/sqrt(h)"}, {"R", "deg/h^2"}};
  const auto units = analysis.find("units");
  if (!units) return;
  for (const auto& [family, usual] : kUsual)
    if (const auto u = units->at(family); u.string() != usual)
      u.fail(
          trf("is \"{}\": {} takes the analysis of a gyro in its usual units (\"{}\"); analyse the record "
              "again without --output-unit",
              u.string(), consumer, usual));
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, 0, tr("cannot open the file"));
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw InputError(path, 0, tr("cannot read the file"));
  return ss.str();
}

Document Document::load(const std::string& path) { return Document(read_file(path), path); }

Value Document::root() const { return Value(*this, root_, ""); }

std::size_t Document::line_of(std::string path) const {
  for (;;) {
    if (const auto it = lines_.find(path); it != lines_.end()) return it->second;
    if (path.empty()) return 0;
    // The parent: drop the last ".key" or "[i]".
    const auto cut = path.find_last_of(".[");
    path.resize(cut == std::string::npos ? 0 : cut);
  }
}

std::string Value::child_path(std::string_view key) const {
  return path_.empty() ? std::string(key) : fmt::format("{}.{}", path_, key);
}

void Value::fail(std::string_view what) const {
  throw InputError(doc_->file(), line(), fmt::format("{} {}", where(path_), what));
}

void Value::wrong_type(std::string_view expected) const {
  fail(trf("must be {}, got {}", expected,
           value_->is_number() || value_->is_boolean() ? shown(*value_) : std::string(type_name(*value_))));
}

const Value& Value::object() const {
  if (!value_->is_object()) wrong_type("an object");
  return *this;
}

Value Value::at(std::string_view key) const {
  object();
  const auto it = value_->find(key);
  if (it == value_->end()) fail(trf("lacks the key \"{}\"", key));
  return Value(*doc_, *it, child_path(key));
}

std::optional<Value> Value::find(std::string_view key) const {
  object();
  const auto it = value_->find(key);
  if (it == value_->end() || it->is_null()) return std::nullopt;
  return Value(*doc_, *it, child_path(key));
}

std::vector<Value> Value::elements() const {
  if (!value_->is_array()) wrong_type("an array");
  std::vector<Value> out;
  out.reserve(value_->size());
  for (std::size_t i = 0; i < value_->size(); ++i)
    out.emplace_back(*doc_, (*value_)[i], fmt::format("{}[{}]", path_, i));
  return out;
}

double Value::number() const {
  if (!value_->is_number()) wrong_type("a number");
  const double v = value_->get<double>();
  if (!std::isfinite(v)) fail("must be a finite number");  // not reachable from text; kept for DOMs built in code
  return v;
}

double Value::number_in(double lo, double hi, std::string_view domain) const {
  const double v = number();
  if (!(v >= lo && v <= hi)) fail(trf("must be {}, got {}", domain, shown(*value_)));
  return v;
}

double Value::positive() const {
  const double v = number();
  if (!(v > 0)) fail(trf("must be a positive number, got {}", shown(*value_)));
  return v;
}

double Value::non_negative() const { return number_in(0, std::numeric_limits<double>::max(), "a number >= 0"); }

std::int64_t Value::integer(std::int64_t lo, std::int64_t hi) const {
  const auto domain = fmt::format("an integer in [{}, {}]", lo, hi);
  if (!value_->is_number()) wrong_type(domain);
  // 2.0 is an integer written as a float; 2.7 and 1e300 are not integers in the range.
  const double v = value_->get<double>();
  if (value_->is_number_float() &&
      (v != std::floor(v) || !(v >= static_cast<double>(lo) && v <= static_cast<double>(hi))))
    fail(trf("must be {}, got {}", domain, shown(*value_)));
  if (value_->is_number_unsigned() && value_->get<std::uint64_t>() > static_cast<std::uint64_t>(hi))
    fail(trf("must be {}, got {}", domain, shown(*value_)));
  const auto i = value_->is_number_float() ? static_cast<std::int64_t>(v) : value_->get<std::int64_t>();
  if (i < lo || i > hi) fail(trf("must be {}, got {}", domain, shown(*value_)));
  return i;
}

std::string Value::string() const {
  if (!value_->is_string()) wrong_type("a string");
  return value_->get<std::string>();
}

bool Value::boolean() const {
  if (!value_->is_boolean()) wrong_type("true or false");
  return value_->get<bool>();
}

}  // namespace rwcalc::json_input
