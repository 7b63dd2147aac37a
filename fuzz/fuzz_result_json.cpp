// libFuzzer target: the readers of rwcalc's own JSON results (what `report` and `merge` read back,
// and class tables), then the code that consumes what they accept.
//
// Input layout: 1 option byte, then the file bytes.
//   byte 0 % 4: 0 a saved result (analyze, batch or diagnose --json) as `report` loads it, then
//               the report's HTML (no figures), the figures' scripts and the combined verdict;
//               1 JSON lines as `report` reads them; 2 JSON lines as `merge` reads them, then the
//               merge (bit 2 of byte 0: --dedupe) and every table format; 3 a class table.
//
// The contract checked: a reader returns or throws rwcalc::InputError / UsageError, nothing else
// (no nlohmann exception, no crash); what it accepts, the consumers handle without any exception
// but InputError (and AnalysisError where a figure has nothing to draw).
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

#include "rwcalc/batch.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/plot.hpp"
#include "rwcalc/report.hpp"
#include "rwcalc/saved_results.hpp"
#include "rwcalc/verdict.hpp"

namespace {

[[noreturn]] void broken(const char* what) {
  std::fprintf(stderr, "fuzz_result_json: contract broken: %s\n", what);
  std::abort();
}

/// Runs `f`; an rwcalc input or analysis error is an accepted outcome, anything else aborts.
template <class F>
void consume(F&& f, const char* what) {
  try {
    f();
  } catch (const rwcalc::InputError&) {
  } catch (const rwcalc::AnalysisError&) {
  } catch (...) {
    broken(what);
  }
}

void use_saved(const rwcalc::SavedResults& saved) {
  rwcalc::ReportInput in;
  for (const auto& a : saved.analyses) in.analyses.push_back(a.run);
  for (const auto& d : saved.diagnoses) in.diagnoses.push_back(d.run);
  if (!saved.overalls.empty()) in.overall = saved.overalls.front();
  rwcalc::ReportOptions ro;
  ro.figures = false;
  if (!in.analyses.empty()) {
    consume([&] { (void)rwcalc::report_html(in, ro); }, "report_html threw");
    consume([&] { (void)rwcalc::summarize_runs(in.analyses, "report"); }, "summarize_runs (report) threw");
    consume([&] { (void)rwcalc::analysis_figure(in.analyses.front(), rwcalc::PlotOptions{}); },
            "analysis_figure threw");
    consume([&] { (void)rwcalc::batch_allan_figure(nlohmann::json(in.analyses), rwcalc::PlotOptions{}); },
            "batch_allan_figure threw");
    consume([&] { (void)rwcalc::batch_direct_figure(nlohmann::json(in.analyses), rwcalc::PlotOptions{}); },
            "batch_direct_figure threw");
  }
  for (const auto& d : saved.diagnoses)
    consume([&] { (void)rwcalc::diagnosis_figure(d.run, rwcalc::PlotOptions{}); }, "diagnosis_figure threw");
}

void use_merged(std::vector<rwcalc::SavedRun> lines, bool dedupe) {
  std::vector<nlohmann::json> runs;
  try {
    runs = rwcalc::merge_runs(std::move(lines), dedupe);
  } catch (const rwcalc::InputError&) {
    return;
  } catch (const rwcalc::UsageError&) {
    return;
  } catch (...) {
    broken("merge_runs threw something else than InputError/UsageError");
  }
  nlohmann::json summary;
  try {
    summary = rwcalc::summarize_runs(std::move(runs), "merge");
  } catch (...) {
    broken("summarize_runs threw on runs that merge accepted");
  }
  try {
    (void)rwcalc::format_batch_text(summary);
    (void)rwcalc::format_batch_markdown(summary);
    (void)rwcalc::format_batch_csv(summary);
    (void)summary.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
  } catch (...) {
    broken("a batch table threw on runs that merge accepted");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::uint8_t mode = data[0];
  const std::string_view body(reinterpret_cast<const char*>(data + 1), size - 1);
  try {
    switch (mode % 4) {
      case 0: {
        rwcalc::SavedResults saved;
        rwcalc::parse_saved_result(body, "fuzz.json", saved);
        use_saved(saved);
        break;
      }
      case 1: {
        rwcalc::SavedResults saved;
        for (auto& r : rwcalc::parse_json_lines(body, "fuzz.jsonl", rwcalc::RunKeys::Shown))
          saved.analyses.push_back(std::move(r));
        use_saved(saved);
        break;
      }
      case 2:
        use_merged(rwcalc::parse_json_lines(body, "fuzz.jsonl", rwcalc::RunKeys::Combined), (mode & 4) != 0);
        break;
      default: {
        const auto table = rwcalc::ClassTable::parse(body, "fuzz-limits.json");
        if (table.classes.empty()) broken("an empty class table accepted");
        break;
      }
    }
  } catch (const rwcalc::InputError&) {
    return 0;
  } catch (const rwcalc::UsageError&) {
    return 0;
  } catch (...) {
    broken("a reader threw something else than InputError/UsageError");
  }
  return 0;
}
