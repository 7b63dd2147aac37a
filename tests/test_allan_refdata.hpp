#pragma once
// Test-local loaders for the reference data under ../shared/data (Stable32 tables, NIST sets, the
// ADIS16405 IMU record): small, independent of the production reader, so the estimator tests
// check the engine alone.
#include <zlib.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "rwcalc/allan.hpp"
#include "rwcalc/series.hpp"

namespace rwcalc::test {

/// Whole file as text; transparently gunzips (zlib reads plain files as they are).
inline std::string read_text_gz(const std::filesystem::path& path) {
  gzFile f = gzopen(path.c_str(), "rb");
  if (!f) throw std::runtime_error("cannot open " + path.string());
  std::string text;
  char buf[1 << 16];
  int got = 0;
  while ((got = gzread(f, buf, sizeof buf)) > 0) text.append(buf, static_cast<std::size_t>(got));
  gzclose(f);
  return text;
}

/// Numbers of one column (0-based, split on commas/blanks) of every non-comment line; a first
/// non-numeric line (a header row) is skipped.
inline std::vector<double> load_column(const std::filesystem::path& path, std::size_t column = 0) {
  std::vector<double> v;
  std::istringstream in(read_text_gz(path));
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#' || line == "\r") continue;
    for (char& c : line)
      if (c == ',' || c == '\t' || c == ';') c = ' ';
    std::istringstream fields(line);
    std::string field;
    for (std::size_t i = 0; i <= column; ++i) fields >> field;
    char* end = nullptr;
    const double x = std::strtod(field.c_str(), &end);
    if (end == field.c_str()) {
      if (v.empty()) continue;  // header row
      throw std::runtime_error("non-numeric field '" + field + "' in " + path.string());
    }
    v.push_back(x);
  }
  return v;
}

/// A phase series from phase samples (clock data: deviations in input units per second).
inline PhaseSeries phase_series(std::vector<double> phase, double tau0 = 1.0) {
  PhaseSeries s;
  s.kind = PhaseKind::Clock;
  s.tau0_s = tau0;
  s.values = std::move(phase);
  return s;
}

/// A phase series from frequency/rate samples: x_0 = 0, x_j = τ0·Σ_{i<j} y_i (summed in long
/// double so the integration adds no visible rounding).
inline PhaseSeries frequency_series(const std::vector<double>& y, double tau0 = 1.0,
                                    PhaseKind kind = PhaseKind::Clock) {
  PhaseSeries s;
  s.kind = kind;
  s.tau0_s = tau0;
  s.values.resize(y.size() + 1);
  long double run = 0;
  s.values[0] = 0;
  for (std::size_t i = 0; i < y.size(); ++i) {
    run += static_cast<long double>(y[i]);
    s.values[i + 1] = static_cast<double>(run * tau0);
  }
  return s;
}

/// One row of a Stable32 result table.
struct Stable32Row {
  long af = 0;
  double tau = 0;
  long n = 0;
  int alpha = 0;
  double min_sigma = 0, sigma = 0, max_sigma = 0;
};

struct Stable32Table {
  bool frequency_data = false;  ///< "Frequency Data Points" in the header (else phase)
  std::string sigma_type;       ///< "Allan", "Overlapping Allan", "Modified Allan", …
  std::vector<Stable32Row> rows;
  [[nodiscard]] bool has_bounds() const {
    for (const auto& r : rows)
      if (r.min_sigma > 0) return true;
    return false;
  }
};

inline Stable32Table load_stable32(const std::filesystem::path& path) {
  Stable32Table t;
  std::istringstream in(read_text_gz(path));
  std::string line;
  while (std::getline(in, line)) {
    if (line.find("Frequency Data Points") != std::string::npos) t.frequency_data = true;
    if (const auto p = line.find("Sigma Type:"); p != std::string::npos) {
      t.sigma_type = line.substr(p + 12);
      while (!t.sigma_type.empty() && (t.sigma_type.back() == '\r' || t.sigma_type.back() == ' '))
        t.sigma_type.pop_back();
    }
    if (line.empty() || line[0] == '#') continue;
    std::istringstream f(line);
    Stable32Row r;
    if (f >> r.af >> r.tau >> r.n >> r.alpha >> r.min_sigma >> r.sigma >> r.max_sigma) t.rows.push_back(r);
  }
  return t;
}

inline Estimator estimator_of(const Stable32Table& t) {
  if (t.sigma_type == "Allan") return Estimator::NonOverlapping;
  if (t.sigma_type == "Overlapping Allan") return Estimator::Overlapping;
  if (t.sigma_type == "Modified Allan") return Estimator::Modified;
  if (t.sigma_type == "Overlapping Hadamard") return Estimator::OverlappingHadamard;
  if (t.sigma_type == "Hadamard") return Estimator::NonOverlappingHadamard;
  throw std::runtime_error("unexpected Stable32 sigma type '" + t.sigma_type + "'");
}

inline double rel_err(double got, double want) { return std::fabs(got - want) / std::fabs(want); }

}  // namespace rwcalc::test
