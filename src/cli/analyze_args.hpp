#pragma once
// Options shared by 'rwcalc analyze' and 'rwcalc batch': fit range and terms, cross-check
// settings, Earth rate, and the verdict's class table, B estimate and tolerance.
#include <CLI/CLI.hpp>
#include <optional>
#include <string>

#include "rwcalc/analysis.hpp"

namespace rwcalc::cli {

/// --outliers keep|remove|replace and --outlier-threshold, as every command that analyses a record
/// takes them (the action is applied by rwcalc::screen_outliers).
void add_outlier_options(CLI::App& app, std::string& action, double& threshold);

/// --temperature C, checked against the usable range; `help` says what it applies to.
CLI::Option* add_temperature_option(CLI::App& app, std::optional<double>& temperature, const std::string& help);

struct AnalyzeArgs {
  std::string fit_range;  ///< "TMIN:TMAX" (s; either side may be empty)
  double min_edf = 1.0;
  std::string terms = "QNBKR";
  bool keep_all_terms = false;
  std::string readout = "auto";  ///< --readout: auto, counter or white (FitOptions::readout)
  double latitude_deg = 55.75;
  std::optional<double> earth_rate;
  bool vertical = false;                         ///< --vertical: Earth rate and class verdict for any input
  const CLI::Option* latitude_option = nullptr;  ///< to tell a --latitude given from its default
  std::string b_estimate = "fit";
  double tolerance_pct = 0;
  std::string limits_file;
  double block_s = 100.0;
  std::string direct_range = "1:100";
  std::string tau = "octave";  ///< τ grid of the reported AV (the fit uses its octave points)
  std::string outliers = "keep";
  double outlier_threshold = kDefaultOutlierThreshold;
  void add_to(CLI::App& app);
  /// Throws UsageError on malformed values; InputError for a bad limits file.
  [[nodiscard]] AnalysisOptions options() const;
};

}  // namespace rwcalc::cli
