// Batch analysis over files (in parallel), JSON-lines merge, and the Table 1 / Table 2 layout.
#include "rwcalc/batch.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <utility>

#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/json_input.hpp"
#include "rwcalc/parallel.hpp"
#include "rwcalc/printable.hpp"
#include "rwcalc/progress.hpp"

namespace rwcalc {

namespace {

using nlohmann::json;

std::optional<int> opt_int(const json& j) {
  if (j.is_null()) return std::nullopt;
  return j.get<int>();
}

json opt_json(const std::optional<int>& c) { return c ? json(*c) : json(nullptr); }

/// The worse of two classes (empty = outside every class is the worst).
std::optional<int> worse(const std::optional<int>& a, const std::optional<int>& b) {
  if (!a || !b) return std::nullopt;
  return std::max(*a, *b);
}

/// Overall class and probabilities over runs for one verdict object path (B, N or overall).
json combine(const std::vector<json>& runs, const std::vector<int>& classes, const char* param) {
  std::optional<int> cls = classes.front();
  std::optional<int> strict = classes.front();
  std::vector<double> p_meets(classes.size(), 1.0);
  for (const auto& r : runs) {
    const json& v = r.at("verdict");
    const json& src = param ? v.at(param) : v;
    const auto c = opt_int(param ? src.at("class") : v.at("class"));
    const auto cs = opt_int(src.at("class_strict"));
    cls = worse(cls, c);
    strict = worse(strict, cs);
    const auto pm = src.at("p_meets").get<std::vector<double>>();
    if (pm.size() != classes.size()) throw InputError(r.value("source", "?"), 0, tr("runs use different class tables"));
    for (std::size_t k = 0; k < classes.size(); ++k) p_meets[k] *= pm[k];
  }
  std::vector<double> p_is;
  double prev = 0;
  for (double p : p_meets) {
    const double f = std::clamp(p, prev, 1.0);
    p_is.push_back(f - prev);
    prev = f;
  }
  p_is.push_back(1.0 - prev);
  std::size_t s = classes.size();
  for (std::size_t k = 0; k < classes.size(); ++k)
    if (cls && classes[k] == *cls) s = k;
  return {{"class", opt_json(cls)}, {"class_strict", opt_json(strict)},
          {"p_meets", p_meets},     {"p_is", p_is},
          {"p_class", p_is[s]},     {"statement", describe_class(p_is, cls, classes)}};
}

bool withheld(const json& run) { return run.at("verdict").value("withheld", false); }

/// The overall verdict when a run's verdict is withheld (its fit rejected): none over the runs, naming
/// them; null when every run has a verdict.
json withheld_overall(const std::vector<json>& runs) {
  std::vector<std::string> sources;
  for (const auto& r : runs)
    if (withheld(r)) sources.push_back(r.at("source").get<std::string>());
  if (sources.empty()) return nullptr;
  std::string names;
  for (const auto& n : sources) names += (names.empty() ? "" : ", ") + printable(n);
  const std::string st =
      trf("no verdict: the fit of {} of {} run(s) is rejected ({})", sources.size(), runs.size(), names);
  const json none = {{"class", nullptr}, {"class_strict", nullptr}, {"p_meets", nullptr},
                     {"p_is", nullptr},  {"p_class", nullptr},      {"statement", st}};
  json o = none;
  o["withheld"] = true;
  o["runs_withheld"] = sources;
  o["class_B"] = o["class_N"] = nullptr;
  o["B"] = o["N"] = none;
  return o;
}

struct Series {
  const char* key;
  const char* label;
  const char* unit;
  std::vector<std::string> path;
};

const std::vector<Series>& series_list() {
  static const std::vector<Series> s{
      {"N_fit", N_("N (AV fit)"), N_("deg/sqrt(h)"), {"fit", "N"}},
      {"N_direct", N_("N (direct)"), N_("deg/sqrt(h)"), {"methods", "N_direct"}},
      {"B_fit", N_("B (AV fit)"), N_("deg/h"), {"fit", "B"}},
      {"B_100s", N_("B (100-s avg)"), N_("deg/h"), {"methods", "B_100s"}},
  };
  return s;
}

const json* lookup(const json& run, const std::vector<std::string>& path) {
  const json* j = &run;
  for (const auto& k : path) {
    if (!j->is_object() || !j->contains(k)) return nullptr;
    j = &(*j)[k];
  }
  return j->is_null() ? nullptr : j;
}

/// Weighted linear trend with temperature and the worst case over the runs.
json trend(const std::vector<json>& runs, const Series& s) {
  double sw = 0, st = 0, sv = 0, stt = 0, stv = 0;
  int n = 0;
  json worst = nullptr;
  for (const auto& r : runs) {
    const json* e = lookup(r, s.path);
    if (!e) continue;
    const double v = e->at("value").get<double>();
    if (worst.is_null() || v > worst.at("value").get<double>())
      worst = {{"value", v},
               {"high95", e->at("high95")},
               {"resolved", e->at("resolved")},
               {"temperature_c", r.at("temperature_c")},
               {"source", r.at("source")}};
    if (r.at("temperature_c").is_null() || !e->at("resolved").get<bool>()) continue;
    const double sig = e->at("sigma").get<double>();
    if (!(sig > 0)) continue;
    const double t = r.at("temperature_c").get<double>();
    const double w = 1.0 / (sig * sig);
    sw += w;
    st += w * t;
    sv += w * v;
    stt += w * t * t;
    stv += w * t * v;
    ++n;
  }
  json out = {{"label", s.label}, {"unit", s.unit}, {"worst", worst}, {"runs_in_trend", n}};
  const double det = sw * stt - st * st;
  if (n >= 3 && det > 0) {
    const double b = (sw * stv - st * sv) / det;
    const double tm = st / sw;
    const double a = sv / sw;  // value at the weighted mean temperature
    out["slope_per_10C"] = 10.0 * b;
    out["slope_per_10C_sigma"] = 10.0 * std::sqrt(sw / det);
    out["value_at_mean_temperature"] = a;
    out["mean_temperature_c"] = tm;
  }
  return out;
}

std::string cell(const json& run, const std::vector<std::string>& path, int digits = 2) {
  const json* e = lookup(run, path);
  if (!e) return "n/a";
  const double v = e->at("value").get<double>();
  const double sg = e->at("sigma").get<double>();
  if (!e->at("resolved").get<bool>()) return fmt::format("< {:.{}g}", v, digits + 1);
  return fmt::format("{:.{}g} ± {:.{}g}", v, digits + 1, sg, 1 + (sg < 0.15 * v ? 1 : 0));
}

/// A cross-check's cell: value and 95 % interval ("< x" when not resolved).
std::string interval_cell(const json& run, const std::vector<std::string>& path) {
  const json* e = lookup(run, path);
  if (!e) return "n/a";
  const double v = e->at("value").get<double>();
  if (!e->at("resolved").get<bool>()) return fmt::format("< {:.3g}", v);
  return fmt::format("{:.3g} [{:.3g}, {:.3g}]", v, e->at("low95").get<double>(), e->at("high95").get<double>());
}

std::string temp_cell(const json& run) {
  return run.at("temperature_c").is_null() ? std::string("?")
                                           : fmt::format("{:+g}", run.at("temperature_c").get<double>());
}

std::string class_cell(const json& v) {
  return v.is_null() ? std::string(tr("none")) : fmt::format("{}", v.get<int>());
}

/// One run's line of the batch text's outlier section: count, action, the first input lines.
/// "  file: [code] message" for each warning of a run (analyze's "warnings"); empty when none.
std::string warning_lines(const json& run) {
  std::string s;
  const auto w = run.find("warnings");
  if (w == run.end() || !w->is_array()) return s;
  for (const auto& x : *w)
    s += fmt::format("  {}: [{}] {}\n", as_typed(run.at("source").get<std::string>()), x.value("code", ""),
                     printable(x.value("message", "")));
  return s;
}

std::string outliers_line(const json& run) {
  const std::string source = as_typed(run.at("source").get<std::string>());
  if (!run.contains("outliers") || !run.at("outliers").is_object())
    return trf("  {}: not in the results (no outlier summary)\n", source);
  const auto& o = run.at("outliers");
  const auto n = o.value("count", std::size_t{0});
  if (n == 0) return trf("  {}: none found\n", source);
  const std::string action = o.value("action", std::string("keep"));
  std::string s = trf("  {}: {} outlier(s) {}", source, n,
                      action == "keep"      ? tr("kept")
                      : action == "remove"  ? tr("removed")
                      : action == "replace" ? tr("replaced by the local median")
                                            : tr("with action ") + action);
  const auto& pos = o.at("positions");
  for (std::size_t k = 0; k < pos.size() && k < 5; ++k)
    s += trf("{} line {} ({:g} s)", k ? "," : tr(": at"), pos[k].at("line").get<std::size_t>(),
             pos[k].at("time_s").get<double>());
  return s + (n > 5 ? ", …\n" : "\n");
}

}  // namespace

std::vector<json> analyze_files(const std::vector<std::string>& files, const ReadOptions& read,
                                const AnalysisOptions& options) {
  if (files.empty()) throw UsageError(tr("batch: no input files"));
  // Files are independent: each is read and analysed on its own (the loops inside an analysis
  // then run serially, parallel_for being nested). Results and errors are kept per file.
  std::vector<json> out(files.size());
  std::vector<std::exception_ptr> errors(files.size());
  Progress progress(tr("analysing the runs"), files.size(), options.progress);
  parallel_for(files.size(), [&](std::size_t i) {
    try {
      const AnalysisResult r = analyze(read_recording(files[i], read), options);
      progress.advance();
      // The batch tables and the report are in a gyro's units and classes: an accelerometer
      // column would be printed under them.
      if (r.sensor != SensorKind::Gyro)
        throw UsageError(
            fmt::format("{}: column '{}' is an accelerometer channel; batch and report take gyro runs "
                        "(use rwcalc imu or analyze for accelerometers)",
                        files[i], r.column));
      out[i] = to_json(r);
    } catch (...) {
      errors[i] = std::current_exception();
    }
  });
  for (std::size_t i = 0; i < files.size(); ++i) {
    if (!errors[i]) continue;
    try {
      std::rethrow_exception(errors[i]);
    } catch (const InputError&) {
      throw;  // already names the file
    } catch (const AnalysisError& e) {
      const std::string w = e.what();
      throw AnalysisError(w.rfind(files[i], 0) == 0 ? w : fmt::format("{}: {}", files[i], w));
    }
  }
  return out;
}

json summarize_runs(std::vector<json> runs, const std::string& source) {
  if (runs.empty()) throw InputError(source, 0, tr("no runs to summarize"));
  for (const auto& r : runs)
    for (const char* k : {"source", "temperature_c", "fit", "methods", "verdict"})
      if (!r.is_object() || !r.contains(k))
        throw InputError(source, 0, trf("a run lacks the key \"{}\" of `rwcalc analyze --json`", k));
  std::stable_sort(runs.begin(), runs.end(), [](const json& a, const json& b) {
    const bool na = a.at("temperature_c").is_null(), nb = b.at("temperature_c").is_null();
    if (na != nb) return nb;
    if (na) return a.at("source").get<std::string>() < b.at("source").get<std::string>();
    return a.at("temperature_c").get<double>() < b.at("temperature_c").get<double>();
  });
  std::vector<int> classes;
  try {
    classes = runs.front().at("verdict").at("classes").get<std::vector<int>>();
    for (const auto& r : runs)
      if (r.at("verdict").at("classes").get<std::vector<int>>() != classes)
        throw InputError(source, 0, tr("runs were judged against different class tables"));
    json overall = withheld_overall(runs);
    if (overall.is_null()) {
      overall = combine(runs, classes, nullptr);
      overall["class_B"] = combine(runs, classes, "B").at("class");
      overall["class_N"] = combine(runs, classes, "N").at("class");
      overall["B"] = combine(runs, classes, "B");
      overall["N"] = combine(runs, classes, "N");
    }
    overall["tolerance_pct"] = runs.front().at("verdict").value("tolerance_pct", 0.0);
    overall["tolerance_changed"] = overall.at("class") != overall.at("class_strict") ||
                                   overall["B"].at("class") != overall["B"].at("class_strict");
    overall["b_estimate"] = runs.front().at("verdict").value("b_estimate", "fit");
    overall["table"] = runs.front().at("verdict").value("table", "");
    overall["classes"] = classes;
    overall["runs"] = runs.size();
    json trends = json::object();
    for (const auto& s : series_list()) trends[s.key] = trend(runs, s);
    // Built key by key so that the runs are moved in, not deep-copied as an initializer list would.
    json out = json::object();
    out["schema_version"] = json_input::kResultSchemaVersion;
    out["runs"] = std::move(runs);
    out["overall"] = std::move(overall);
    out["trends"] = std::move(trends);
    return out;
  } catch (const json::exception& e) {
    throw InputError(source, 0, trf("malformed run object: {}", e.what()));
  }
}

std::string format_batch_text(const json& summary) {
  const auto& runs = summary.at("runs");
  const auto& ov = summary.at("overall");
  std::string s;
  s += trf("rwcalc batch: {} run(s); class table {}; B from {}{}\n\n", runs.size(),
           tr(ov.value("table", std::string())), ov.value("b_estimate", "fit"),
           ov.value("tolerance_pct", 0.0) > 0
               ? trf("; +{:g} % heading-gyro tolerance on B", ov.value("tolerance_pct", 0.0))
               : std::string(tr("; strict limits")));
  s += tr("Table 1: coefficients (AV fit ±1 sigma; cross-checks [95 % interval]; \"< x\": 95 % upper bound)\n");
  s += fmt::format("  {:>6}  {:<22} {:<30} {:<22} {:<30} {}\n", tr("T, °C"), tr("N (AV), °/√h"), tr("N direct, °/√h"),
                   tr("B (AV), °/h"), tr("B 100-s avg, °/h"), tr("file"));
  for (const auto& r : runs)
    s += fmt::format("  {:>6}  {:<22} {:<30} {:<22} {:<30} {}\n", temp_cell(r), cell(r, {"fit", "N"}),
                     interval_cell(r, {"methods", "N_direct"}), cell(r, {"fit", "B"}),
                     interval_cell(r, {"methods", "B_100s"}), as_typed(r.at("source").get<std::string>()));
  s += tr("\nTable 2: class per parameter (probability of the stated class)\n");
  s += fmt::format("  {:>6}  {:<30} {:<30} {}\n", tr("T, °C"), tr("by N"), tr("by B"), tr("overall"));
  for (const auto& r : runs) {
    const auto& v = r.at("verdict");
    std::string o = v.value("statement", class_cell(v.at("class")));
    if (v.value("tolerance_changed", false)) o += trf(" [tolerance; strict {}]", class_cell(v.at("class_strict")));
    s += fmt::format("  {:>6}  {:<30} {:<30} {}\n", temp_cell(r), v.value("statement_N", class_cell(v.at("class_N"))),
                     v.value("statement_B", class_cell(v.at("class_B"))), o);
  }
  // Outliers are never passed over in silence: one line per run.
  s += tr("\nOutliers (see 'rwcalc analyze' for each; --outliers keep|remove|replace)\n");
  for (const auto& r : runs) s += outliers_line(r);
  std::string warnings;
  for (const auto& r : runs) warnings += warning_lines(r);
  if (!warnings.empty()) s += tr("\nWarnings (see 'rwcalc analyze' for each run)\n") + warnings;
  s += trf("\nOverall over the runs: {}", ov.at("statement").get<std::string>());
  if (ov.value("tolerance_changed", false))
    s += trf("  [with the +{:g} % tolerance on B; strict: class {}]", ov.value("tolerance_pct", 0.0),
             class_cell(ov.at("class_strict")));
  if (ov.value("withheld", false))  // the runs' rows above say why and what to run
    s += "\n";
  else
    s += trf("\n  by N: {}; by B: {}\n", ov.at("N").at("statement").get<std::string>(),
             ov.at("B").at("statement").get<std::string>());
  s += tr("\nTrend with temperature (weighted linear fit) and worst case\n");
  for (const auto& [key, t] : summary.at("trends").items()) {
    const std::string unit = tr(t.at("unit").get<std::string>());
    s += fmt::format("  {:<14}", tr(t.at("label").get<std::string>()));
    if (t.contains("slope_per_10C"))
      s += trf(" {:+.3g} ± {:.2g} {} per 10 °C;", t.at("slope_per_10C").get<double>(),
               t.at("slope_per_10C_sigma").get<double>(), unit);
    else
      s += tr(" no trend (fewer than 3 runs with temperature);");
    if (!t.at("worst").is_null()) {
      const auto& w = t.at("worst");
      s += trf(" worst {}{:.3g} {} at {} °C", w.at("resolved").get<bool>() ? "" : "< ", w.at("value").get<double>(),
               unit, temp_cell(w));
    }
    s += "\n";
  }
  s +=
      tr("\nConventions: Q, N, B, K, R as in IEEE 952 (B from sigma² = (2 ln2/π)B²); intervals 95 % profile "
         "likelihood.\n");
  return s;
}

std::string format_batch_markdown(const json& summary) {
  const auto& runs = summary.at("runs");
  const auto& ov = summary.at("overall");
  std::string s;
  s +=
      tr("| T, °C | N (AV), °/√h | N direct [95 %], °/√h | B (AV), °/h | B 100-s avg [95 %], °/h "
         "| class by N | class by B | class |\n");
  s += "|---|---|---|---|---|---|---|---|\n";
  for (const auto& r : runs) {
    const auto& v = r.at("verdict");
    s += fmt::format("| {} | {} | {} | {} | {} | {} | {} | {} |\n", temp_cell(r), cell(r, {"fit", "N"}),
                     interval_cell(r, {"methods", "N_direct"}), cell(r, {"fit", "B"}),
                     interval_cell(r, {"methods", "B_100s"}), v.value("statement_N", ""), v.value("statement_B", ""),
                     v.value("statement", ""));
  }
  s += fmt::format("| {} | | | | | {} | {} | {} |\n", tr("overall"), ov.at("N").at("statement").get<std::string>(),
                   ov.at("B").at("statement").get<std::string>(), ov.at("statement").get<std::string>());
  s += tr("\nOutliers (--outliers keep|remove|replace):\n\n");
  for (const auto& r : runs) {
    std::string item = outliers_line(r);  // "  file: …" → "- file: …", a Markdown list item
    item[0] = '-';
    s += item;
  }
  std::string warnings;
  for (const auto& r : runs) warnings += warning_lines(r);
  if (!warnings.empty()) {
    s += tr("\nWarnings:\n\n");
    for (std::size_t at = 0; at < warnings.size();) {  // "  file: …" → "- file: …" line by line
      const std::size_t end = warnings.find('\n', at);
      s += "- " + warnings.substr(at + 2, end - at - 1);
      at = end + 1;
    }
  }
  return s;
}

std::string format_batch_csv(const json& summary) {
  std::string s =
      "source,temperature_c,N_fit,N_fit_sigma,N_fit_resolved,N_direct,N_direct_sigma,B_fit,B_fit_sigma,B_fit_resolved,"
      "B_100s,B_100s_sigma,class_N,class_B,class,p_class,outliers,outlier_action\n";
  auto val = [](const json& r, const std::vector<std::string>& path, const char* k) -> std::string {
    const json* e = lookup(r, path);
    if (!e) return "";
    const json& x = e->at(k);
    if (x.is_boolean()) return x.get<bool>() ? "true" : "false";
    return fmt::format("{:.6g}", x.get<double>());
  };
  auto cls = [](const json& c) { return c.is_null() ? std::string("") : fmt::format("{}", c.get<int>()); };
  auto csv_escape = [](const std::string& x) {
    if (x.find_first_of(",\"\n") == std::string::npos) return x;
    std::string o = "\"";
    for (char ch : x) o += ch == '"' ? std::string("\"\"") : std::string(1, ch);
    return o + "\"";
  };
  // A withheld verdict (a rejected fit) has no probability: its cell is empty, like its class.
  auto probability = [](const json& v) {
    return v.at("p_class").is_null() ? std::string() : fmt::format("{:.4f}", v.at("p_class").get<double>());
  };
  for (const auto& r : summary.at("runs")) {
    const auto& v = r.at("verdict");
    const json* o = lookup(r, {"outliers"});
    std::string values;  // value, sigma (and resolved, for the fit) of each series
    for (const auto& se : series_list())
      for (const char* k : {"value", "sigma", "resolved"})
        if (std::string_view(k) != "resolved" || se.path[0] == "fit") values += val(r, se.path, k) + ",";
    s += fmt::format("{},{},{}{},{},{},{},{},{}\n", csv_escape(r.at("source").get<std::string>()),
                     r.at("temperature_c").is_null() ? std::string("")
                                                     : fmt::format("{:g}", r.at("temperature_c").get<double>()),
                     values, cls(v.at("class_N")), cls(v.at("class_B")), cls(v.at("class")), probability(v),
                     o ? fmt::format("{}", o->value("count", std::size_t{0})) : std::string(),
                     o ? csv_escape(o->value("action", std::string())) : std::string());
  }
  const auto& ov = summary.at("overall");
  s += fmt::format("overall,,,,,,,,,,,,{},{},{},{},,\n", cls(ov.at("class_N")), cls(ov.at("class_B")),
                   cls(ov.at("class")), probability(ov));
  return s;
}

}  // namespace rwcalc
