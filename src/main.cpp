// rwcalc: the executable is a thin wrapper around the library's command-line front end.
#include <fcntl.h>
#include <unistd.h>

#include <iostream>

#include "rwcalc/cli.hpp"
#include "rwcalc/output.hpp"

namespace {

/// A standard descriptor (0–2) closed when rwcalc starts would be taken by the next file rwcalc
/// opens, and a report meant for standard output would land in an output's temporary file. Each
/// closed one is occupied by /dev/null opened the other way round (stdin write-only, stdout and
/// stderr read-only), so that using it still fails as on a closed descriptor (EBADF): writing a
/// report to a closed standard output ends in status 3, not in another file.
void occupy_closed_standard_descriptors() {
  for (int fd = 0; fd <= 2; ++fd) {
    if (fcntl(fd, F_GETFD) >= 0) continue;
    const int opened = open("/dev/null", fd == 0 ? O_WRONLY : O_RDONLY);
    if (opened >= 0 && opened != fd) {
      (void)dup2(opened, fd);
      (void)close(opened);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  occupy_closed_standard_descriptors();
  // Standard output through a buffer that remembers why a write failed (output.hpp); C's stdout
  // is not written by rwcalc.
  rwcalc::DescriptorBuffer standard_output(STDOUT_FILENO);
  std::streambuf* const previous = std::cout.rdbuf(&standard_output);
  const int status =
      rwcalc::cli::run(argc, argv, std::cout, std::cerr, rwcalc::stderr_is_terminal() ? stderr : nullptr);
  std::cout.rdbuf(previous);
  return status;
}
