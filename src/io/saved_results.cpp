// Reading back rwcalc's own JSON results, every value checked against its domain.
#include "rwcalc/saved_results.hpp"
#include "rwcalc/i18n.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <filesystem>
#include <optional>
#include <unordered_map>

#include "rwcalc/error.hpp"
#include "rwcalc/json_input.hpp"
#include "rwcalc/reader.hpp"

namespace rwcalc {

namespace {

using json_input::Document;
using json_input::read_file;
using json_input::Value;
using nlohmann::json;

/// Class numbers rwcalc accepts in a class table (and so in a verdict).
constexpr std::int64_t kMaxClassNumber = 1000000;
/// Counts (samples, blocks, lines…) fit in 2^53, where a double still holds every integer.
constexpr std::int64_t kMaxCount = std::int64_t{1} << 53;

/// Keys a verdict, estimate or run must have for `merge`; for `report` only those present are
/// checked.
class Checker {
 public:
  explicit Checker(RunKeys keys) : combined_(keys == RunKeys::Combined) {}

  /// The member `key`: required when combining, else optional (absent or null: nothing to check).
  [[nodiscard]] std::optional<Value> member(const Value& object, std::string_view key) const {
    if (combined_) {
      const Value v = object.at(key);
      return v.is_null() ? std::nullopt : std::optional<Value>(v);
    }
    return object.find(key);
  }

  void run(const Value& r) const;

 private:
  void estimate(const Value& e) const;
  void fit(const Value& f) const;
  void methods(const Value& m) const;
  void allan(const Value& a) const;
  void outliers(const Value& o) const;
  void input(const Value& in) const;
  void segments(const Value& s) const;
  void verdict(const Value& v) const;
  void parameter_verdict(const Value& p, std::optional<std::size_t> classes) const;

