// libFuzzer target: command-line parsing. The input is split at newlines into argv[1..] (at most
// 64 arguments) and parsed by the same CLI11 application `rwcalc` builds, without running the
// command (rwcalc::cli::parse_only). Contract: parsing returns an exit status of 0, 1 or 2 and
// never throws; every non-zero status comes with a message on the error stream.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "rwcalc/cli.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> args{"rwcalc"};
  std::size_t start = 0;
  while (start <= text.size() && args.size() <= 64) {
    const auto nl = text.find('\n', start);
    const auto end = nl == std::string::npos ? text.size() : nl;
    args.push_back(text.substr(start, end - start));
    if (nl == std::string::npos) break;
    start = nl + 1;
  }
  std::vector<const char*> argv;
  argv.reserve(args.size());
  for (const auto& a : args) argv.push_back(a.c_str());

  std::ostringstream out, err;
  const int status = rwcalc::cli::parse_only(static_cast<int>(argv.size()), argv.data(), out, err);
  if (status < 0 || status > 3 || (status != 0 && err.str().empty())) {
    std::fprintf(stderr, "fuzz_cli_args: status %d with message '%s'\n", status, err.str().c_str());
    std::abort();
  }
  return 0;
}
