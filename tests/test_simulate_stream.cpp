// `rwcalc simulate` writes its record block by block as it is generated (memory does not grow with
// the record), bit-identical to the in-memory generator, atomically, and never writes a record it
// cannot count (a pulse count beyond 64 bits, a non-finite angle).
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "rwcalc/error.hpp"
#include "rwcalc/output.hpp"
#include "rwcalc/pulse_writer.hpp"
#include "rwcalc/simulate.hpp"
#include "rwcalc/units.hpp"
#include "test_support.hpp"

namespace {

using namespace rwcalc;
using rwcalc::test::run_cli;
using rwcalc::test::run_exe;
using rwcalc::test::TempDir;
namespace fs = std::filesystem;

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif

// Every term of the simulator, so that each one's state is carried across the blocks.
NoiseModel all_terms() {
  NoiseModel m;
  m.arw_deg_per_sqrt_h = 0.01;
  m.bias_instability_deg_per_h = 0.05;
  m.rrw_deg_per_h_per_sqrt_h = 0.1;
  m.ramp_deg_per_h2 = 30.0;
  m.bias_deg_per_h = 20.0;
  m.earth_rate_deg_per_h = earth_rate_at(55.75);
  m.white_angle_arcsec = 0.3;
  m.sinusoids.push_back({3.0, 5.0, 0.4});
  m.gauss_markov.push_back({0.5, 2.0});
  m.bias_steps.push_back({1.0, 0.7});
  m.warmups.push_back({3.0, 0.5});
  m.lowpass_tc_s = 0.01;
  m.temperature_bias = TemperatureBias{0.02, {TemperatureProfile::Kind::Cycle, 0, 0, 2.0, 1.5}};
  return m;
}

SimulationSettings settings(double duration_s, std::uint64_t seed) {
  SimulationSettings s;
  s.duration_s = duration_s;
  s.seed = seed;
  return s;
}

std::string gunzip(const fs::path& p) {
  gzFile g = gzopen(p.c_str(), "rb");
  std::string out;
  char buf[4096];
  int n = 0;
  while ((n = gzread(g, buf, sizeof buf)) > 0) out.append(buf, static_cast<std::size_t>(n));
  gzclose(g);
  return out;
}

// The text of a written file (gunzipped for ".gz").
std::string text_of(const fs::path& p) { return p.extension() == ".gz" ? gunzip(p) : test::slurp(p); }

// The numbers after the header line `column` of a written record.
std::vector<std::string> data_lines(const std::string& text, const std::string& column) {
  const std::size_t head = text.find("\n" + column + "\n");
  std::vector<std::string> lines;
  if (head == std::string::npos) return lines;
  std::istringstream in(text.substr(head + column.size() + 2));
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// Everything stream() hands out, put together.
PhaseSeries streamed(Simulator& sim, std::uint64_t seed) {
  PhaseSeries p;
  p.counts.push_back(0);
  p.values.push_back(0.0);
  std::size_t next = 1;
  sim.stream(seed, [&](const RecordBlock& b) {
    EXPECT_EQ(b.first, next);
    EXPECT_LE(b.counts.size() + b.angles.size(), 256u);
    p.counts.insert(p.counts.end(), b.counts.begin(), b.counts.end());
    p.values.insert(p.values.end(), b.angles.begin(), b.angles.end());
    next += b.counts.size() + b.angles.size();
  });
  return p;
}

TEST(SimulateStream, BlocksAreTheRecordOfRunBitForBit) {
  for (const ReadoutMode readout : {ReadoutMode::Counting, ReadoutMode::White}) {
    NoiseModel m = all_terms();
    m.readout = readout;
    Simulator sim(m, settings(3.3, 11));  // 1320 samples: the last block is partial
    PhaseSeries whole;
    sim.run(11, whole);
    const PhaseSeries parts = streamed(sim, 11);
    EXPECT_EQ(parts.counts, whole.counts);
    EXPECT_EQ(parts.values.size(), 1u);
  }
  // With an output-chain low-pass the record is the filtered angle (two passes when streamed).
  NoiseModel m = all_terms();
  m.output_lowpass_tc_s = 0.05;
  Simulator sim(m, settings(3.3, 12));
  PhaseSeries whole;
  sim.run(12, whole);
  const PhaseSeries parts = streamed(sim, 12);
  EXPECT_EQ(parts.counts.size(), 1u);
  ASSERT_EQ(parts.values.size(), whole.values.size());
  EXPECT_EQ(parts.values, whole.values);
}

// A record written by the CLI reads back as the generator's record, count for count.
TEST(SimulateStream, WrittenRecordReadsBackAsTheGeneratorsRecord) {
  TempDir dir;
  for (const char* name : {"r.csv", "r.csv.gz"}) {
    const fs::path out = dir.path() / name;
    const auto r = run_exe({"simulate", "-o", out.string(), "--duration", "5", "--seed", "21", "--arw", "0.002",
                            "--bias-instability", "0.01", "--sinusoid", "1:0.5", "--white-readout"});
    ASSERT_EQ(r.status, 0) << r.err;
    NoiseModel m;
    m.arw_deg_per_sqrt_h = 0.002;
    m.bias_instability_deg_per_h = 0.01;
    m.sinusoids.push_back({1, 0.5, 0});
    m.readout = ReadoutMode::White;
    m.earth_rate_deg_per_h = earth_rate_at(units::moscow_latitude_deg);
    const PhaseSeries expected = simulate(m, settings(5, 21));
    const std::string text = text_of(out);
    EXPECT_NE(text.find("# rate_hz: 400\n"), std::string::npos);
    std::vector<std::int64_t> counts = {0};
    for (const auto& line : data_lines(text, "pulses")) counts.push_back(counts.back() + std::stoll(line));
    EXPECT_EQ(counts, expected.counts) << name;
    EXPECT_EQ(run_cli({"analyze", out.string()}).status, 0) << name;
  }
  // The filtered angle of an output-chain low-pass, to its 6 written decimals.
  const fs::path out = dir.path() / "angle.csv";
  const auto r = run_exe({"simulate", "-o", out.string(), "--duration", "5", "--seed", "22", "--arw", "0.01",
                          "--output-lowpass", "0.05", "--no-earth-rate"});
  ASSERT_EQ(r.status, 0) << r.err;
  NoiseModel m;
  m.arw_deg_per_sqrt_h = 0.01;
  m.output_lowpass_tc_s = 0.05;
  const PhaseSeries expected = simulate(m, settings(5, 22));
  const auto lines = data_lines(test::slurp(out), "angle");
  ASSERT_EQ(lines.size(), expected.values.size());
  for (std::size_t k = 0; k < lines.size(); ++k)
    ASSERT_EQ(lines[k], fmt::format("{:.6f}", expected.values[k])) << "sample " << k;
  EXPECT_EQ(run_cli({"analyze", "--input", "angle", out.string()}).status, 0);
}

// Run the built executable with its address space limited (setrlimit in the child before exec).
int run_exe_limited(const std::vector<std::string>& args, rlim_t address_space_bytes) {
  std::vector<std::string> argv_s = {RWCALC_EXE};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t pid = fork();
  if (pid == 0) {
    const rlimit limit{address_space_bytes, address_space_bytes};
    if (setrlimit(RLIMIT_AS, &limit) != 0) _exit(125);
    execv(argv[0], argv.data());
    _exit(126);
  }
  int status = 0;
  if (pid < 0 || waitpid(pid, &status, 0) != pid) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// A 2-h 1 kHz record (7.2 M samples) held whole in memory with its increments and text needs
// ~130 MB besides the program (~19 bytes a sample); written as it is generated it runs in 150 MB of
// address space, about 70 MB of which are the program, its libraries and its allocator's arenas.
TEST(SimulateStream, LongRecordIsWrittenInBoundedMemory) {
  if (kAddressSanitizer) GTEST_SKIP() << "AddressSanitizer reserves terabytes of address space";
  TempDir dir;
  const fs::path out = dir.path() / "long.csv.gz";
  const int status = run_exe_limited({"simulate", "-o", out.string(), "--duration", "7200", "--rate", "1000", "--arw",
                                      "0.001", "--white-readout"},
                                     150u << 20);
  ASSERT_EQ(status, 0);
  // The file is complete: every sample has its line after the header.
  const std::string text = gunzip(out);
  const std::size_t data = text.find("\npulses\n");
  ASSERT_NE(data, std::string::npos);
  EXPECT_EQ(std::count(text.begin() + static_cast<std::ptrdiff_t>(data + 8), text.end(), '\n'), 7200000);
}

// --- A record that cannot be counted is never written -----------------------------------------

TEST(SimulateStream, UncountableAngleIsAUsageErrorNamingTheSample) {
  NoiseModel m;
  m.bias_deg_per_h = 1e300;
  Simulator sim(m, settings(1, 1));
  PhaseSeries p;
  try {
    sim.run(1, p);
    FAIL() << "no error";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("sample 1 "), std::string::npos) << e.what();
  }
  EXPECT_THROW(sim.stream(1, [](const RecordBlock&) {}), UsageError);
  // A ramp leaves the range late in the record: the sample named is the first whose angle
  // 0.5·R·t² (R in ″/s²) is beyond 2^61 pulses of q = 0.92″ (k ≈ 1106 at 400 Hz).
  NoiseModel ramp;
  ramp.ramp_deg_per_h2 = 2e21;
  const double r_s = ramp.ramp_deg_per_h2 / 3600.0;
  std::size_t first_out = 1;
  while (0.5 * r_s * std::pow(static_cast<double>(first_out) / 400.0, 2) / 0.92 < kMaxSimulatedPulses) ++first_out;
  Simulator late(ramp, settings(10, 1));
  try {
    late.run(1, p);
    FAIL() << "no error";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find(fmt::format("sample {} ", first_out)), std::string::npos)
        << first_out << ": " << e.what();
  }
}

TEST(SimulateStream, CliRefusesAnUncountableRecordAndLeavesNoFile) {
  const std::vector<std::vector<std::string>> cases = {{"--bias", "1e300"},
                                                       {"--arw", "1e300"},
                                                       {"--scale", "1e-300"},
                                                       {"--ramp", "1e300"},
                                                       {"--white-angle", "1e300"},
                                                       {"--bias", "1e300", "--output-lowpass", "0.1"},
                                                       {"--bias", "1e300", "--runs", "2"},
                                                       {"--sinusoid", "1:1e300"}};
  for (const char* name : {"x.csv", "x.csv.gz"}) {
    for (const auto& opts : cases) {
      TempDir dir;
      auto args = test::concat({"simulate", "-o", (dir.path() / name).string(), "--duration", "10"}, opts);
      const auto r = run_exe(args);
      const std::string what = opts[0] + " " + opts[1] + " -> " + name;
      EXPECT_EQ(r.status, 2) << what << ": " << r.err;
      // Neither the file, nor a numbered run, nor a temporary file.
      EXPECT_TRUE(fs::is_empty(dir.path())) << what;
      // The message names where the record stops being countable, or the option at fault.
      EXPECT_TRUE(r.err.find("sample") != std::string::npos || r.err.find(opts[0]) != std::string::npos)
          << what << ": " << r.err;
    }
  }
}

TEST(SimulateStream, PulseWriterRefusesUnwritableValuesAndLeavesNoFile) {
  TempDir dir;
  const Metadata md = {{"rate_hz", "400"}};
  {
    const fs::path out = dir.path() / "wrap.csv";
    PulseFileWriter w(out.string(), md, PulseFileWriter::Column::Pulses, false);
    const std::vector<std::int64_t> counts = {5, std::numeric_limits<std::int64_t>::min()};
    try {
      w.add_counts(counts);
      FAIL() << "no error";
    } catch (const UsageError& e) {
      // The metadata line, the header, then sample 1 on line 3 and sample 2 on line 4.
      EXPECT_NE(std::string(e.what()).find("line 4 (sample 2)"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(out.string()), std::string::npos) << e.what();
    }
  }
  for (const double bad : {std::nan(""), HUGE_VAL, -HUGE_VAL}) {
    const fs::path out = dir.path() / "nan.csv.gz";
    PulseFileWriter w(out.string(), md, PulseFileWriter::Column::Angle, false);
    const std::vector<double> angles = {1.0, 2.0, bad};
    try {
      w.add_angles(angles);
      FAIL() << "no error for " << bad;
    } catch (const UsageError& e) {
      // Line 3 holds θ_0; θ_3 is on line 6.
      EXPECT_NE(std::string(e.what()).find("line 6 (sample 3)"), std::string::npos) << e.what();
    }
  }
  // The in-memory form refuses the same values.
  PhaseSeries floating;
  floating.values = {0.0, std::nan("")};
  EXPECT_THROW((void)format_pulse_file(md, floating), UsageError);
  EXPECT_TRUE(fs::is_empty(dir.path()));
}

std::size_t entries(const fs::path& dir) {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
  return n;
}

TEST(SimulateStream, AtomicOutputAppearsWholeOrNotAtAll) {
  TempDir dir;
  for (const char* name : {"a.txt", "a.txt.gz"}) {
    const fs::path out = dir.path() / name;
    const std::size_t before = entries(dir.path());
    auto content = [&] { return out.extension() == ".gz" ? gunzip(out) : test::slurp(out); };
    {
      AtomicOutput o(out.string(), false);
      o.write("first ");
      EXPECT_FALSE(fs::exists(out));
      EXPECT_EQ(entries(dir.path()), before + 1);  // the temporary file
    }                                              // abandoned: the temporary file goes with it
    EXPECT_EQ(entries(dir.path()), before);
    AtomicOutput o(out.string(), false);
    o.write("first ");
    o.write("second\n");
    o.commit();
    ASSERT_TRUE(fs::exists(out));
    EXPECT_THROW(AtomicOutput(out.string(), false), OutputError);  // exists, no --force
    AtomicOutput again(out.string(), true);
    again.write("third\n");
    EXPECT_EQ(content(), "first second\n");  // the old one until commit()
    again.commit();
    EXPECT_EQ(content(), "third\n");
    EXPECT_EQ(entries(dir.path()), before + 1);
  }
}

}  // namespace