  bool combined_;
};

/// The member `key` when present and not null, checked by `check` (a Value accessor).
template <class Check>
void optional(const Value& object, std::string_view key, Check check) {
  if (const auto v = object.find(key)) (void)check(*v);
}
constexpr auto as_number = [](const Value& v) { return v.number(); };
constexpr auto as_non_negative = [](const Value& v) { return v.non_negative(); };
constexpr auto as_positive = [](const Value& v) { return v.positive(); };
constexpr auto as_string = [](const Value& v) { return v.string(); };
constexpr auto as_boolean = [](const Value& v) { return v.boolean(); };
constexpr auto as_probability = [](const Value& v) { return v.probability(); };
constexpr auto as_count = [](const Value& v) { return v.integer(0, kMaxCount); };

/// A temperature in °C: finite, not below absolute zero.
void temperature(const Value& t) { (void)t.number_in(-273.15, 1000, "a temperature in °C in [-273.15, 1000]"); }

/// A class number, or null for "outside every class"; when given, one of `classes`.
void class_number(const std::optional<Value>& c, const std::vector<std::int64_t>& classes) {
  if (!c) return;
  const auto n = c->integer(0, kMaxClassNumber);
  if (!classes.empty() && std::find(classes.begin(), classes.end(), n) == classes.end())
    c->fail(trf("is class {}, which is not among the verdict's \"classes\"", n));
}

/// Each element of the array `a` checked by `each`; `size`, when known, is how many it must hold.
template <class Each>
void array_of(const Value& a, std::optional<std::size_t> size, std::string_view what, Each each) {
  const auto e = a.elements();
  if (size && e.size() != *size)
    a.fail(trf("must hold {} {} (one per {}), got {}", *size, *size == 1 ? "value" : "values", what, e.size()));
  for (const auto& x : e) (void)each(x);
}

/// A coefficient or cross-check estimate {value, sigma, low95, high95, resolved, …}.
void Checker::estimate(const Value& e) const {
  e.object();
  for (const char* key : {"value", "sigma"})
    if (const auto v = member(e, key)) (void)v->non_negative();
  if (const auto v = member(e, "resolved")) (void)v->boolean();
  if (combined_) (void)e.at("high95");
  for (const char* key : {"low95", "high95"}) optional(e, key, as_non_negative);
  optional(e, "estimate", as_number);
  optional(e, "model_value", as_non_negative);
  optional(e, "in_model", as_boolean);
  optional(e, "fitted", as_boolean);
  optional(e, "unit", as_string);
}

void Checker::fit(const Value& f) const {
  f.object();
  for (const char* key : {"Q", "N", "B", "K", "R"})
    if (const auto c = f.find(key)) estimate(*c);
  for (const char* key : {"chi2_per_dof", "chi2", "tau_min_s", "tau_max_s"}) optional(f, key, as_non_negative);
  optional(f, "p_value", as_probability);
  optional(f, "points", as_count);
}

void Checker::methods(const Value& m) const {
  m.object();
  if (const auto sl = m.find("N_straight_line_paper")) {
    sl->object();
    for (const char* k : {"value", "bias_factor"}) optional(*sl, k, as_non_negative);
    for (const char* k : {"intercept", "slope"}) optional(*sl, k, as_number);
  }
  for (const char* key : {"N_direct", "B_100s", "spread_100s"}) {
    const auto e = m.find(key);
    if (!e) continue;
    estimate(*e);
    for (const char* k : {"edf", "tau_s", "avar", "white_removed", "replicates", "expected", "expected_sigma"})
      optional(*e, k, as_non_negative);
    if (const auto curve = e->find("curve"))
      for (const auto& p : curve->elements()) {
        p.object();
        (void)p.at("t_s").positive();
        optional(p, "intervals", as_count);
        optional(p, "var", as_non_negative);
      }
    for (const char* k : {"t_min_s", "t_max_s", "block_s"}) optional(*e, k, as_non_negative);
    optional(*e, "blocks", as_count);
  }
}

void Checker::allan(const Value& a) const {
  a.object();
  optional(a, "unit", as_string);
  optional(a, "estimator", as_string);
  if (const auto points = a.find("points"))
    for (const auto& p : points->elements()) {
      p.object();
      (void)p.at("tau_s").positive();
      (void)p.at("dev").non_negative();
      for (const char* key : {"dev_low", "dev_high", "var", "edf"}) optional(p, key, as_non_negative);
      optional(p, "m", as_count);
      optional(p, "n", as_count);
    }
}

void Checker::outliers(const Value& o) const {
  o.object();
  std::int64_t count = 0;
  if (const auto c = o.find("count")) count = c->integer(0, kMaxCount);
  if (combined_ && count > 0) (void)o.at("positions");  // the tables list where the outliers are
  if (const auto action = o.find("action")) {
    const auto s = action->string();
    if (s != "keep" && s != "remove" && s != "replace")
      action->fail(trf("must be \"keep\", \"remove\" or \"replace\", got \"{}\"", s));
  }
  if (const auto positions = o.find("positions"))
    for (const auto& p : positions->elements()) {
      p.object();
      (void)p.at("line").integer(1, kMaxCount);
      (void)p.at("time_s").number();
      optional(p, "index", as_count);
    }
}

/// What a run was read from, as far as the report shows it: the identification (a string each, or
/// null when not given), the file's size and digest, the column and the reader's notes.
void Checker::input(const Value& in) const {
  in.object();
  if (const auto id = in.find("identification")) {
    id->object();
    for (const std::string_view key : kIdentificationKeys) optional(*id, key, as_string);
  }
  for (const char* key : {"sha256", "column", "unit", "kind", "rate_source", "time_column", "time_unit"})
    optional(in, key, as_string);
  optional(in, "file_bytes", as_count);
  optional(in, "rate_hz", as_positive);
  for (const char* key : {"notes", "warnings"})
    if (const auto lines = in.find(key)) array_of(*lines, std::nullopt, "line", as_string);
}

/// The segments of a record read with --gaps segments: their count, lengths and gaps.
void Checker::segments(const Value& s) const {
  s.object();
  optional(s, "count", as_count);
  if (const auto v = s.find("samples")) array_of(*v, std::nullopt, "segment", as_count);
  if (const auto v = s.find("durations_s")) array_of(*v, std::nullopt, "segment", as_non_negative);
  if (const auto gaps = s.find("gaps"))
    for (const auto& g : gaps->elements()) {
      g.object();
      (void)g.at("line").integer(1, kMaxCount);
      (void)g.at("missing_s").positive();
      optional(g, "before_sample", as_count);
    }
}

/// The verdict of one parameter (B or N); its arrays hold one value per class when `classes` is
/// known (the verdict's "classes" is given).
void Checker::parameter_verdict(const Value& p, std::optional<std::size_t> classes) const {
  p.object();
  const auto plus = [&](std::size_t extra) { return classes ? std::optional(*classes + extra) : std::nullopt; };
  if (const auto v = member(p, "p_meets")) array_of(*v, plus(0), "class", as_probability);
  if (const auto v = p.find("p_is")) array_of(*v, plus(1), "class and 'outside'", as_probability);
  if (const auto v = p.find("limits")) array_of(*v, plus(0), "class", [](const Value& x) { return x.positive(); });
  if (const auto v = p.find("margin_pct")) array_of(*v, plus(0), "class", as_number);
  optional(p, "p_class", as_probability);
  optional(p, "value", as_non_negative);
  optional(p, "resolved", as_boolean);
  optional(p, "unit", as_string);
}

void Checker::verdict(const Value& v) const {
  v.object();
  std::vector<std::int64_t> classes;
  if (const auto c = combined_ ? std::optional<Value>(v.at("classes")) : v.find("classes")) {
    const auto list = c->elements();
    if (list.empty()) c->fail("must list at least one class");
    for (const auto& x : list) {
      classes.push_back(x.integer(0, kMaxClassNumber));
      if (classes.size() > 1 && classes.back() <= classes[classes.size() - 2])
        x.fail("must be greater than the class before it (classes are listed best first)");
    }
  }
  for (const char* key : {"class", "class_B", "class_N", "class_strict"}) {
    // A class key present with null is "outside every class": member() must still see the key.
    if (combined_) (void)v.at(key);
    class_number(v.find(key), classes);
  }
  if (const auto p = member(v, "p_class")) (void)p->probability();
  for (const char* key : {"p_class_B", "p_class_N"}) optional(v, key, as_probability);
  optional(v, "decisive", as_boolean);
  if (const auto t = v.find("tolerance_pct")) (void)t->number_in(0, 1000, "a percentage in [0, 1000]");
  for (const char* key : {"statement", "statement_B", "statement_N", "b_estimate", "table"})
    optional(v, key, as_string);
  optional(v, "tolerance_changed", as_boolean);
  if (const auto r = v.find("rho_BN")) (void)r->number_in(-1, 1, "a correlation in [-1, 1]");
  // Without "classes" (a hand-made verdict) the arrays cannot be sized against it.
  const auto n = classes.empty() ? std::nullopt : std::optional<std::size_t>(classes.size());
  if (const auto p = member(v, "p_meets")) array_of(*p, n, "class", as_probability);
  if (const auto p = v.find("p_is"))
    array_of(*p, n ? std::optional(*n + 1) : std::nullopt, "class and 'outside'", as_probability);
  for (const char* key : {"B", "N"}) {
    if (const auto p = member(v, key)) {
      parameter_verdict(*p, n);
      for (const char* k : {"class", "class_strict"})
        if (combined_) (void)p->at(k);
      for (const char* k : {"class", "class_strict"}) class_number(p->find(k), classes);
    }
  }
}

void Checker::run(const Value& r) const {
  r.object();
  if (const auto s = member(r, "source")) (void)s->string();
  if (combined_) (void)r.at("temperature_c");  // null: temperature unknown
  if (const auto t = r.find("temperature_c")) temperature(*t);
  optional(r, "temperature_source", as_string);
  optional(r, "samples", as_count);
  optional(r, "rate_hz", as_positive);
  optional(r, "duration_s", as_non_negative);
  for (const char* key : {"mean_rate", "earth_rate", "bias"}) optional(r, key, as_number);
  // The tables and the class limits are a gyro's, in its usual units.
  json_input::require_gyro_units(r, tr("the report (and merge)"));
  if (const auto l = r.find("latitude_deg")) (void)l->number_in(-90, 90, "a latitude in [-90, 90]");
  if (const auto a = r.find("allan")) allan(*a);
  if (const auto f = member(r, "fit")) fit(*f);
  if (const auto m = member(r, "methods")) methods(*m);
  if (const auto o = r.find("outliers")) outliers(*o);
  if (const auto in = r.find("input")) input(*in);
  if (const auto s = r.find("segments")) segments(*s);
  verdict(r.at("verdict"));
  if (const auto c = r.find("conventions")) c->object();
}

/// The object of `diagnose --json`, as far as the report reads it.
void check_diagnosis(const Value& d) {
  d.object();
  optional(d, "source", as_string);
  if (const auto t = d.find("temperature_c")) temperature(*t);
  optional(d, "runs", as_count);
  optional(d, "samples", as_count);
  for (const char* key : {"rate_hz", "duration_s", "scale_arcsec_per_pulse"})
    if (const auto v = d.find(key)) (void)v->positive();
  if (const auto findings = d.find("findings"))
    for (const auto& f : findings->elements()) {
      f.object();
      (void)f.at("effect").string();
      for (const auto& [k, v] : f.json().items())
        if (!v.is_number() && !v.is_string() && !v.is_boolean() && !v.is_null() && !v.is_object() && !v.is_array())
          f.at(k).fail("must be a number, a string, true/false, an object or an array");
    }
  if (const auto gain = d.find("gain")) {
    gain->object();
    for (const auto& [k, v] : gain->json().items())
      if (!v.is_null()) (void)gain->at(k).number();
  }
  auto band = [](const Value& b) {
    for (const auto& p : b.elements()) {
      p.object();
      (void)p.at("tau_s").positive();
      for (const char* key : {"band_low", "band_high", "dev", "median"}) optional(p, key, as_non_negative);
    }
  };
  for (const char* model : {"base_model", "extended_model"})
    if (const auto m = d.find(model)) {
      m->object();
      if (const auto b = m->find("band")) band(*b);
      if (const auto level = m->find("band_level")) (void)level->probability();
    }
  for (const char* key : {"band", "band_extended"})
    if (const auto b = d.find(key)) band(*b);
}

/// The overall verdict of `batch --json`, as far as the report reads it.
void check_overall(const Value& o) {
  o.object();
  std::vector<std::int64_t> classes;
  if (const auto c = o.find("classes"))
    for (const auto& x : c->elements()) classes.push_back(x.integer(0, kMaxClassNumber));
  for (const char* key : {"class", "class_B", "class_N", "class_strict"}) class_number(o.find(key), classes);
  optional(o, "statement", as_string);
  for (const char* key : {"B", "N"})
    if (const auto p = o.find(key)) {
      p->object();
      optional(*p, "statement", as_string);
      class_number(p->find("class"), classes);
    }
  optional(o, "runs", as_count);
  optional(o, "p_class", as_probability);
}

bool has(const json& j, const char* key) { return j.contains(key); }

}  // namespace

void parse_saved_result(std::string_view text, const std::string& file, SavedResults& into) {
  Document doc(text, file);
  const Value root = doc.root();
  if (!root.json().is_object())
    root.fail(
        fmt::format("must be a JSON object from 'rwcalc analyze --json', 'batch --json' or 'diagnose --json', "
                    "got {}",
                    json_input::type_name(root.json())));
  const json& j = root.json();
  const Checker shown(RunKeys::Shown);
  // A batch has an array of runs; a diagnosis also has "runs", the size of its ensemble.
  if (has(j, "runs") && j.at("runs").is_array()) {
    json_input::require_schema_version(root);
    const auto runs = root.at("runs").elements();
    if (runs.empty()) root.at("runs").fail("must hold at least one run");
    for (const auto& r : runs) shown.run(r);
    std::optional<json> overall;
    if (const auto o = root.find("overall")) {
      check_overall(*o);
      overall = o->json();
    }
    std::vector<std::size_t> lines;
    lines.reserve(runs.size());
    for (const auto& r : runs) lines.push_back(r.line());
    json all = doc.take();
    for (std::size_t i = 0; i < lines.size(); ++i) into.analyses.push_back({std::move(all["runs"][i]), file, lines[i]});
    if (overall) into.overalls.push_back(std::move(*overall));
  } else if (has(j, "allan") || has(j, "verdict")) {
    json_input::require_schema_version(root);
    shown.run(root);
    (void)root.at("allan");
    into.analyses.push_back({doc.take(), file, 1});
  } else if (has(j, "band") || has(j, "base_model") || has(j, "findings")) {
    json_input::require_schema_version(root);
    check_diagnosis(root);
    into.diagnoses.push_back({doc.take(), file, 1});
  } else {
    throw InputError(file, 1,
                     tr("not an rwcalc result: expected the JSON of 'rwcalc analyze --json' (\"allan\", \"verdict\"), "
                        "'batch --json' (\"runs\") or 'diagnose --json' (\"base_model\", \"findings\")"));
  }
}

std::vector<SavedRun> parse_json_lines(std::string_view text, const std::string& file, RunKeys keys) {
  const Checker checker(keys);
  std::vector<SavedRun> out;
  std::size_t no = 0;
  std::size_t start = 0;
  while (start < text.size()) {
    const auto end = std::min(text.find('\n', start), text.size());
    const std::string_view line = text.substr(start, end - start);
    start = end + 1;
    ++no;
    if (line.find_first_not_of(" \t\r") == std::string_view::npos) continue;
    Document doc(line, file, no);
    const Value root = doc.root();
    if (!root.json().is_object())
      throw InputError(file, no,
                       trf("not an analyze object but {}; write the lines with `rwcalc batch --jsonl`",
                           json_input::type_name(root.json())));
    json_input::require_schema_version(root);
    if (!root.json().contains("verdict"))
      throw InputError(file, no,
                       tr("not an analyze object (no \"verdict\"); write the lines with `rwcalc batch --jsonl`"));
    checker.run(root);
    out.push_back({doc.take(), file, no});
  }
  if (out.empty()) throw InputError(file, 0, tr("no JSON lines"));
  return out;
}

void load_saved_result(const std::string& path, SavedResults& into) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".jsonl") {
    for (auto& r : load_json_lines(path, RunKeys::Shown)) into.analyses.push_back(std::move(r));
    return;
  }
  parse_saved_result(read_file(path), path, into);
}

