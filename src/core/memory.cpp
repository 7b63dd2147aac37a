// The memory ceiling (memory.hpp): what the machine, the resource limits and the cgroup allow,
// and the --max-memory option.
#include "rwcalc/memory.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <string>

#include <fmt/format.h>

#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"

namespace rwcalc {

namespace {

constexpr double kKiB = 1024.0;

// The soft limit of `resource`, 0 when there is none.
std::size_t soft_limit(int resource) {
  struct rlimit r {};
  if (getrlimit(resource, &r) != 0 || r.rlim_cur == RLIM_INFINITY) return 0;
  return static_cast<std::size_t>(r.rlim_cur);
}

// The cgroup (v2) memory limit of this process' cgroup as the container sees it, 0 when none.
std::size_t cgroup_limit() {
  std::ifstream in("/sys/fs/cgroup/memory.max");
  std::string text;
  if (!(in >> text) || text == "max") return 0;
  std::size_t v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  return ec == std::errc() && end == text.data() + text.size() ? v : 0;
}

}  // namespace

MemoryCeiling default_memory_ceiling() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  MemoryCeiling c{pages > 0 && page > 0 ? static_cast<std::size_t>(pages) * static_cast<std::size_t>(page)
                                        : std::size_t{1} << 31,
                  tr("half the physical memory")};
  const std::pair<std::size_t, const char*> limits[] = {{soft_limit(RLIMIT_AS),
                                                         N_("half the address-space limit, ulimit -v")},
                                                        {soft_limit(RLIMIT_DATA),
                                                         N_("half the data-size limit, ulimit -d")},
                                                        {cgroup_limit(), N_("half the memory limit of the cgroup")}};
  for (const auto& [bytes, origin] : limits)
    if (bytes > 0 && bytes < c.bytes) c = {bytes, tr(origin)};
  c.bytes /= 2;
  return c;
}

MemoryCeiling memory_ceiling_option(std::string_view size) {
  const auto refuse = [&] {
    throw UsageError(
        trf("{} {}: not a memory size of at least 1 MiB; give bytes or a number with K, M, G or T "
            "(1K = 1024 bytes), e.g. 4G",
            kMaxMemoryOption, size));
  };
  double value = 0;
  const auto [end, ec] = std::from_chars(size.data(), size.data() + size.size(), value);
  if (ec != std::errc() || !std::isfinite(value) || value < 0) refuse();
  std::string unit(end, size.data() + size.size());
  for (auto& ch : unit) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  for (const char* tail : {"IB", "B"})
    if (unit.size() > 1 && unit.ends_with(tail)) unit.resize(unit.size() - std::string_view(tail).size());
  const std::string_view units = "KMGT";
  const auto at = unit.empty() ? std::string_view::npos : units.find(unit);
  if (!unit.empty() && (unit.size() != 1 || at == std::string_view::npos)) refuse();
  const double bytes = value * (unit.empty() ? 1.0 : std::pow(kKiB, static_cast<double>(at + 1)));
  if (!(bytes >= kKiB * kKiB && bytes < 0x1p62)) refuse();
  return {static_cast<std::size_t>(bytes), kMaxMemoryOption};
}

std::string format_memory(double bytes) {
  if (bytes < kKiB) return trf("{:.0f} bytes", bytes);
  int unit = 0;
  for (; unit < 3 && bytes >= kKiB * kKiB; ++unit) bytes /= kKiB;
  constexpr const char* kNames[] = {"KiB", "MiB", "GiB", "TiB"};
  return fmt::format("{:.3g} {}", bytes / kKiB, kNames[unit]);
}

}  // namespace rwcalc
