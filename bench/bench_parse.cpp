// Reading: parse the text of a 2-h 400 Hz GL-2D pulse file already in memory (the floor of
// `rwcalc analyze` is reading and parsing ~6 MB), with each kernel of the one-digit-line path and
// that kernel alone, the same read from a file, and the cumulative sums it ends with.
#include <benchmark/benchmark.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <vector>

#include "io/reader_detail.hpp"
#include "io/reader_simd.hpp"
#include "bench_inputs.hpp"
#include "rwcalc/reader.hpp"

namespace {

using namespace rwcalc;

// Argument: parse threads (1: serial; 2: the second half of the text on another thread).
void BM_ParsePulseFile2h(benchmark::State& state) {
  const std::string& text = bench::gl2d_text();
  ReadOptions o;
  o.threads = static_cast<unsigned>(state.range(0));
  for (auto _ : state) {
    auto rec = read_recording_text(text, "gl2d.csv", o);
    benchmark::DoNotOptimize(rec.phase.points());
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(text.size()));
  state.SetItemsProcessed(state.iterations() * 2'880'000);
}
BENCHMARK(BM_ParsePulseFile2h)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// Argument of the kernel cases: 0 the AVX-512 VBMI2 kernel (the portable one where it cannot run),
// 1 the portable kernel, 2 none (the per-line path of scan_int_line).
detail::DigitKernel kernel_arg(std::int64_t a) {
  return a == 0 ? detail::DigitKernel::Avx512 : a == 1 ? detail::DigitKernel::Portable : detail::DigitKernel::Off;
}

// The parse kernel alone on the data lines of the 2-h text (2.88 M lines, nearly all one digit):
// running sums and Σ|c| into a buffer whose pages are mapped once, one thread. With a kernel,
// digit_windows takes the windows and a line it leaves is taken by scan_int_line; without, every
// line is (the reader's path before the vectorised one, less its 64-byte line-end windows).
void BM_DigitWindows2h(benchmark::State& state) {
  const std::string& text = bench::gl2d_text();
  std::string padded = text + std::string(64, '\0');
  const char* begin = padded.data();  // the header lines skipped
  while (!detail::is_digit(*begin) && *begin != '-') begin = std::strchr(begin, '\n') + 1;
  const char* end = padded.data() + text.size();
  std::vector<std::int64_t> out(static_cast<std::size_t>(end - begin) / 2 + 64);
  const auto before = detail::set_digit_kernel(kernel_arg(state.range(0)));
  std::size_t lines = 0;
  for (auto _ : state) {
    std::uint64_t acc = 0, mag = 0;
    std::size_t k = 0;
    const char* p = begin;
    while (p < end) {
      std::size_t n = 0;
      p = detail::digit_windows<true>(p, end, out.data() + k, n, acc, mag);
      k += n;
      if (p >= end) break;
      std::int64_t v = 0;
      const char* next = detail::scan_int_line(p, v);
      if (next) {
        acc += static_cast<std::uint64_t>(v);
        mag += static_cast<std::uint64_t>(v < 0 ? -v : v);
        out[k++] = static_cast<std::int64_t>(acc);
      }
      p = next ? next : std::strchr(p, '\n') + 1;
    }
    lines = k;
    benchmark::DoNotOptimize(out.data());
    benchmark::DoNotOptimize(mag);
  }
  detail::set_digit_kernel(before);
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(end - begin));
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(lines));
  state.SetLabel(detail::digit_kernel_available(detail::DigitKernel::Avx512) || state.range(0) != 0
                     ? ""
                     : "no AVX-512 VBMI2: portable kernel");
}
BENCHMARK(BM_DigitWindows2h)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

// The whole parse of the 2-h text with each kernel (arguments: threads, kernel as above).
void BM_ParsePulseFile2hKernel(benchmark::State& state) {
  const std::string& text = bench::gl2d_text();
  ReadOptions o;
  o.threads = static_cast<unsigned>(state.range(0));
  const auto before = detail::set_digit_kernel(kernel_arg(state.range(1)));
  for (auto _ : state) {
    auto rec = read_recording_text(text, "gl2d.csv", o);
    benchmark::DoNotOptimize(rec.phase.points());
  }
  detail::set_digit_kernel(before);
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(text.size()));
  state.SetItemsProcessed(state.iterations() * 2'880'000);
}
BENCHMARK(BM_ParsePulseFile2hKernel)
    ->ArgsProduct({{1, 2}, {0, 1, 2}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// The same text read from a file (page cache): loading the bytes (argument 2: in two halves on two
// threads), then parsing as above. What `rwcalc analyze` does before its analysis.
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
  ReadOptions o;
  o.threads = static_cast<unsigned>(state.range(0));
  for (auto _ : state) {
    auto rec = read_recording(file.path(), o);
    benchmark::DoNotOptimize(rec.phase.points());
  }
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(bench::gl2d_text().size()));
  state.SetItemsProcessed(state.iterations() * 2'880'000);
}
BENCHMARK(BM_ReadPulseFile2h)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

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

}  // namespace