namespace {

std::string place(const SavedRun& r) { return fmt::format("{}:{}", r.file, r.line); }
const std::string& source_of(const SavedRun& r) { return r.run.at("source").get_ref<const std::string&>(); }

/// The runs without repeats (see merge_runs), as indices into `runs`.
std::vector<std::size_t> distinct_runs(const std::vector<SavedRun>& runs, bool dedupe) {
  std::vector<std::size_t> kept;
  std::unordered_map<std::string, std::size_t> by_source;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const auto& r = runs[i];
    const auto [it, fresh] = by_source.emplace(source_of(r), i);
    if (fresh) {
      kept.push_back(i);
      continue;
    }
    const auto& first = runs[it->second];
    if (!dedupe)
      throw InputError(r.file, r.line,
                       trf("run '{}' is already given at {}: each run is counted once (--dedupe drops a "
                           "repeated identical line)",
                           source_of(r), place(first)));
    if (r.run != first.run)
      throw InputError(r.file, r.line,
                       trf("run '{}' is also given at {}, with different results: merge cannot tell which "
                           "one holds",
                           source_of(r), place(first)));
  }
  return kept;
}

/// Every run must have been judged against the first run's class table.
void require_one_class_table(const std::vector<SavedRun>& runs, const std::vector<std::size_t>& kept) {
  static const std::array<std::pair<const char*, const char*>, 3> kTable{
      {{"/classes", "verdict.classes"}, {"/B/limits", "verdict.B.limits"}, {"/N/limits", "verdict.N.limits"}}};
  const auto& first = runs[kept.front()];
  for (const auto i : kept) {
    const auto& v = runs[i].run.at("verdict");
    for (const auto& [pointer, name] : kTable) {
      const json::json_pointer ptr(pointer);
      const auto& v0 = first.run.at("verdict");
      const bool in0 = v0.contains(ptr), in = v.contains(ptr);
      if (in0 == in && (!in || v0.at(ptr) == v.at(ptr))) continue;
      throw InputError(runs[i].file, runs[i].line,
                       trf("run '{}' was judged against another class table (\"{}\") than run '{}' at {}",
                           source_of(runs[i]), name, source_of(first), place(first)));
    }
  }
}

}  // namespace

std::vector<nlohmann::json> merge_runs(std::vector<SavedRun> runs, bool dedupe) {
  if (runs.empty()) throw UsageError(tr("merge: no runs"));
  const auto kept = distinct_runs(runs, dedupe);
  require_one_class_table(runs, kept);
  std::vector<nlohmann::json> out;
  out.reserve(kept.size());
  for (const auto i : kept) out.push_back(std::move(runs[i].run));
  return out;
}

std::vector<SavedRun> load_json_lines(const std::string& path, RunKeys keys) {
  return parse_json_lines(read_file(path), path, keys);
}

}  // namespace rwcalc
