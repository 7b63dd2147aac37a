// Reading: parse the text of a 2-h 400 Hz GL-2D pulse file already in memory (the floor of
// `rwcalc analyze` is reading and parsing ~6 MB), the same read from a file, and the cumulative
// sums it ends with; the short decimals of IMU text read by read_decimal against std::from_chars.
#include <benchmark/benchmark.h>

#include <charconv>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "bench_inputs.hpp"
#include "io/decimal.hpp"
#include "rwcalc/reader.hpp"

namespace {

using namespace rwcalc;

void BM_ParsePulseFile2h(benchmark::State& state) {
  const std::string& text = bench::gl2d_text();
  for (auto _ : state) {
    auto rec = read_recording_text(text, "gl2d.csv");
    benchmark::DoNotOptimize(rec.phase.points());
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(text.size()));
  state.SetItemsProcessed(state.iterations() * 2'880'000);
}
BENCHMARK(BM_ParsePulseFile2h)->Unit(benchmark::kMillisecond)->UseRealTime();

// The same text read from a file (page cache), in pieces, parsed as above. What `rwcalc analyze` does before its
// analysis.
class PulseFileOnDisk {
 public:
  PulseFileOnDisk() : path_(std::filesystem::temp_directory_path() / "rwcalc_bench_gl2d_p50C.csv") {
    std::ofstream(path_, std::ios::binary) << bench::gl2d_text();
  }
  ~PulseFileOnDisk() {
    std::error_code ec;
    std::filesystem::remove(path_, ec);
  }
  PulseFileOnDisk(const PulseFileOnDisk&) = delete;
  PulseFileOnDisk& operator=(const PulseFileOnDisk&) = delete;
  [[nodiscard]] std::string path() const { return path_.string(); }

 private:
  std::filesystem::path path_;
};

void BM_ReadPulseFile2h(benchmark::State& state) {
  static const PulseFileOnDisk file;
  for (auto _ : state) {
    auto rec = read_recording(file.path());
    benchmark::DoNotOptimize(rec.phase.points());
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(bench::gl2d_text().size()));
  state.SetItemsProcessed(state.iterations() * 2'880'000);
}
BENCHMARK(BM_ReadPulseFile2h)->Unit(benchmark::kMillisecond)->UseRealTime();

// Cumulative sum of int64 increments into counts (wrap-around arithmetic, as PhaseSeries keeps them).
void BM_CumulativeSum2h(benchmark::State& state) {
  const auto inc = pulse_increments(bench::gl2d_series());
  std::vector<std::int64_t> c(inc.size() + 1);
  for (auto _ : state) {
    c[0] = 0;
    std::uint64_t acc = 0;
    for (std::size_t k = 0; k < inc.size(); ++k) {
      acc += static_cast<std::uint64_t>(inc[k]);
      c[k + 1] = static_cast<std::int64_t>(acc);
    }
    benchmark::DoNotOptimize(c.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(inc.size()));
}
BENCHMARK(BM_CumulativeSum2h)->Unit(benchmark::kMillisecond);

// Exact prefix sums of the counts in double (what MVAR's moving sums need), for comparison.
void BM_PrefixSumOfCounts2h(benchmark::State& state) {
  const auto& c = bench::gl2d_series().counts;
  std::vector<double> s(c.size() + 1);
  for (auto _ : state) {
    s[0] = 0;
    double acc = 0;
    for (std::size_t k = 0; k < c.size(); ++k) s[k + 1] = acc += static_cast<double>(c[k]);
    benchmark::DoNotOptimize(s.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(c.size()));
}
BENCHMARK(BM_PrefixSumOfCounts2h)->Unit(benchmark::kMillisecond);

// One million fields as the ADIS16405 IMU text holds them (gyro "-0.35", accelerometer
// "-1.01565"), each ended by a comma.
const std::string& imu_fields() {
  static const std::string text = [] {
    std::mt19937_64 rng(3);
    std::string t;
    for (int i = 0; i < 1'000'000; ++i)
      t += i % 2 ? fmt::format("-{}.{:05d},", rng() % 2, rng() % 100000)
                 : fmt::format("{}.{},", rng() % 3, rng() % 20 * 5);
    return t;
  }();
  return text;
}

template <class Read>
void read_fields(benchmark::State& state, const Read& read) {
  const std::string& t = imu_fields();
  for (auto _ : state) {
    double sum = 0;
    for (const char* p = t.data(); p < t.data() + t.size();) {
      double v = 0;
      p = read(p, t.data() + t.size(), v).ptr + 1;
      sum += v;
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * 1'000'000);
}

// The stage the reader's bulk reading of decimal columns spends most of its time in.
void BM_ReadDecimalImuFields(benchmark::State& state) {
  read_fields(state, [](const char* p, const char* e, double& v) { return rwcalc::detail::read_decimal(p, e, v); });
}
BENCHMARK(BM_ReadDecimalImuFields)->Unit(benchmark::kMillisecond);

void BM_FromCharsImuFields(benchmark::State& state) {
  read_fields(state, [](const char* p, const char* e, double& v) { return std::from_chars(p, e, v); });
}
BENCHMARK(BM_FromCharsImuFields)->Unit(benchmark::kMillisecond);

}  // namespace
