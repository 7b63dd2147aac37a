// Every numeric option of every command refuses values the computation cannot carry (NaN,
// infinities, numbers beyond a double, magnitudes far outside the option's range) with exit 2
// and a message naming the option; no command crashes or prints a non-finite number. The options
// are enumerated from the command line itself, so a new numeric option without a check fails here.
#include <CLI/CLI.hpp>
#include <cmath>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <filesystem>

#include "cli/commands.hpp"
#include "cli/numeric_options.hpp"
#include "rwcalc/cli.hpp"
#include "test_support.hpp"

namespace {

using rwcalc::test::CliResult;
using rwcalc::test::run_exe;
using rwcalc::test::TempDir;

struct NumericOption {
  std::string command;
  std::string name;  ///< the long name, e.g. "--block"
  std::string type;  ///< CLI11's type name: FLOAT, INT, UINT
};

/// The numeric options of every command, read from the CLI11 app the command line builds.
std::vector<NumericOption> numeric_options() {
  CLI::App app;
  rwcalc::cli::Runner runner;
  for (auto* add : {rwcalc::cli::register_allan, rwcalc::cli::register_analyze, rwcalc::cli::register_batch,
                    rwcalc::cli::register_merge, rwcalc::cli::register_simulate, rwcalc::cli::register_diagnose,
                    rwcalc::cli::register_report})
    add(app, runner);
  std::vector<NumericOption> found;
  for (const CLI::App* sub : app.get_subcommands({})) {
    for (const CLI::Option* opt : sub->get_options()) {
      const std::string type = opt->get_type_name();
      if (opt->get_expected_min() == 0 || opt->get_lnames().empty()) continue;  // flags, positionals
      if (type.find("FLOAT") == std::string::npos && type.find("INT") == std::string::npos) continue;
      found.push_back({sub->get_name(), "--" + opt->get_lnames().front(), type});
    }
  }
  return found;
}

/// The arguments that make a command otherwise complete (its parse then fails on the option only).
std::vector<std::string> base_args(const std::string& command) {
  if (command == "simulate") return {"simulate", "-o", "never-written.csv"};
  if (command == "report") return {"report", "in.csv", "-o", "never-written"};
  return {command, "in.csv"};
}

int parse(const std::vector<std::string>& args, std::string& err) {
  std::vector<const char*> argv{"rwcalc"};
  for (const auto& a : args) argv.push_back(a.c_str());
  std::ostringstream out, errs;
  const int status = rwcalc::cli::parse_only(static_cast<int>(argv.size()), argv.data(), out, errs);
  err = errs.str();
  return status;
}

TEST(NumericOptions, TheCommandLineHasNumericOptions) {
  // The walk below must see the options it is meant to check (a guard against an empty walk).
  std::set<std::string> names;
  for (const auto& o : numeric_options()) names.insert(o.command + " " + o.name);
  for (const char* expected :
       {"analyze --block", "analyze --rate", "analyze --earth-rate", "allan --confidence", "simulate --bias",
        "simulate --seed", "diagnose --seed", "batch --temperature", "report --diagnose-runs", "analyze --temperature"})
    EXPECT_TRUE(names.count(expected)) << expected;
}

TEST(NumericOptions, EveryNumericOptionHasACheck) {
  for (const auto& o : numeric_options()) {
    CLI::App a;
    rwcalc::cli::Runner r;
    // Rebuild the command alone and look its option up there.
    for (auto* add : {rwcalc::cli::register_allan, rwcalc::cli::register_analyze, rwcalc::cli::register_batch,
                      rwcalc::cli::register_merge, rwcalc::cli::register_simulate, rwcalc::cli::register_diagnose,
                      rwcalc::cli::register_report})
      add(a, r);
    const CLI::Option* opt = a.get_subcommand(o.command)->get_option(o.name);
    EXPECT_NO_THROW((void)const_cast<CLI::Option*>(opt)->get_validator(rwcalc::cli::kNumberCheck))
        << o.command << " " << o.name << " has no finite-range check";
  }
}

TEST(NumericOptions, EveryNumericOptionRefusesNonFiniteAndHugeValues) {
  const std::vector<std::string> always_bad = {"nan",    "NaN",   "inf",    "-inf", "1e400",
                                               "-1e400", "1e300", "-1e300", "abc"};
  for (const auto& o : numeric_options()) {
    std::vector<std::string> bad = always_bad;
    if (o.type.find("INT") != std::string::npos) bad.insert(bad.end(), {"1.5", "1e3"});
    if (o.type.find("UINT") != std::string::npos) bad.push_back("-1");
    for (const auto& v : bad) {
      std::string err;
      const int status = parse(rwcalc::test::concat(base_args(o.command), {o.name + "=" + v}), err);
      EXPECT_EQ(status, 2) << o.command << " " << o.name << "=" << v;
      EXPECT_NE(err.find(o.name), std::string::npos) << o.command << " " << o.name << "=" << v << ": " << err;
    }
  }
}

// Values inside the double range but outside what an option means: each named option refuses them.
TEST(NumericOptions, OptionsRefuseValuesOutsideTheirMeaning) {
  const std::map<std::string, std::vector<std::string>> bad = {
      {"--rate", {"0", "-1", "1e-300", "1e-10", "1e10"}},
      {"--scale", {"0", "-1", "1e-300", "1e10"}},
      {"--block", {"0", "-1", "1e17"}},
      {"--min-edf", {"0", "-1"}},
      {"--latitude", {"-91", "90.5"}},
      {"--earth-rate", {"1e17"}},
      {"--tolerance", {"-1", "1001"}},
      {"--outlier-threshold", {"0", "1e-9", "2.9"}},
      {"--time-tolerance", {"-1", "0.6"}},
      {"--counter-bits", {"0", "65", "-1"}},
      {"--temperature", {"-300", "1e4"}},
      {"--confidence", {"0", "1", "-1", "1.5"}},
      {"--false-alarm", {"0", "-1", "0.5"}},
      {"--seed", {"-1"}},
      {"--runs", {"0", "-1"}},
      {"--duration", {"0", "-1", "1e17"}},
      {"--arw", {"-1"}},
      {"--bias-instability", {"-1"}},
      {"--rrw", {"-1"}},
      {"--white-angle", {"-1"}},
      {"--lowpass", {"-1"}},
      {"--output-lowpass", {"-1"}},
      {"--diagnose-runs", {"0", "9"}},
  };
  std::set<std::string> covered;
  for (const auto& o : numeric_options()) {
    const auto it = bad.find(o.name);
    if (it == bad.end()) continue;
    covered.insert(o.name);
    for (const auto& v : it->second) {
      std::string err;
      const int status = parse(rwcalc::test::concat(base_args(o.command), {o.name + "=" + v}), err);
      EXPECT_EQ(status, 2) << o.command << " " << o.name << "=" << v;
      EXPECT_NE(err.find(o.name), std::string::npos) << o.command << " " << o.name << "=" << v << ": " << err;
    }
  }
  for (const auto& [name, values] : bad) EXPECT_TRUE(covered.count(name)) << name << " is no option of any command";
}

// --- End to end: the reproducers, through the executable -------------------------------------

/// A 60-s pulse record from `rwcalc simulate` in `dir`.
std::string pulse_record(const TempDir& dir) {
  const std::string path = (dir.path() / "p.csv").string();
  const CliResult r = run_exe(
      {"simulate", "-o", path, "--duration", "120", "--arw", "0.001", "--bias-instability", "0.01", "--white-readout"});
  EXPECT_EQ(r.status, 0) << r.err;
  return path;
}

/// "inf", "nan", "-nan", "inf.0", "Infinity"… as a word of their own ("edf_inflation" is none).
bool has_non_finite(const std::string& text) {
  static const std::regex word("(^|[^A-Za-z_])(inf|infinity|nan)([^A-Za-z_]|$)", std::regex::icase);
  return std::regex_search(text, word);
}

TEST(NumericOptionsExe, HugeBlockIsRefusedNotACrash) {
  TempDir dir;
  const std::string p = pulse_record(dir);
  for (const char* cmd : {"analyze", "batch"}) {
    const CliResult r = run_exe({cmd, p, "--block", "1e17"});
    EXPECT_EQ(r.status, 2) << cmd << ": " << r.err;
    EXPECT_NE(r.err.find("--block"), std::string::npos) << r.err;
  }
  // The largest accepted block is longer than the record: no blocks, a result, no crash.
  const CliResult r = run_exe({"analyze", p, "--block", "1e9", "--json"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(has_non_finite(r.out));
}

TEST(NumericOptionsExe, AllanNeverPrintsNonFiniteNumbers) {
  TempDir dir;
  const std::string p = pulse_record(dir);
  for (const char* fmt : {"--json", "--csv", "--tau=octave"}) {
    const CliResult r = run_exe({"allan", p, fmt, "--rate", "1e300"});
    EXPECT_EQ(r.status, 2) << fmt << ": " << r.err;
    EXPECT_NE(r.err.find("--rate"), std::string::npos) << r.err;
    EXPECT_FALSE(has_non_finite(r.out)) << r.out;
  }
  // The extreme accepted scales still give finite numbers everywhere.
  for (const auto& extra : {std::vector<std::string>{"--rate", "1e9", "--scale", "1e9"},
                            std::vector<std::string>{"--rate", "1e-9", "--scale", "1e-9"}}) {
    for (const char* fmt : {"--json", "--csv"}) {
      const CliResult r = run_exe(rwcalc::test::concat({"allan", p, fmt}, extra));
      EXPECT_EQ(r.status, 0) << r.err;
      EXPECT_FALSE(has_non_finite(r.out)) << r.out.substr(0, 400);
    }
  }
}

TEST(NumericOptionsExe, SimulateRefusesMagnitudesTheCountsCannotCarry) {
  TempDir dir;
  const std::string out = (dir.path() / "s.csv").string();
  // Within each option's range, but the record's angle would exceed the pulse counts' range.
  for (const auto& extra :
       {std::vector<std::string>{"--bias", "1e9", "--duration", "1e7", "--rate", "1", "--scale", "1e-3"},
        std::vector<std::string>{"--arw", "1e9", "--duration", "1e6", "--rate", "1", "--scale", "1e-9"},
        std::vector<std::string>{"--bias", "1e6", "--scale", "1e-9", "--duration", "1e5", "--rate", "1"},
        std::vector<std::string>{"--ramp", "1e9", "--duration", "3e6", "--rate", "1"},
        std::vector<std::string>{"--sinusoid", "1:1e300"}, std::vector<std::string>{"--bias-step", "1e300:1"}}) {
    const CliResult r = run_exe(rwcalc::test::concat({"simulate", "-o", out}, extra));
    EXPECT_EQ(r.status, 2) << extra[0] << ": " << r.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << extra[0] << " wrote a record";
    std::filesystem::remove(out);
    EXPECT_TRUE(r.err.find("pulses") != std::string::npos || r.err.find(extra[0]) != std::string::npos) << r.err;
  }
  for (const auto& extra : {std::vector<std::string>{"--bias", "1e300"}, std::vector<std::string>{"--arw", "1e300"},
                            std::vector<std::string>{"--scale", "1e-300"}}) {
    const CliResult r = run_exe(rwcalc::test::concat({"simulate", "-o", out}, extra));
    EXPECT_EQ(r.status, 2) << extra[0] << ": " << r.err;
    EXPECT_NE(r.err.find(extra[0]), std::string::npos) << r.err;
  }
}

TEST(NumericOptionsExe, NonsenseScalesAreInputErrors) {
  TempDir dir;
  const std::string p = pulse_record(dir);
  for (const auto& extra :
       {std::vector<std::string>{"--rate", "1e300"}, std::vector<std::string>{"--rate", "1e-300"},
        std::vector<std::string>{"--scale", "1e300"}, std::vector<std::string>{"--scale", "1e-300"}}) {
    const CliResult r = run_exe(rwcalc::test::concat({"analyze", p}, extra));
    EXPECT_EQ(r.status, 2) << extra[0] << " " << extra[1] << ": " << r.err;
    EXPECT_NE(r.err.find(extra[0]), std::string::npos) << r.err;
  }
  // Data of size 1e-300: refused as input naming the data, not analysed as a noiseless record.
  std::string angle = "angle\n";
  std::string rate = "rate\n";
  for (int i = 0; i < 4000; ++i) {
    angle += fmt::format("{:g}\n", 1e-300 * std::sin(0.7 * i) * (1 + i % 7));
    rate += fmt::format("{:g}\n", 1e-300 * std::cos(1.3 * i) * (1 + i % 5));
  }
  const auto a = dir.write("tiny_angle.csv", angle);
  const auto r1 = run_exe({"analyze", a.string(), "--input", "angle", "--rate", "400"});
  EXPECT_EQ(r1.status, 2) << r1.err;
  EXPECT_NE(r1.err.find("too small"), std::string::npos) << r1.err;
  const auto y = dir.write("tiny_rate.csv", rate);
  const auto r2 = run_exe({"allan", y.string(), "--input", "rate", "--rate", "400"});
  EXPECT_EQ(r2.status, 2) << r2.err;
  EXPECT_NE(r2.err.find("too small"), std::string::npos) << r2.err;
  // Metadata with a nonsense rate or scale is refused too, naming the key and the line.
  const auto m = dir.write("meta.csv", "# rate_hz: 1e300\npulses\n1\n2\n1\n3\n");
  const auto r3 = run_exe({"analyze", m.string()});
  EXPECT_EQ(r3.status, 2) << r3.err;
  EXPECT_NE(r3.err.find("rate_hz"), std::string::npos) << r3.err;
}

/// A rate record (deg/h at 100 Hz) of white noise with a spike on every `spike_every`-th sample.
std::string spiky_rate_record(int samples, int spike_every) {
  std::string text = "# rate_hz: 100\nrate\n";
  std::uint64_t s = 99;
  for (int i = 0; i < samples; ++i) {
    double sum = 0;
    for (int k = 0; k < 12; ++k) {  // near-Gaussian: a sum of 12 uniforms
      s = s * 6364136223846793005ULL + 1442695040888963407ULL;
      sum += static_cast<double>(s >> 11) / 9007199254740992.0;
    }
    text += fmt::format("{:.9g}\n", 10.0 + (sum - 6.0) + (i % spike_every == 5 ? 500.0 : 0.0));
  }
  return text;
}

TEST(NumericOptionsExe, OutlierRewriteOfMoreThanOnePercentIsRefused) {
  TempDir dir;
  const std::string p = pulse_record(dir);
  const CliResult tiny = run_exe({"analyze", p, "--outliers", "remove", "--outlier-threshold", "1e-9"});
  EXPECT_EQ(tiny.status, 2) << tiny.err;
  EXPECT_NE(tiny.err.find("--outlier-threshold"), std::string::npos) << tiny.err;
  // Spikes on 2 % of the samples: refused with the share and the hint, for both actions; kept
  // outliers are only reported.
  const auto many = dir.write("many.csv", spiky_rate_record(200000, 50));
  for (const std::string action : {"remove", "replace"}) {
    const CliResult r = run_exe({"analyze", many.string(), "--input", "rate", "--outliers", action});
    EXPECT_EQ(r.status, 2) << action << ": " << r.err;
    EXPECT_NE(r.err.find("2 %"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("--outlier-threshold"), std::string::npos) << r.err;
  }
  const CliResult kept = run_exe({"analyze", many.string(), "--input", "rate", "--json"});
  EXPECT_EQ(kept.status, 0) << kept.err;
  // Spikes on 0.5 % of the samples are removed as before.
  const auto few = dir.write("few.csv", spiky_rate_record(200000, 200));
  const CliResult r = run_exe({"analyze", few.string(), "--input", "rate", "--outliers", "remove", "--json"});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("\"removed\": 1000"), std::string::npos);
}

/// sigma(tau0) from `rwcalc allan --csv` (the first data row's deviation).
double first_deviation(const std::string& csv) {
  std::istringstream in(csv);
  std::string line;
  std::getline(in, line);  // header
  std::getline(in, line);
  std::vector<std::string> cells;
  std::stringstream ss(line);
  for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
  return cells.size() > 6 ? std::stod(cells[6]) : NAN;  // dev_deg_h
}

TEST(NumericOptionsExe, RateOffsetTenToTheTwelveTimesTheNoiseKeepsSigmaTau0) {
  TempDir dir;
  std::string plain = "rate\n", offset = "rate\n";
  std::uint64_t s = 12345;
  const int n = 200000;
  for (int i = 0; i < n; ++i) {
    // A uniform noise of unit size, printed to 17 digits; the offset 10^12 times larger.
    s = s * 6364136223846793005ULL + 1442695040888963407ULL;
    const double noise = static_cast<double>(s >> 11) / 9007199254740992.0 - 0.5;
    plain += fmt::format("{:.17g}\n", noise);
    offset += fmt::format("{:.17g}\n", 1e12 + noise);
  }
  const auto a = dir.write("plain.csv", plain);
  const auto b = dir.write("offset.csv", offset);
  const CliResult ra = run_exe({"allan", a.string(), "--input", "rate", "--rate", "400", "--csv"});
  const CliResult rb = run_exe({"allan", b.string(), "--input", "rate", "--rate", "400", "--csv"});
  ASSERT_EQ(ra.status, 0) << ra.err;
  ASSERT_EQ(rb.status, 0) << rb.err;
  const double sa = first_deviation(ra.out), sb = first_deviation(rb.out);
  EXPECT_NEAR(sb / sa, 1.0, 1e-3) << sa << " vs " << sb;
  // The mean rate keeps the offset.
  const CliResult an = run_exe({"analyze", b.string(), "--input", "rate", "--json"});
  if (an.status == 0) {
    const auto at = an.out.find("\"mean_rate_deg_per_h\": ");
    ASSERT_NE(at, std::string::npos);
    EXPECT_NEAR(std::stod(an.out.substr(at + 23)), 1e12, 1.0);
  }
}

}  // namespace
