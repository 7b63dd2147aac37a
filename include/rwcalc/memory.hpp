#pragma once
/// @file memory.hpp
/// The memory ceiling: the most memory one record may take, read or simulated. The reader counts
/// what it holds as the samples arrive and simulate estimates a record before it starts; a record
/// that would pass the ceiling is refused with the memory it needs, instead of running out of
/// memory part way (docs/reliability.md).
#include <cstddef>
#include <string>
#include <string_view>

namespace rwcalc {

struct MemoryCeiling {
  std::size_t bytes = 0;
  /// Where it comes from, for messages: "--max-memory", "half the physical memory", …
  std::string origin;
};

/// Half of the memory rwcalc may use: the smallest of the physical memory, the address-space
/// limit (ulimit -v), the data-segment limit (ulimit -d) and the cgroup's memory.max. Half, so
/// that the analysis of a record that fits has room beside its samples.
MemoryCeiling default_memory_ceiling();

/// The ceiling `--max-memory SIZE` gives: bytes, or a number with K, M, G or T (binary units,
/// 1K = 1024; "KiB", "MB" and the like read the same). Throws UsageError for anything else or
/// for less than 1 MiB.
MemoryCeiling memory_ceiling_option(std::string_view size);

/// Bytes as a reader says them: "4.01 GiB", "64 MiB", "512 bytes" (binary units, 3 digits).
std::string format_memory(double bytes);

/// How the ceiling is raised, for the end of a refusal: "--max-memory SIZE".
inline constexpr const char* kMaxMemoryOption = "--max-memory";

}  // namespace rwcalc
