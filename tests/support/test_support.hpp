#pragma once
// Helpers shared by the test binaries: locating reference data, running the CLI, temp files.
#include <gtest/gtest.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "rwcalc/simulate.hpp"

namespace rwcalc {
struct Recording;   // rwcalc/reader.hpp
struct ClassTable;  // rwcalc/verdict.hpp
}  // namespace rwcalc

namespace rwcalc::test {

/// Path of a file under ../shared/data (the read-only reference material).
std::filesystem::path shared_data(const std::string& relative);

/// Path of a file under the source tree (e.g. "data/gl2d/...").
std::filesystem::path source_path(const std::string& relative);

/// Skip the current test with a clear message when the shared reference file is absent.
#define RWCALC_REQUIRE_SHARED(path)                                            \
  do {                                                                         \
    if (!std::filesystem::exists(path))                                        \
      GTEST_SKIP() << "reference data not found: " << (path)                   \
                   << " (the ../shared folder beside the checkout is absent)"; \
  } while (0)

struct CliResult {
  int status = -1;
  std::string out;
  std::string err;
};

/// Run `rwcalc ARGS…` in-process through rwcalc::cli::run.
CliResult run_cli(const std::vector<std::string>& args);

/// Run the built executable as a separate process (argv[0] = rwcalc), optionally feeding stdin.
CliResult run_exe(const std::vector<std::string>& args, const std::string& stdin_text = {});

/// Run the built executable with standard output redirected by the shell as `redirection` says,
/// e.g. ">/dev/full" or ">&-" (closed); `out` is then empty.
CliResult run_exe_stdout(const std::vector<std::string>& args, const std::string& redirection);

/// Run the built executable with its standard error (and input) on a pseudo-terminal, as in an
/// interactive shell, through util-linux `script`: `err` is what the terminal received (progress
/// lines and messages, line ends as CR LF), `out` the standard output, which goes to a file.
CliResult run_exe_on_terminal(const std::vector<std::string>& args);

/// A fresh temporary directory removed when the object goes out of scope.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  /// Write a file inside the directory and return its path.
  std::filesystem::path write(const std::string& name, const std::string& content) const;

 private:
  std::filesystem::path path_;
};

/// The whole content of a file (empty when it cannot be read).
std::string slurp(const std::filesystem::path& path);

/// The decompressed content of a gzip file (empty when it cannot be opened).
std::string gunzip(const std::filesystem::path& path);

/// The five shipped GL-2D runs (data/gl2d/), in temperature order −50 … +50 °C.
std::vector<std::string> gl2d_runs();

/// `a` followed by `b`: argument lists put together.
std::vector<std::string> concat(std::vector<std::string> a, const std::vector<std::string>& b);

/// The same record as a floating angle x_i − x_0 (the domain of the line and low-pass detectors);
/// a record that is already floating is returned as it is.
PhaseSeries floating_angle(const PhaseSeries& x);

/// A GL-2D-like record of the coverage tests: ARW n (°/√h), flicker b (°/h), the white read-out
/// unless another is given, the vertical Earth rate at 55.75°, simulated with `settings` (its seed,
/// length, rate, pulse weight).
Recording simulated_gyro(double n, double b, const SimulationSettings& settings,
                         ReadoutMode readout = ReadoutMode::White);

/// The class a gyro with these true B and N belongs to (none: beyond the table).
std::optional<int> true_class(double b, double n, const ClassTable& table);

/// Sets (or, with a null value, unsets) an environment variable for the lifetime of the object,
/// then restores it.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const char* value);
  ~ScopedEnv();
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

 private:
  std::string name_;
  std::optional<std::string> old_;
};

/// A GL-2D-like gyro (the +50 °C run of Table 1: N 0.00098 °/√h, B 0.0081 °/h, the Moscow vertical
/// Earth rate, white read-out) for tests that need a realistic record.
NoiseModel gl2d_model();

/// An hour of gl2d_model() at 400 Hz from the ensemble path, seeded by `seed` (source "sim").
Recording gl2d_hour(std::uint64_t seed);

}  // namespace rwcalc::test
