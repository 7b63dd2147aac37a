// The vectorised path for one-digit pulse lines (see reader_simd.hpp): a window of 64 bytes is
// classified into bit masks (bit i for byte i), the masks prove that every line ending in the window
// is "[-]d\n" or "[-]d\r\n", and the values are then taken from the digit positions: by vpcompressb
// with the running sums formed in vector registers where the processor has AVX-512 VBMI2, else by
// a loop over the set bits of the digit mask (the line starts come from the masks, so no line waits
// for the previous one's bytes).
#include "io/reader_simd.hpp"

#include "io/reader_detail.hpp"

#include <atomic>
#include <bit>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace rwcalc::detail {
namespace {

struct Classes {
  std::uint64_t nl = 0, minus = 0, digit = 0, cr = 0;
};

// Where the values of a qualifying window are: `value` has the bit of each line's digit, `neg` the
// bits of the digits after a minus sign; `used` is the number of bytes up to the last line end.
struct Window {
  std::uint64_t value = 0, neg = 0;
  unsigned used = 0;
};

// Whether the window starting at a line start, of byte classes c, consists of one-digit lines up to
// its last line end. With L the bytes up to that line end, each line of it is M? D R? N (minus,
// digit, carriage return, newline), which holds exactly when:
//   - no byte of L is of another class;
//   - the digits in L are the bytes before each N, or before each R that precedes an N (so there is
//     one digit per line, right before its line end);
//   - every R in L is right before an N, every M at a line start (bit 0 or after an N);
//   - the window does not start with N or R (a blank line).
// A line with no digit ("-\n", "\r\n") or two ("12\n") breaks the digit equation.
inline bool plain_window(const Classes& c, Window& w) noexcept {
  const std::uint64_t n = c.nl;
  if (n == 0 || ((n | c.cr) & 1U) != 0) return false;
  const unsigned last = 63U - static_cast<unsigned>(std::countl_zero(n));
  const std::uint64_t in = (std::uint64_t{2} << last) - 1;  // L: bits 0..last (all when last = 63)
  const std::uint64_t before_nl = n >> 1;
  const std::uint64_t cr = c.cr & in;
  const std::uint64_t minus = c.minus & in;
  const std::uint64_t value = (before_nl & ~cr) | (cr >> 1);
  const std::uint64_t starts = (n << 1) | 1U;
  const std::uint64_t bad = (in & ~(c.digit | minus | n | cr)) | ((c.digit & in) ^ value) | (cr & ~before_nl) |
                            (minus & ~starts);
  if (bad != 0) return false;
  w.value = value;
  w.neg = minus << 1;  // the digit after each minus (a subset of value once the checks pass)
  w.used = last + 1;
  return true;
}

#if defined(__x86_64__)
inline Classes classify_sse2(const char* p) noexcept {
  const __m128i lf = _mm_set1_epi8('\n');
  const __m128i mn = _mm_set1_epi8('-');
  const __m128i cr = _mm_set1_epi8('\r');
  const __m128i zero = _mm_set1_epi8('0');
  const __m128i nine = _mm_set1_epi8(9);
  Classes c;
  for (int k = 0; k < 4; ++k) {
    const __m128i b = _mm_loadu_si128(reinterpret_cast<const __m128i*>(p + 16 * k));
    const __m128i d = _mm_sub_epi8(b, zero);
    const auto mask = [](__m128i m) {
      return static_cast<std::uint64_t>(static_cast<std::uint32_t>(_mm_movemask_epi8(m)));
    };
    c.nl |= mask(_mm_cmpeq_epi8(b, lf)) << (16 * k);
    c.minus |= mask(_mm_cmpeq_epi8(b, mn)) << (16 * k);
    c.cr |= mask(_mm_cmpeq_epi8(b, cr)) << (16 * k);
    c.digit |= mask(_mm_cmpeq_epi8(_mm_min_epu8(d, nine), d)) << (16 * k);  // (b − '0') ≤ 9 unsigned
  }
  return c;
}
#else
inline Classes classify_sse2(const char* p) noexcept {
  Classes c;
  for (unsigned i = 0; i < 64; ++i) {
    const auto b = static_cast<unsigned char>(p[i]);
    const std::uint64_t bit = std::uint64_t{1} << i;
    c.nl |= b == '\n' ? bit : 0;
    c.minus |= b == '-' ? bit : 0;
    c.cr |= b == '\r' ? bit : 0;
    c.digit |= static_cast<unsigned char>(b - '0') < 10 ? bit : 0;
  }
  return c;
}
#endif

// Portable kernel: the masks from SSE2 compares, the values by a loop over the digit bits; emit(u,
// d) takes each line's count u (modulo 2^64) and its digit d, in line order.
template <class Emit>
const char* each_portable(const char* p, const char* limit, Emit&& emit) noexcept {
  while (limit - p >= 64) {
    Window w;
    if (!plain_window(classify_sse2(p), w)) break;
    for (std::uint64_t e = w.value; e != 0; e &= e - 1) {
      const auto i = static_cast<unsigned>(std::countr_zero(e));
      const auto d = static_cast<std::uint64_t>(static_cast<unsigned char>(p[i]) - '0');
      const std::uint64_t s = 0 - ((w.neg >> i) & 1U);
      emit((d ^ s) - s, d);
    }
    p += w.used;
  }
  return p;
}

template <bool Sum>
const char* windows_portable(const char* p, const char* limit, std::int64_t* out, std::size_t& count,
                             std::uint64_t& acc, std::uint64_t& mag) noexcept {
  std::size_t k = 0;
  std::uint64_t a = acc, m = mag;
  p = each_portable(p, limit, [&](std::uint64_t u, std::uint64_t d) {
    if constexpr (Sum) {
      a += u;
      m += d;
      out[k++] = static_cast<std::int64_t>(a);
    } else {
      out[k++] = static_cast<std::int64_t>(u);
    }
  });
  count = k;
  acc = a;
  mag = m;
  return p;
}

// Sum of the counts of the windows of one-digit lines from p (as windows_portable, nothing written).
const char* sum_portable(const char* p, const char* limit, std::uint64_t& sum) noexcept {
  std::uint64_t a = sum;
  p = each_portable(p, limit, [&](std::uint64_t u, std::uint64_t) { a += u; });
  sum = a;
  return p;
}

#if defined(__x86_64__)
// GCC 12 warns about the deliberately undefined upper lanes inside its own AVX-512 headers
// (_mm512_undefined_epi32 in the casts and conversions): nothing here reads them.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#define RWCALC_VBMI2 __attribute__((target("avx512f,avx512bw,avx512vbmi2,popcnt,bmi2")))

// AVX-512 kernel: masks from four compares of the whole window; the values (digit − '0', negated
// after a minus) compressed to the first bytes of a register (vpcompressb), widened to 16 bits for
// an in-register prefix sum over the window's ≤ 32 lines (|sum| ≤ 288), widened again to 64 bits
// and offset by the running sum, kept broadcast in a register; Σ|c| by vpsadbw on the digits.
// The classes of the 64 bytes at p (as classify_sse2), and the bytes less '0' in d.
RWCALC_VBMI2 inline __attribute__((always_inline)) Classes classify_avx512(const char* p, __m512i& d) noexcept {
  const __m512i b = _mm512_loadu_si512(p);
  d = _mm512_sub_epi8(b, _mm512_set1_epi8('0'));
  Classes c;
  c.nl = _mm512_cmpeq_epi8_mask(b, _mm512_set1_epi8('\n'));
  c.minus = _mm512_cmpeq_epi8_mask(b, _mm512_set1_epi8('-'));
  c.cr = _mm512_cmpeq_epi8_mask(b, _mm512_set1_epi8('\r'));
  c.digit = _mm512_cmplt_epu8_mask(d, _mm512_set1_epi8(10));
  return c;
}

template <bool Sum>
RWCALC_VBMI2 const char* windows_avx512(const char* p, const char* limit, std::int64_t* out, std::size_t& count,
                                        std::uint64_t& acc, std::uint64_t& mag) noexcept {
  const __m512i zero = _mm512_setzero_si512();
  // Lane i of the shift by s takes lane i − s (lanes below s are zeroed by the mask).
  const __m512i lane = _mm512_set_epi16(31, 30, 29, 28, 27, 26, 25, 24, 23, 22, 21, 20, 19, 18, 17, 16, 15, 14, 13,
                                        12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0);
  const __m512i last_lane = _mm512_set1_epi64(7);
  __m512i accv = _mm512_set1_epi64(static_cast<long long>(acc));
  __m512i magv = zero;
  std::size_t k = 0;
  while (limit - p >= 64) {
    __m512i d;
    const Classes c = classify_avx512(p, d);
    Window w;
    if (!plain_window(c, w)) break;
    const __m512i v = _mm512_mask_sub_epi8(d, w.neg, zero, d);   // the counts, as int8
    const __m512i packed = _mm512_maskz_compress_epi8(w.value, v);  // line order; zeros after
    const auto lines = static_cast<unsigned>(_mm_popcnt_u64(w.value));
    const auto valid = static_cast<std::uint32_t>(_bzhi_u64(~std::uint64_t{0}, lines));
    if constexpr (Sum) {
      magv = _mm512_add_epi64(magv, _mm512_sad_epu8(_mm512_maskz_mov_epi8(w.value, d), zero));
      __m512i x = _mm512_cvtepi8_epi16(_mm512_castsi512_si256(packed));
      for (int s = 1; s < 32; s *= 2) {
        const auto keep = static_cast<__mmask32>(~0U << s);
        x = _mm512_add_epi16(
            x, _mm512_maskz_permutexvar_epi16(keep, _mm512_sub_epi16(lane, _mm512_set1_epi16(static_cast<short>(s))),
                                              x));
      }
      // Lanes past the last line repeat the window's total (the compressed zeros add nothing).
      __m512i y3 = zero;
      for (int g = 0; g < 4; ++g) {
        const __m128i part = g == 0   ? _mm512_castsi512_si128(x)
                             : g == 1 ? _mm512_extracti32x4_epi32(x, 1)
                             : g == 2 ? _mm512_extracti32x4_epi32(x, 2)
                                      : _mm512_extracti32x4_epi32(x, 3);
        const __m512i y = _mm512_add_epi64(_mm512_cvtepi16_epi64(part), accv);
        _mm512_mask_storeu_epi64(out + k + 8 * g, static_cast<__mmask8>(valid >> (8 * g)), y);
        if (g == 3) y3 = y;
      }
      accv = _mm512_permutexvar_epi64(last_lane, y3);
    } else {
      const __m128i lo = _mm512_castsi512_si128(packed);
      const __m128i hi = _mm512_extracti32x4_epi32(packed, 1);
      _mm512_mask_storeu_epi64(out + k, static_cast<__mmask8>(valid), _mm512_cvtepi8_epi64(lo));
      _mm512_mask_storeu_epi64(out + k + 8, static_cast<__mmask8>(valid >> 8),
                               _mm512_cvtepi8_epi64(_mm_srli_si128(lo, 8)));
      _mm512_mask_storeu_epi64(out + k + 16, static_cast<__mmask8>(valid >> 16), _mm512_cvtepi8_epi64(hi));
      _mm512_mask_storeu_epi64(out + k + 24, static_cast<__mmask8>(valid >> 24),
                               _mm512_cvtepi8_epi64(_mm_srli_si128(hi, 8)));
    }
    k += lines;
    p += w.used;
  }
  count = k;
  if constexpr (Sum) {
    acc = static_cast<std::uint64_t>(_mm_cvtsi128_si64(_mm512_castsi512_si128(accv)));
    mag += static_cast<std::uint64_t>(_mm512_reduce_add_epi64(magv));
  }
  return p;
}
// Sum of the counts of the windows of one-digit lines from p: the digits after a minus and the
// others summed apart by vpsadbw (eight 64-bit partial sums each), nothing written.
RWCALC_VBMI2 const char* sum_avx512(const char* p, const char* limit, std::uint64_t& sum) noexcept {
  const __m512i zero = _mm512_setzero_si512();
  __m512i pos = zero, neg = zero;
  while (limit - p >= 64) {
    __m512i d;
    const Classes c = classify_avx512(p, d);
    Window w;
    if (!plain_window(c, w)) break;
    pos = _mm512_add_epi64(pos, _mm512_sad_epu8(_mm512_maskz_mov_epi8(w.value & ~w.neg, d), zero));
    neg = _mm512_add_epi64(neg, _mm512_sad_epu8(_mm512_maskz_mov_epi8(w.neg, d), zero));
    p += w.used;
  }
  sum += static_cast<std::uint64_t>(_mm512_reduce_add_epi64(pos)) -
         static_cast<std::uint64_t>(_mm512_reduce_add_epi64(neg));
  return p;
}
#undef RWCALC_VBMI2
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

bool has_avx512_kernel() noexcept {
  static const bool yes = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
                          __builtin_cpu_supports("avx512vbmi2") && __builtin_cpu_supports("bmi2") &&
                          __builtin_cpu_supports("popcnt");
  return yes;
}
#else
bool has_avx512_kernel() noexcept { return false; }
#endif

DigitKernel resolve(DigitKernel k) noexcept {
  if (k == DigitKernel::Auto) return has_avx512_kernel() ? DigitKernel::Avx512 : DigitKernel::Portable;
  if (k == DigitKernel::Avx512 && !has_avx512_kernel()) return DigitKernel::Portable;
  return k;
}

std::atomic<DigitKernel>& requested() noexcept {
  static std::atomic<DigitKernel> k{DigitKernel::Auto};
  return k;
}

std::atomic<DigitKernel>& in_use() noexcept {
  static std::atomic<DigitKernel> k{resolve(DigitKernel::Auto)};
  return k;
}

}  // namespace

