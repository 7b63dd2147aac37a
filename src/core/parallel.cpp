// The library's only thread pool: threads started per loop, items handed out by an atomic index;
// and the one two-stage pipeline, its second stage on a thread started per call.
#include "rwcalc/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cstdlib>
#include <exception>
#include <mutex>
#include <string_view>
#include <system_error>
#include <thread>
#include <vector>

namespace rwcalc {
namespace {

thread_local bool inside_parallel_for = false;

// Restores the flag however the loop ends.
struct InsideGuard {
  bool saved = inside_parallel_for;
  InsideGuard() { inside_parallel_for = true; }
  ~InsideGuard() { inside_parallel_for = saved; }
  InsideGuard(const InsideGuard&) = delete;
  InsideGuard& operator=(const InsideGuard&) = delete;
};

}  // namespace

unsigned worker_count() {
  if (const char* env = std::getenv("RWCALC_THREADS")) {
    const std::string_view text(env);
    unsigned value = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec == std::errc() && end == text.data() + text.size() && value >= 1 && value <= 4096) return value;
  }
  return std::max(1u, std::thread::hardware_concurrency());
}

bool inside_parallel_items() noexcept { return inside_parallel_for; }

void parallel_for(std::size_t n, const std::function<void(std::size_t)>& fn) {
  const std::size_t threads = inside_parallel_for ? 1 : std::min<std::size_t>(n, worker_count());
  if (threads <= 1) {
    for (std::size_t i = 0; i < n; ++i) fn(i);
    return;
  }
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto work = [&] {
    const InsideGuard guard;
    for (std::size_t i = next++; i < n && !failed; i = next++) {
      try {
        fn(i);
      } catch (...) {
        const std::lock_guard lock(error_mutex);
        if (!error) error = std::current_exception();
        failed = true;
      }
    }
  };
  {
    std::vector<std::jthread> helpers;
    helpers.reserve(threads - 1);
    for (std::size_t t = 1; t < threads; ++t) {
      try {
        helpers.emplace_back(work);
      } catch (const std::system_error&) {
        break;  // no more threads to be had: the ones running (and this one) do every item
      }
    }
    work();
  }  // the jthreads join here
  if (error) std::rethrow_exception(error);
}

void run_beside(const std::function<void()>& main, const std::function<void()>& beside) {
  if (inside_parallel_for || worker_count() <= 1) {
    main();
    beside();
    return;
  }
  std::exception_ptr beside_error;
  {
    std::jthread helper;
    try {
      helper = std::jthread([&] {
        try {
          beside();
        } catch (...) {
          beside_error = std::current_exception();
        }
      });
    } catch (const std::system_error&) {
      main();  // no thread to be had: one after the other
      beside();
      return;
    }
    main();  // on an exception the helper joins as the jthread goes
  }
  if (beside_error) std::rethrow_exception(beside_error);
}

}  // namespace rwcalc
