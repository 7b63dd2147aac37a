// The lab profile of a test protocol: a YAML file read with libyaml into checked fields.
#include "rwcalc/lab_profile.hpp"

#include <fmt/format.h>
#include <yaml.h>

#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <set>

#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"

namespace rwcalc {

namespace {

/// One YAML document loaded with its marks; every error names the file and the node's line.
class YamlDocument {
 public:
  explicit YamlDocument(std::string path) : path_(std::move(path)) {
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path_.c_str(), "rb"), std::fclose);
    if (!file) throw InputError(path_, 0, trf("cannot open the lab profile: {}", std::strerror(errno)));
    yaml_parser_t parser;
    yaml_parser_initialize(&parser);
    yaml_parser_set_input_file(&parser, file.get());
    const bool loaded = yaml_parser_load(&parser, &doc_) != 0;
    if (!loaded) {
      const std::size_t line = parser.problem_mark.line + 1;
      const std::string problem = parser.problem ? parser.problem : "";
      yaml_parser_delete(&parser);
      throw InputError(path_, line, trf("the lab profile is not valid YAML: {}", problem));
    }
    yaml_parser_delete(&parser);
    loaded_ = true;
  }
  ~YamlDocument() {
    if (loaded_) yaml_document_delete(&doc_);
  }
  YamlDocument(const YamlDocument&) = delete;
  YamlDocument& operator=(const YamlDocument&) = delete;

  yaml_node_t* root() { return yaml_document_get_root_node(&doc_); }
  yaml_node_t* node(int index) { return yaml_document_get_node(&doc_, index); }
  [[noreturn]] void fail(const yaml_node_t* n, const std::string& message) const {
    throw InputError(path_, n ? n->start_mark.line + 1 : 0, message);
  }

  /// The scalar text of a node; anything else is an error naming `key`.
  std::string scalar(const yaml_node_t* n, std::string_view key) const {
    if (!n || n->type != YAML_SCALAR_NODE) fail(n, trf("'{}' must be a text, not a list or a mapping", key));
    return {reinterpret_cast<const char*>(n->data.scalar.value), n->data.scalar.length};
  }

  /// Calls `field(key, value node)` for each pair of a mapping; anything else is an error.
  void each_pair(yaml_node_t* map, std::string_view what,
                 const std::function<void(const std::string&, yaml_node_t*)>& field) {
    if (!map || map->type != YAML_MAPPING_NODE) fail(map, trf("{} must be a mapping of keys to values", what));
    std::set<std::string> seen;
    for (auto* p = map->data.mapping.pairs.start; p < map->data.mapping.pairs.top; ++p) {
      auto key = scalar(node(p->key), what);
      if (!seen.insert(key).second) fail(node(p->key), trf("'{}' is given twice", key));
      field(key, node(p->value));
    }
  }

 private:
  std::string path_;
  yaml_document_t doc_{};
  bool loaded_ = false;
};

/// A number as a lab writes it: 21.5 or 21,5.
double number_field(YamlDocument& y, const yaml_node_t* n, std::string_view key) {
  std::string text = y.scalar(n, key);
  for (char& c : text)
    if (c == ',') c = '.';
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || errno == ERANGE || !std::isfinite(v))
    y.fail(n, trf("'{}': '{}' is not a number", key, text));
  return v;
}