bool digit_kernel_available(DigitKernel k) noexcept { return k != DigitKernel::Avx512 || has_avx512_kernel(); }

DigitKernel set_digit_kernel(DigitKernel k) noexcept {
  in_use().store(resolve(k), std::memory_order_relaxed);
  return requested().exchange(k, std::memory_order_relaxed);
}

DigitKernel digit_kernel() noexcept { return in_use().load(std::memory_order_relaxed); }

template <bool Sum>
const char* digit_windows(const char* p, const char* limit, std::int64_t* out, std::size_t& n, std::uint64_t& acc,
                          std::uint64_t& mag) noexcept {
  switch (digit_kernel()) {
#if defined(__x86_64__)
    case DigitKernel::Avx512:
      return windows_avx512<Sum>(p, limit, out, n, acc, mag);
#endif
    case DigitKernel::Portable:
      return windows_portable<Sum>(p, limit, out, n, acc, mag);
    default:
      n = 0;
      return p;
  }
}

bool digit_sum(const char* p, const char* limit, std::uint64_t& sum) noexcept {
  std::uint64_t a = 0;
  const DigitKernel k = digit_kernel();
  while (p < limit) {
#if defined(__x86_64__)
    if (k == DigitKernel::Avx512) p = sum_avx512(p, limit, a);
#endif
    if (k == DigitKernel::Portable) p = sum_portable(p, limit, a);
    // A window of other lines, or the last bytes: one line at a time up to the next window.
    const char* stop = limit - p > 64 ? p + 64 : limit;
    while (p < stop) {
      std::int64_t v = 0;
      const char* next = scan_int_line(p, v);
      if (!next) return false;
      a += static_cast<std::uint64_t>(v);
      p = next;
    }
  }
  sum = a;
  return p == limit;
}

template const char* digit_windows<true>(const char*, const char*, std::int64_t*, std::size_t&, std::uint64_t&,
                                         std::uint64_t&) noexcept;
template const char* digit_windows<false>(const char*, const char*, std::int64_t*, std::size_t&, std::uint64_t&,
                                          std::uint64_t&) noexcept;

}  // namespace rwcalc::detail
