// The vectorised path for one-digit pulse lines (src/reader_simd.hpp): every kernel (AVX-512 VBMI2
// where the processor has it, the portable one, none) must take exactly the windows made only of
// "[-]d\n" / "[-]d\r\n" lines, give the values scan_int_line gives with the same running sums and
// Σ|c|, write nothing else, and leave the reader's records and errors as they were.
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "io/reader_detail.hpp"
#include "io/reader_simd.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/reader.hpp"

namespace {

namespace detail = rwcalc::detail;
using detail::DigitKernel;
using rwcalc::read_recording_text;
using rwcalc::ReadOptions;
using rwcalc::Recording;

// Sets a kernel for the scope of a test and puts the previous one back.
class KernelScope {
 public:
  explicit KernelScope(DigitKernel k) : before_(detail::set_digit_kernel(k)) {}
  ~KernelScope() { detail::set_digit_kernel(before_); }
  KernelScope(const KernelScope&) = delete;
  KernelScope& operator=(const KernelScope&) = delete;

 private:
  DigitKernel before_;
};

// The kernels that take windows on this machine (the AVX-512 one only where it can run).
std::vector<DigitKernel> window_kernels() {
  std::vector<DigitKernel> k{DigitKernel::Portable};
  if (detail::digit_kernel_available(DigitKernel::Avx512)) k.push_back(DigitKernel::Avx512);
  return k;
}

const char* kernel_name(DigitKernel k) {
  switch (k) {
    case DigitKernel::Avx512: return "avx512";
    case DigitKernel::Portable: return "portable";
    case DigitKernel::Off: return "off";
    default: return "auto";
  }
}

// Whether [b, e) (one line with its LF) is a one-digit pulse line, decided character by character.
bool one_digit_line(const char* b, const char* e) {
  std::string line(b, e);
  if (!line.empty() && line[0] == '-') line.erase(0, 1);
  return line.size() >= 2 && detail::is_digit(line[0]) && (line.substr(1) == "\n" || line.substr(1) == "\r\n");
}

struct Taken {
  const char* stop = nullptr;
  std::vector<std::int64_t> values;  // running sums with Sum, else the counts
  std::uint64_t acc = 0, mag = 0;
};

// What digit_windows must do, from the specification: windows of 64 bytes from p while p + 64 ≤ limit,
// each taken when it holds a line end and every line up to its last line end is one-digit; the
// values from scan_int_line.
template <bool Sum>
Taken reference(const char* p, const char* limit, std::uint64_t acc, std::uint64_t mag) {
  Taken t;
  t.acc = acc;
  t.mag = mag;
  while (limit - p >= 64) {
    const char* last = nullptr;
    for (const char* c = p; c < p + 64; ++c)
      if (*c == '\n') last = c;
    if (!last) break;
    bool ok = true;
    for (const char* s = p; s <= last && ok;) {
      const char* e = s;
      while (*e != '\n') ++e;
      ok = one_digit_line(s, e + 1);
      s = e + 1;
    }
    if (!ok) break;
    for (const char* s = p; s <= last;) {
      std::int64_t v = 0;
      const char* next = detail::scan_int_line(s, v);
      EXPECT_NE(next, nullptr);
      std::int64_t want = 0;
      EXPECT_NE(detail::scan_int_fast(s, want), nullptr);
      EXPECT_EQ(v, want);
      if constexpr (Sum) {
        t.acc += static_cast<std::uint64_t>(v);
        t.mag += static_cast<std::uint64_t>(v < 0 ? -v : v);
        t.values.push_back(static_cast<std::int64_t>(t.acc));
      } else {
        t.values.push_back(v);
      }
      s = next;
    }
    p = last + 1;
  }
  t.stop = p;
  return t;
}

constexpr std::int64_t kUntouched = 0x5a5a5a5a5a5a5a5a;

template <bool Sum>
void check_windows(const std::string& padded_text, std::size_t from, std::size_t to, DigitKernel k,
                   std::uint64_t acc0) {
  const char* p = padded_text.data() + from;
  const char* limit = padded_text.data() + to;
  const std::uint64_t mag0 = acc0 / 3;
  const Taken want = reference<Sum>(p, limit, acc0, mag0);
  // Room for one value per byte (more than one per line), plus slots that must stay untouched.
  std::vector<std::int64_t> out(to - from + 40, kUntouched);
  std::size_t n = 12345;
  std::uint64_t acc = acc0, mag = mag0;
  const KernelScope scope(k);
  const char* stop = detail::digit_windows<Sum>(p, limit, out.data(), n, acc, mag);
  const auto where = [&] { return fmt::format("{} sum={} from={} to={}", kernel_name(k), Sum, from, to); };
  ASSERT_EQ(stop - padded_text.data(), want.stop - padded_text.data()) << where();
  ASSERT_EQ(n, want.values.size()) << where();
  for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(out[i], want.values[i]) << where() << " value " << i;
  for (std::size_t i = n; i < out.size(); ++i) ASSERT_EQ(out[i], kUntouched) << where() << " slot " << i;
  if (Sum) {
    EXPECT_EQ(acc, want.acc) << where();
    EXPECT_EQ(mag, want.mag) << where();
  } else {
    EXPECT_EQ(acc, acc0) << where();
    EXPECT_EQ(mag, mag0) << where();
  }
}

// Mostly one-digit lines, with every kind of other line now and then: multi-digit counts, CRLF,
// blank lines, comments, lines the reader rejects, and near misses of the one-digit form.
std::string mixed_lines(std::size_t lines, unsigned seed, int rare_per_1000) {
  static const char* const kOdd[] = {"12\n", "-345\n", "1234567\n", "12345678\n", "\n", "\r\n", "# note\n",
                                     "x\n", "--1\n", "-\n", "-\r\n", "1\r\r\n", "1 \n", " 1\n", "+1\n",
                                     "1-\n", "1\r", "5\n\r\n", "-1-\n", "1.\n", "\t\n", "99\r\n"};
  std::mt19937_64 rng(seed);
  std::string t;
  for (std::size_t i = 0; i < lines; ++i) {
    if (static_cast<int>(rng() % 1000) < rare_per_1000) {
      t += kOdd[rng() % std::size(kOdd)];
      continue;
    }
    if (rng() % 3 == 0) t += '-';
    t += static_cast<char>('0' + rng() % 10);
    t += (rng() % 16 == 0) ? "\r\n" : "\n";
  }
  return t;
}

std::string padded(std::string t) { return t + std::string(80, '\0'); }

TEST(ReadSimd, KernelsTakeExactlyTheOneDigitWindows) {
  for (const int rare : {0, 2, 10, 40, 200}) {
    const std::string text = padded(mixed_lines(4000, 100U + static_cast<unsigned>(rare), rare));
    const std::size_t size = text.size() - 80;
    // Every line start of the first 300 bytes as a start (so windows cut lines at every offset),
    // the end of the text or a line start near it as the limit.
    std::vector<std::size_t> starts{0};
    for (std::size_t i = 0; i < 300; ++i)
      if (text[i] == '\n') starts.push_back(i + 1);
    const std::size_t mid = text.find('\n', size / 2) + 1;
    for (const DigitKernel k : window_kernels())
      for (const std::size_t s : starts)
        for (const std::size_t to : {size, mid, s + 63, s + 64, s + 65, s + 130}) {
          if (to < s || to > size) continue;
          check_windows<true>(text, s, to, k, 1000U * s);
          check_windows<false>(text, s, to, k, 0);
          if (::testing::Test::HasFatalFailure()) return;
        }
  }
}

TEST(ReadSimd, OneOddLineAtEveryOffsetOfAWindow) {
  // Windows of one-digit lines with a single odd line (or byte) starting at every offset 0..191:
  // the kernels stop at the window that holds it, whatever its offset, and take everything before.
  static const char* const kOdd[] = {"12\n", "\n", "\r\n", "-\n", "x\n", "--1\n", "1\r\r\n", "1\r", "+1\n", "-12\n"};
  for (const char* odd : kOdd)
    for (std::size_t at = 0; at < 192; ++at) {
      if (at == 1) continue;  // no whole line is 1 byte long (offset 1 of later windows is covered)
      std::string t;
      std::mt19937_64 rng(at);
      while (at - t.size() > 4) t += (rng() & 1) ? "-3\n" : "7\n";  // whole lines up to exactly `at`
      const std::size_t rest = at - t.size();
      t += rest == 2 ? "7\n" : rest == 3 ? "-3\n" : rest == 4 ? "7\n7\n" : "";
      ASSERT_EQ(t.size(), at);
      t += odd;
      while (t.size() < 400) t += (rng() & 1) ? "-1\r\n" : "0\n";
      const std::string text = padded(t);
      for (const DigitKernel k : window_kernels()) {
        check_windows<true>(text, 0, t.size(), k, 7);
        check_windows<false>(text, 0, t.size(), k, 0);
        if (::testing::Test::HasFatalFailure()) return;
      }
    }
}

TEST(ReadSimd, LargestAndExtremeSums) {
  // 32 lines of "9\n" fill a window (the largest window total, 288) and "-9\n" the smallest; the
  // running sum wraps modulo 2^64 as the scalar path's does.
  std::string t;
  for (int i = 0; i < 96; ++i) t += "9\n";
  for (int i = 0; i < 96; ++i) t += "-9\n";
  for (int i = 0; i < 64; ++i) t += "-0\n";
  const std::string text = padded(t);
  for (const DigitKernel k : window_kernels())
    for (const std::uint64_t acc0 : {std::uint64_t{0}, ~std::uint64_t{0} - 100, std::uint64_t{1} << 63}) {
      check_windows<true>(text, 0, t.size(), k, acc0);
      check_windows<false>(text, 0, t.size(), k, 0);
    }
}

// digit_sum: the sum of the counts of a range of lines when every line in it is plain (what
// scan_int_line takes: up to 7 digits, LF or CRLF), else false; the same with every kernel.
TEST(ReadSimd, DigitSumOfARangeOfLines) {
  for (const int rare : {0, 1, 5, 50}) {
    std::string t = mixed_lines(6000, 300U + static_cast<unsigned>(rare), rare);
    const std::string text = padded(t);
    std::vector<std::size_t> starts{0};
    for (std::size_t i = 0; i < t.size(); ++i)
      if (text[i] == '\n') starts.push_back(i + 1);
    std::mt19937_64 rng(static_cast<unsigned>(rare));
    for (int trial = 0; trial < 300; ++trial) {
      std::size_t a = starts[rng() % starts.size()], b = starts[rng() % starts.size()];
      if (trial % 50 == 0) {  // the whole text
        a = 0;
        b = t.size();
      }
      if (a > b) std::swap(a, b);
      // The reference: line by line.
      bool plain = true;
      std::uint64_t want = 0;
      for (std::size_t q = a; q < b && plain;) {
        std::int64_t v = 0;
        const char* next = detail::scan_int_line(text.data() + q, v);
        plain = next != nullptr;
        if (plain) {
          want += static_cast<std::uint64_t>(v);
          q = static_cast<std::size_t>(next - text.data());
        }
      }
      for (const DigitKernel k : {DigitKernel::Avx512, DigitKernel::Portable, DigitKernel::Off}) {
        if (!detail::digit_kernel_available(k)) continue;
        const KernelScope scope(k);
        std::uint64_t got = 12345;
        const bool ok = detail::digit_sum(text.data() + a, text.data() + b, got);
        ASSERT_EQ(ok, plain) << kernel_name(k) << " [" << a << ", " << b << ") rare " << rare;
        if (plain) {
          ASSERT_EQ(got, want) << kernel_name(k) << " [" << a << ", " << b << ") rare " << rare;
        }
      }
    }
  }
}

ReadOptions with_threads(unsigned t) {
  ReadOptions o;
  o.threads = t;
  return o;
}

// A pulse file of mostly one-digit lines with the reader's other line kinds (comments, blank lines,
// multi-digit and CRLF lines, "+3", indented values) spread through both parts of the text.
// Lines before `plain_until` are all one-digit (the second part's sums then start from the first
// part's total, summed beforehand).
std::string pulse_file(std::size_t n, unsigned seed, std::size_t plain_until = 0) {
  std::mt19937_64 rng(seed);
  std::string t = "# rate_hz: 400\npulses\n";
  for (std::size_t i = 0; i < n; ++i) {
    const auto r = i < plain_until ? 3000 : rng() % 3000;
    if (r == 0) t += "# note\n";
    if (r == 1) t += "\n";
    const int v = static_cast<int>(rng() % 7) - 3;
    if (r == 2)
      t += fmt::format("{}\n", 1000 * v);
    else if (r == 3)
      t += fmt::format(" {}\n", v);
    else if (r == 4 && v >= 0)
      t += fmt::format("+{}\n", v);
    else
      t += fmt::format("{}{}", v, r == 5 ? "\r\n" : "\n");
  }
  return t;
}

TEST(ReadSimd, ReaderSameRecordWithEveryKernel) {
  // Serial; two parts with other lines in both; a first part of one-digit lines only, the other
  // lines in the second; one-digit lines only.
  const std::size_t big = 1200000;
  for (const auto& [n, plain_until] : {std::pair{std::size_t{3000}, std::size_t{0}}, std::pair{big, std::size_t{0}},
                                       std::pair{big, big * 3 / 5}, std::pair{big, big}}) {
    const std::string text = pulse_file(n, 17, plain_until);
    Recording ref;
    {
      const KernelScope off(DigitKernel::Off);
      ref = read_recording_text(text, "p.csv", with_threads(1));
    }
    ASSERT_EQ(ref.samples, n);
    for (const DigitKernel k : window_kernels()) {
      const KernelScope scope(k);
      for (const unsigned t : {1U, 2U}) {
        const Recording r = read_recording_text(text, "p.csv", with_threads(t));
        EXPECT_EQ(r.samples, ref.samples) << kernel_name(k) << " threads " << t;
        EXPECT_EQ(r.phase.wide_counts(), ref.phase.wide_counts()) << kernel_name(k) << " threads " << t;
        EXPECT_EQ(r.line_runs, ref.line_runs) << kernel_name(k) << " threads " << t;
      }
    }
  }
}

struct Failure {
  std::string file;
  std::size_t line = 0;
  std::string message;
};

Failure failure(const std::string& text, unsigned threads) {
  try {
    (void)read_recording_text(text, "bad.csv", with_threads(threads));
  } catch (const rwcalc::InputError& e) {
    return {e.file(), e.line(), e.message()};
  }
  return {};
}

TEST(ReadSimd, ErrorsNameTheSameFileAndLine) {
  // A bad line among one-digit lines, early, at the middle (either side of where the text is split)
  // and late; the same error with every kernel and the vectorised path off.
  const std::size_t n = 1200000;
  for (const char* bad : {"1x\n", "--1\n", "-\n", "1,5\n"})
    for (const std::size_t at : {std::size_t{40}, n / 2 - 3, n / 2 + 40, n * 11 / 20, n - 7}) {
      std::string t = "pulses\n";
      t.reserve(3 * n);
      std::mt19937_64 rng(at);
      for (std::size_t i = 0; i < n; ++i) {
        if (i == at)
          t += bad;
        else
          t += (rng() & 3) == 0 ? "-1\n" : (rng() & 1) ? "1\n" : "0\n";
      }
      Failure want;
      {
        const KernelScope off(DigitKernel::Off);
        want = failure(t, 1);
      }
      ASSERT_EQ(want.line, at + 2) << bad;  // the header, then 1-based lines
      EXPECT_EQ(want.file, "bad.csv");
      for (const DigitKernel k : window_kernels()) {
        const KernelScope scope(k);
        for (const unsigned threads : {1U, 2U}) {
          const Failure got = failure(t, threads);
          EXPECT_EQ(got.file, want.file) << kernel_name(k) << " " << bad << " at " << at;
          EXPECT_EQ(got.line, want.line) << kernel_name(k) << " " << bad << " at " << at;
          EXPECT_EQ(got.message, want.message) << kernel_name(k) << " " << bad << " at " << at;
        }
      }
    }
}

TEST(ReadSimd, DispatchHook) {
  const KernelScope keep(DigitKernel::Auto);
  EXPECT_NE(detail::digit_kernel(), DigitKernel::Auto);  // resolved to a real kernel
  detail::set_digit_kernel(DigitKernel::Portable);
  EXPECT_EQ(detail::digit_kernel(), DigitKernel::Portable);
  detail::set_digit_kernel(DigitKernel::Off);
  EXPECT_EQ(detail::digit_kernel(), DigitKernel::Off);
  detail::set_digit_kernel(DigitKernel::Avx512);
  EXPECT_EQ(detail::digit_kernel(),
            detail::digit_kernel_available(DigitKernel::Avx512) ? DigitKernel::Avx512 : DigitKernel::Portable);
  if (!detail::digit_kernel_available(DigitKernel::Avx512))
    GTEST_SKIP() << "no AVX-512 VBMI2 here: only the portable kernel was tested";
}

}  // namespace
