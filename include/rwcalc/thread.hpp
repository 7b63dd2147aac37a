#pragma once
/// @file thread.hpp
/// rwcalc::Thread: a std::jthread started on another core than the calling thread's.
#include <pthread.h>

#include <functional>
#include <stop_token>
#include <type_traits>
#include <utility>

namespace rwcalc {

/// Like std::jthread — it joins on destruction, after asking a function that takes a
/// std::stop_token to stop — but started on another core than the calling thread's when the
/// process may run on one: the scheduler otherwise often queues a new thread on its creator's
/// core, which is busy, until it moves it (1–4 ms on a 2-core machine, as long as the pass the
/// thread was started for). Once running, the thread may run on every core the process may.
class Thread {
 public:
  Thread() noexcept = default;
  template <class F>
    requires(!std::is_same_v<std::remove_cvref_t<F>, Thread>)
  explicit Thread(F&& f) {
    if constexpr (std::is_invocable_v<std::decay_t<F>&, std::stop_token>)
      start([fn = std::forward<F>(f), token = stop_.get_token()]() mutable { fn(token); });
    else
      start(std::function<void()>(std::forward<F>(f)));
  }
  Thread(Thread&& other) noexcept { swap(other); }
  Thread& operator=(Thread&& other) noexcept {
    if (this != &other) {
      stop_and_join();
      swap(other);
    }
    return *this;
  }
  Thread(const Thread&) = delete;
  Thread& operator=(const Thread&) = delete;
  ~Thread() { stop_and_join(); }

  [[nodiscard]] bool joinable() const noexcept { return running_; }
  /// Waits for the thread's function to return.
  void join() noexcept;
  bool request_stop() noexcept { return stop_.request_stop(); }

 private:
  void start(std::function<void()> fn);
  void stop_and_join() noexcept {
    if (!running_) return;
    stop_.request_stop();
    join();
  }
  void swap(Thread& o) noexcept {
    std::swap(stop_, o.stop_);
    std::swap(handle_, o.handle_);
    std::swap(running_, o.running_);
  }
  std::stop_source stop_;
  pthread_t handle_{};
  bool running_ = false;
};

}  // namespace rwcalc
