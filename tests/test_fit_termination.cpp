// How the fit's iterations ended (termination.hpp): a fit that converges says so in its result and
// its JSON and prints nothing about it; a fit held to fewer iterations than it needs reports the
// iteration limit in the result, the JSON, the text report and the HTML report.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "rwcalc/analysis.hpp"
#include "rwcalc/fit.hpp"
#include "rwcalc/report.hpp"
#include "rwcalc/simulate.hpp"
#include "rwcalc/termination.hpp"
#include "test_support.hpp"

namespace rwcalc {
namespace {

using nlohmann::json;

TEST(FitTermination, CombineKeepsTheWorseStatusAndAddsIterations) {
  using S = TerminationStatus;
  EXPECT_EQ(combine({S::Converged, 3}, {S::NoProgress, 4}).status, S::NoProgress);
  EXPECT_EQ(combine({S::IterationLimit, 3}, {S::NoProgress, 4}).status, S::IterationLimit);
  EXPECT_EQ(combine({S::Converged, 3}, {S::Converged, 4}).status, S::Converged);
  EXPECT_EQ(combine({S::Converged, 3}, {S::IterationLimit, 4}).iterations, 7);
  EXPECT_EQ(to_json(Termination{S::IterationLimit, 9}), (json{{"status", "iteration_limit"}, {"iterations", 9}}));
  EXPECT_EQ(to_string(S::NoProgress), "no_progress");
  EXPECT_EQ(to_string(S::Converged), "converged");
}

TEST(FitTermination, ConvergedFitSaysSoOnlyInItsData) {
  const AnalysisResult r = analyze(test::gl2d_hour(11), {});
  EXPECT_EQ(r.fit.termination.status, TerminationStatus::Converged);
  EXPECT_GT(r.fit.termination.iterations, 0);
  EXPECT_LT(r.fit.termination.iterations, 2 * FitOptions{}.max_iterations);
  for (const Term t : kAllTerms) {
    if (r.fit[t].enabled) {
      EXPECT_TRUE(r.fit[t].termination.converged()) << term_name(t);
    }
  }
  const json j = to_json(r);
  EXPECT_EQ(j.at("fit").at("termination").at("status"), "converged");
  EXPECT_EQ(j.at("fit").at("termination").at("iterations"), r.fit.termination.iterations);
  EXPECT_EQ(j.at("fit").at("N").at("termination").at("status"), "converged");
  const std::string text = format_report(r);
  EXPECT_EQ(text.find("did not converge"), std::string::npos) << text;
}

TEST(FitTermination, IterationLimitIsReportedEverywhere) {
  AnalysisOptions o;
  o.fit.max_iterations = 1;  // Fisher scoring from the data's start needs several
  const AnalysisResult r = analyze(test::gl2d_hour(11), o);
  EXPECT_EQ(r.fit.termination.status, TerminationStatus::IterationLimit);
  EXPECT_GE(r.fit.termination.iterations, 1);
  const json j = to_json(r);
  EXPECT_EQ(j.at("fit").at("termination").at("status"), "iteration_limit");
  bool warned = false;
  for (const auto& w : j.at("warnings")) warned = warned || w.at("code") == "fit_not_converged";
  EXPECT_TRUE(warned) << j.at("warnings").dump();
  const std::string text = format_report(r);
  EXPECT_NE(text.find("The noise-model fit did not converge: it took its most iterations"), std::string::npos) << text;
  ReportOptions ro;
  ro.figures = false;
  const std::string html = report_html(ReportInput{{j}, {}, nullptr}, ro);
  EXPECT_NE(html.find("The noise-model fit did not converge"), std::string::npos);
}

}  // namespace
}  // namespace rwcalc
