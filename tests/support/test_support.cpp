#include "test_support.hpp"

#include <zlib.h>

#include <fmt/format.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>

#include "rwcalc/cli.hpp"
#include "rwcalc/reader.hpp"
#include "rwcalc/verdict.hpp"

namespace rwcalc::test {

std::filesystem::path shared_data(const std::string& relative) {
  return std::filesystem::path(RWCALC_SHARED_DIR) / "data" / relative;
}

std::filesystem::path source_path(const std::string& relative) {
  return std::filesystem::path(RWCALC_SOURCE_DIR) / relative;
}

std::string slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string gunzip(const std::filesystem::path& path) {
  gzFile g = gzopen(path.c_str(), "rb");
  std::string out;
  if (g == nullptr) return out;
  char buf[65536];
  for (int n; (n = gzread(g, buf, sizeof buf)) > 0;) out.append(buf, static_cast<std::size_t>(n));
  gzclose(g);
  return out;
}

std::vector<std::string> gl2d_runs() {
  std::vector<std::string> f;
  for (const char* t : {"m50C", "m25C", "0C", "p25C", "p50C"})
    f.push_back(source_path(std::string("data/gl2d/gl2d_") + t + ".csv.gz").string());
  return f;
}

std::vector<std::string> concat(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

ScopedEnv::ScopedEnv(const char* name, const char* value) : name_(name) {
  if (const char* old = std::getenv(name)) old_ = old;
  if (value)
    ::setenv(name, value, 1);
  else
    ::unsetenv(name);
}

ScopedEnv::~ScopedEnv() {
  if (old_)
    ::setenv(name_.c_str(), old_->c_str(), 1);
  else
    ::unsetenv(name_.c_str());
}

CliResult run_cli(const std::vector<std::string>& args) {
  std::vector<const char*> argv{"rwcalc"};
  for (const auto& a : args) argv.push_back(a.c_str());
  std::ostringstream out, err;
  CliResult r;
  r.status = rwcalc::cli::run(static_cast<int>(argv.size()), argv.data(), out, err);
  r.out = out.str();
  r.err = err.str();
  return r;
}

namespace {
std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) {
    if (c == '\'')
      q += "'\\''";
    else
      q += c;
  }
  return q + "'";
}

CliResult run_exe_as(const std::vector<std::string>& args, const std::string& stdin_text,
                     const std::optional<std::string>& stdout_redirection) {
  TempDir tmp;
  auto in_path = tmp.write("stdin.txt", stdin_text);
  std::string cmd = shell_quote(RWCALC_EXE);
  for (const auto& a : args) cmd += " " + shell_quote(a);
  cmd += " <" + shell_quote(in_path.string()) + " " +
         stdout_redirection.value_or(">" + shell_quote((tmp.path() / "out").string())) + " 2>" +
         shell_quote((tmp.path() / "err").string());
  const int rc = std::system(cmd.c_str());
  CliResult r;
  r.status = WIFEXITED(rc) ? WEXITSTATUS(rc) : 128 + WTERMSIG(rc);
  r.out = slurp(tmp.path() / "out");
  r.err = slurp(tmp.path() / "err");
  return r;
}

}  // namespace

CliResult run_exe(const std::vector<std::string>& args, const std::string& stdin_text) {
  return run_exe_as(args, stdin_text, std::nullopt);
}

CliResult run_exe_stdout(const std::vector<std::string>& args, const std::string& redirection) {
  return run_exe_as(args, {}, redirection);
}

CliResult run_exe_on_terminal(const std::vector<std::string>& args) {
  TempDir tmp;
  std::string inner = shell_quote(RWCALC_EXE);
  for (const auto& a : args) inner += " " + shell_quote(a);
  inner += " >" + shell_quote((tmp.path() / "out").string());
  // -e: script exits with the command's status; /dev/null: no typescript file.
  const std::string cmd = "script -qec " + shell_quote(inner) + " /dev/null </dev/null >" +
                          shell_quote((tmp.path() / "terminal").string()) + " 2>&1";
  const int rc = std::system(cmd.c_str());
  CliResult r;
  r.status = WIFEXITED(rc) ? WEXITSTATUS(rc) : 128 + WTERMSIG(rc);
  r.out = slurp(tmp.path() / "out");
  r.err = slurp(tmp.path() / "terminal");
  return r;
}

TempDir::TempDir() {
  std::random_device rd;
  const auto base = std::filesystem::temp_directory_path();
  for (int attempt = 0; attempt < 100; ++attempt) {
    auto candidate = base / fmt::format("rwcalc-test-{:016x}", (static_cast<unsigned long long>(rd()) << 32) ^ rd());
    if (std::filesystem::create_directory(candidate)) {
      path_ = candidate;
      return;
    }
  }
  throw std::runtime_error("cannot create a temporary directory");
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

std::filesystem::path TempDir::write(const std::string& name, const std::string& content) const {
  auto p = path_ / name;
  std::ofstream out(p, std::ios::binary);
  out << content;
  return p;
}

NoiseModel gl2d_model() {
  NoiseModel m;
  m.arw_deg_per_sqrt_h = 0.00098;
  m.bias_instability_deg_per_h = 0.0081;
  m.earth_rate_deg_per_h = earth_rate_at(55.75);
  m.readout = ReadoutMode::White;
  return m;
}

Recording gl2d_hour(std::uint64_t seed) {
  SimulationSettings s;
  s.duration_s = 3600;
  s.rate_hz = 400;
  Recording rec;
  rec.source = "sim";
  rec.rate_hz = 400;
  Simulator(gl2d_model(), s, SimulationPath::Ensemble).run(seed, rec.phase);
  rec.samples = rec.phase.points() - 1;
  return rec;
}

Recording simulated_gyro(double n, double b, const SimulationSettings& settings, ReadoutMode readout) {
  NoiseModel m;
  m.arw_deg_per_sqrt_h = n;
  m.bias_instability_deg_per_h = b;
  m.readout = readout;
  m.earth_rate_deg_per_h = earth_rate_at(55.75);
  Recording rec;
  rec.source = "sim";
  rec.phase = simulate(m, settings);
  rec.rate_hz = settings.rate_hz;
  rec.samples = rec.phase.points() - 1;
  return rec;
}

std::optional<int> true_class(double b, double n, const ClassTable& table) {
  for (const auto& c : table.classes)
    if (b <= c.B_deg_per_h && n <= c.N_deg_per_sqrt_h) return c.cls;
  return std::nullopt;
}

PhaseSeries floating_angle(const PhaseSeries& x) {
  if (!x.exact()) return x;
  PhaseSeries f;
  f.tau0_s = x.tau0_s;
  f.kind = x.kind;
  f.values.resize(x.points());
  for (std::size_t i = 0; i < x.points(); ++i) f.values[i] = x.diff(i, 0);
  return f;
}

}  // namespace rwcalc::test
