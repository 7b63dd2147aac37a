// rwcalc: the executable is a thin wrapper around the library's command-line front end.
#include <fcntl.h>
#include <malloc.h>
#include <unistd.h>

#include <iostream>

#include "io/reader_detail.hpp"
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
  // Buffers below 64 MB (those of a 2-h record: text, counts, the second part's values, the int32
  // view) come from the heap and stay mapped when freed, so a later buffer — the next file's in
  // `batch` — reuses their pages instead of faulting in fresh ones; larger ones (a 24-h record)
  // are mapped and unmapped as before. Performance only: results do not depend on it.
  (void)mallopt(M_MMAP_THRESHOLD, 64 << 20);
  (void)mallopt(M_TRIM_THRESHOLD, 128 << 20);
  // One arena for all threads. A thread's own arena is built of 64-MB heaps that glibc unmaps as
  // soon as one is wholly free, whatever M_TRIM_THRESHOLD says: the buffers of batch's second
  // worker, and the outlier scan's beside the fit, were mapped and zeroed afresh every time. The
  // threads allocate a few large blocks each, not many small ones, so the shared lock costs nothing.
  (void)mallopt(M_ARENA_MAX, 1);
  // The heap grows 64 MB beyond each request (address space only: no page is touched until
  // used). Each growth is a brk call, which takes the process's memory map for writing and so
  // waits for any other thread mapping pages of its buffers (prefault): batch's workers, mapping
  // their first runs' buffers side by side, no longer queue behind each other's heap growth.
  (void)mallopt(M_TOP_PAD, 64 << 20);
  // So a buffer that reuses such pages is not mapped again (detail::prefault).
  rwcalc::detail::remember_mapped_pages(true);
  // Standard output through a buffer that remembers why a write failed (output.hpp); C's stdout
  // is not written by rwcalc.
  rwcalc::DescriptorBuffer standard_output(STDOUT_FILENO);
  std::streambuf* const previous = std::cout.rdbuf(&standard_output);
  const int status = rwcalc::cli::run(argc, argv, std::cout, std::cerr);
  std::cout.rdbuf(previous);
  return status;
}