CalendarDate date_field(YamlDocument& y, const yaml_node_t* n, std::string_view key) {
  const std::string text = y.scalar(n, key);
  CalendarDate d;
  char tail = 0;
  const bool iso = std::sscanf(text.c_str(), "%4d-%2d-%2d%c", &d.year, &d.month, &d.day, &tail) == 3;
  const bool dotted = !iso && std::sscanf(text.c_str(), "%2d.%2d.%4d%c", &d.day, &d.month, &d.year, &tail) == 3;
  static constexpr std::array<int, 12> kDays{31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  const bool leap = d.year % 4 == 0 && (d.year % 100 != 0 || d.year % 400 == 0);
  if (!(iso || dotted) || d.year < 1900 || d.year > 2999 || d.month < 1 || d.month > 12 || d.day < 1 ||
      d.day > kDays[static_cast<std::size_t>(d.month - 1)] || (d.month == 2 && d.day == 29 && !leap))
    y.fail(n, trf("'{}': '{}' is not a date (write 2026-11-27 or 27.11.2026)", key, text));
  return d;
}

ProtocolPerson person_field(YamlDocument& y, yaml_node_t* n, const std::string& key) {
  ProtocolPerson p;
  y.each_pair(n, key, [&](const std::string& k, yaml_node_t* v) {
    if (k == "position")
      p.position = y.scalar(v, k);
    else if (k == "name")
      p.name = y.scalar(v, k);
    else
      y.fail(v, trf("'{}' has no key '{}' (its keys: position, name)", key, k));
  });
  return p;
}

/// The items of a list, each a mapping handed to `item`.
void each_item(YamlDocument& y, yaml_node_t* list, const std::string& key,
               const std::function<void(yaml_node_t*)>& item) {
  if (!list || list->type != YAML_SEQUENCE_NODE) y.fail(list, trf("'{}' must be a list", key));
  for (auto* i = list->data.sequence.items.start; i < list->data.sequence.items.top; ++i) item(y.node(*i));
}

MeasuringInstrument instrument_field(YamlDocument& y, yaml_node_t* n) {
  MeasuringInstrument m;
  bool verified = false;
  y.each_pair(n, "instruments", [&](const std::string& k, yaml_node_t* v) {
    if (k == "type")
      m.type = y.scalar(v, k);
    else if (k == "serial")
      m.serial = y.scalar(v, k);
    else if (k == "verified")
      m.verified = date_field(y, v, k), verified = true;
    else if (k == "valid_until")
      m.valid_until = date_field(y, v, k);
    else if (k == "certificate")
      m.certificate = y.scalar(v, k);
    else
      y.fail(v, trf("an instrument has no key '{}' (its keys: type, serial, verified, valid_until, certificate)", k));
  });
  if (m.type.empty() || m.serial.empty() || !verified)
    y.fail(n, tr("each instrument needs its type, serial and verified (the date of its last verification)"));
  return m;
}

AmbientCondition condition_field(YamlDocument& y, yaml_node_t* n) {
  AmbientCondition c;
  bool value = false;
  y.each_pair(n, "conditions", [&](const std::string& k, yaml_node_t* v) {
    if (k == "quantity")
      c.quantity = y.scalar(v, k);
    else if (k == "value")
      c.value = number_field(y, v, k), value = true;
    else if (k == "uncertainty")
      c.uncertainty = number_field(y, v, k);
    else if (k == "unit")
      c.unit = y.scalar(v, k);
    else
      y.fail(v, trf("a condition has no key '{}' (its keys: quantity, value, uncertainty, unit)", k));
  });
  if (c.quantity.empty() || !value || c.unit.empty())
    y.fail(n, tr("each condition needs its quantity, value and unit"));
  if (c.uncertainty && !(*c.uncertainty > 0)) y.fail(n, tr("'uncertainty' must be positive"));
  return c;
}

}  // namespace

LabProfile read_lab_profile(const std::string& path) {
  YamlDocument y(path);
  LabProfile p;
  yaml_node_t* root = y.root();
  if (!root) throw InputError(path, 0, tr("the lab profile is empty"));
  y.each_pair(root, tr("the lab profile"), [&](const std::string& k, yaml_node_t* v) {
    if (k == "laboratory")
      p.laboratory = y.scalar(v, k);
    else if (k == "address")
      p.address = y.scalar(v, k);
    else if (k == "accreditation")
      p.accreditation = y.scalar(v, k);
    else if (k == "approver")
      p.approver = person_field(y, v, k);
    else if (k == "performer")
      p.performer = person_field(y, v, k);
    else if (k == "checker")
      p.checker = person_field(y, v, k);
    else if (k == "customer")
      p.customer = y.scalar(v, k);
    else if (k == "method")
      p.method = y.scalar(v, k);
    else if (k == "instruments")
      each_item(y, v, k, [&](yaml_node_t* i) { p.instruments.push_back(instrument_field(y, i)); });
    else if (k == "conditions")
      each_item(y, v, k, [&](yaml_node_t* i) { p.conditions.push_back(condition_field(y, i)); });
    else
      y.fail(v, trf("unknown key '{}' (the keys: laboratory, address, accreditation, approver, performer, checker, "
                    "customer, method, instruments, conditions)",
                    k));
  });
  return p;
}

std::string date_text(const CalendarDate& d) {
  return language() == Language::Russian ? fmt::format("{:02}.{:02}.{:04}", d.day, d.month, d.year)
                                         : fmt::format("{:04}-{:02}-{:02}", d.year, d.month, d.day);
}

}  // namespace rwcalc
