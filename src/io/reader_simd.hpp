#pragma once
// Internal to the reader: the vectorised path for the commonest pulse lines of all, one digit with
// an optional minus sign ("0\n", "1\n", "-1\n"; CRLF too). A 64-byte window is classified at once
// (line ends, minus signs, digits, carriage returns); when every line that ends in it is of that
// form, its values are taken together, with no per-line branch, and the cumulative counts and Σ|c|
// written as Reader::int_lines writes them. The first window with any other line is left to the
// caller's per-line path, so the values, runs of lines and errors do not depend on this path.
#include <cstddef>
#include <cstdint>

namespace rwcalc::detail {

/// Which kernel digit_windows runs. Auto: the AVX-512 VBMI2 kernel (vpcompressb) when the processor
/// has it, else the portable one (SSE2 classification, a loop over the value bits). Off: none
/// (digit_windows takes nothing; the reader's per-line path does every line, as before).
enum class DigitKernel { Auto, Avx512, Portable, Off };

/// Whether `k` can run on this processor (Auto and Off always can).
bool digit_kernel_available(DigitKernel k) noexcept;

/// The kernel digit_windows uses from now on (a test and benchmark hook; Auto at start). Falls back
/// to Portable when `k` is not available here. Returns the one asked for before. Not to be changed
/// while a read is in progress.
DigitKernel set_digit_kernel(DigitKernel k) noexcept;

/// The kernel in use (Auto resolved: Avx512, Portable or Off).
DigitKernel digit_kernel() noexcept;

/// Takes whole windows of 64 bytes from p (a line start) while p + 64 ≤ limit and every line that
/// ends in the window is "[-]d\n" or "[-]d\r\n"; the line the window cuts starts the next window.
/// Writes one value per line to out[0, n) (only those slots: room for one per line suffices), and
/// returns where it stopped (p when the first window does not qualify) and n. With Sum, the values
/// written are the running sums acc + c_1 + … (modulo 2^64) and Σ|c| is added to mag, as
/// Reader::int_lines<true> forms them; without, the counts themselves (acc and mag untouched).
template <bool Sum>
const char* digit_windows(const char* p, const char* limit, std::int64_t* out, std::size_t& n,
                          std::uint64_t& acc, std::uint64_t& mag) noexcept;

/// The sum (modulo 2^64) of the counts of the lines in [p, limit), where limit is a line start,
/// when every one of them is a plain integer line ("[-]d…d" of 1 to 7 digits, then LF or CRLF:
/// what scan_int_line takes); false at the first line that is not (sum is then meaningless).
/// Windows of one-digit lines are summed without writing anything, by the kernel in use.
bool digit_sum(const char* p, const char* limit, std::uint64_t& sum) noexcept;

extern template const char* digit_windows<true>(const char*, const char*, std::int64_t*, std::size_t&,
                                                std::uint64_t&, std::uint64_t&) noexcept;
extern template const char* digit_windows<false>(const char*, const char*, std::int64_t*, std::size_t&,
                                                 std::uint64_t&, std::uint64_t&) noexcept;

}  // namespace rwcalc::detail
