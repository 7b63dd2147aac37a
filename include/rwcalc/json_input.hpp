#pragma once
// Reading JSON that rwcalc is given (saved results, class tables, models). JSON from another
// machine is untrusted: every value is read through a typed accessor that checks its type and
// domain and otherwise throws an InputError naming the file, the value's line and key path, e.g.
//   report.json:12: "fit.N.value" must be a number, got string
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace rwcalc::json_input {

/// Deepest nesting accepted (rwcalc's results nest 6 levels): refused before anything walks it
/// recursively.
inline constexpr std::size_t kMaxDepth = 64;

class Value;

/// A parsed JSON text with the line of each value (by key path), for error messages.
class Document {
 public:
  /// `text` starts on line `first_line` of `file`. Throws InputError on invalid JSON, a number
  /// beyond a double (1e400), a key given twice, or nesting deeper than kMaxDepth.
  Document(std::string_view text, std::string file, std::size_t first_line = 1);
  /// A value built in code (errors name `file` and the key path, no line).
  static Document of_value(nlohmann::json value, std::string file) {
    Document d;
    d.file_ = std::move(file);
    d.root_ = std::move(value);
    return d;
  }
  static Document load(const std::string& path);

  [[nodiscard]] Value root() const;
  [[nodiscard]] const std::string& file() const { return file_; }
  /// Line of the value at `path`, else of its nearest ancestor in the document.
  [[nodiscard]] std::size_t line_of(std::string path) const;
  /// The parsed value, moved out (the accessors must not be used afterwards).
  [[nodiscard]] nlohmann::json take() { return std::move(root_); }

 private:
  Document() = default;
  std::string file_;
  nlohmann::json root_;
  std::unordered_map<std::string, std::size_t> lines_;
};

/// One value of a Document with its key path ("" for the root, "runs[2].fit.B").
class Value {
 public:
  Value(const Document& doc, const nlohmann::json& value, std::string path)
      : doc_(&doc), value_(&value), path_(std::move(path)) {}

  [[nodiscard]] const nlohmann::json& json() const { return *value_; }
  [[nodiscard]] const std::string& path() const { return path_; }
  [[nodiscard]] std::size_t line() const { return doc_->line_of(path_); }
  [[nodiscard]] bool is_null() const { return value_->is_null(); }

  [[nodiscard]] Value at(std::string_view key) const;                   ///< must be present
  [[nodiscard]] std::optional<Value> find(std::string_view key) const;  ///< absent or null: none
  [[nodiscard]] std::vector<Value> elements() const;                    ///< must be an array
  const Value& object() const;                                          ///< must be an object

  [[nodiscard]] double number() const;  ///< finite
  /// Finite, in [lo, hi]; `domain` names the range in the message ("a probability in [0, 1]").
  [[nodiscard]] double number_in(double lo, double hi, std::string_view domain) const;
  [[nodiscard]] double positive() const;
  [[nodiscard]] double non_negative() const;
  [[nodiscard]] double probability() const { return number_in(0, 1, "a probability in [0, 1]"); }
  /// No fraction (2.0 is fine, 2.7 is not), in [lo, hi].
  [[nodiscard]] std::int64_t integer(std::int64_t lo, std::int64_t hi) const;
  [[nodiscard]] std::string string() const;
  [[nodiscard]] bool boolean() const;

  /// Throws InputError(file, line of this value, "\"PATH\" WHAT").
  [[noreturn]] void fail(std::string_view what) const;

 private:
  [[noreturn]] void wrong_type(std::string_view expected) const;
  [[nodiscard]] std::string child_path(std::string_view key) const;

  const Document* doc_;
  const nlohmann::json* value_;
  std::string path_;
};

/// The version of the schema of the JSON rwcalc writes (docs/result.schema.json): every document
/// carries it as "schema_version". Version 2 named units as fields (keys carry none).
inline constexpr int kResultSchemaVersion = 2;

/// Refuses a document of rwcalc's results written under another schema version (or none, as
/// before version 2): InputError naming the file and line, the version found and what to do.
void require_schema_version(const Value& root);

/// Refuses an analysis whose numbers are not in a gyro's usual units ("units": rate deg/h, Q arcsec,
/// N deg/sqrt(h), B deg/h, K deg/h/sqrt(h), R deg/h^2; what `analyze` of a gyro writes without
/// --output-unit), which `consumer` ("--from", "the report") needs: InputError naming the key, the
/// unit found and what to do. An object without "units" (made by hand) is taken as in those units.
void require_gyro_units(const Value& analysis, std::string_view consumer);

/// The whole file; InputError when it cannot be opened or read.
std::string read_file(const std::string& path);

/// JSON type name for messages ("number", "string", "object", …).
std::string_view type_name(const nlohmann::json& j);

}  // namespace rwcalc::json_input
