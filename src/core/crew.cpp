// Threads lent to parallel loops (see crew.hpp).
#include "rwcalc/crew.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <memory>
#include <thread>

namespace rwcalc {

struct Crew::Job {
  std::size_t chunks = 0;
  const std::function<void(std::size_t)>* fn = nullptr;
  std::atomic<std::size_t> next{0};
  std::size_t users = 0;  ///< lenders inside run(), guarded by the crew's mutex
  std::mutex error_mu;
  std::exception_ptr error;
};

void Crew::run(Job& job) {
  for (std::size_t c = job.next++; c < job.chunks; c = job.next++) {
    try {
      (*job.fn)(c);
    } catch (...) {
      const std::lock_guard lock(job.error_mu);
      if (!job.error) job.error = std::current_exception();
      job.next = job.chunks;  // start no more chunks
    }
  }
}

Crew::Posted::Posted(Crew* crew, std::unique_ptr<Job> job) : crew_(crew), job_(std::move(job)) {}
Crew::Posted::Posted(Posted&&) noexcept = default;
Crew::Posted::~Posted() {
  if (!job_) return;
  try {
    crew_->join(*this);
  } catch (...) {  // the loop's exception: whoever destroys an unjoined loop is already unwinding
  }
}

Crew::Posted Crew::post(std::size_t chunks, const std::function<void(std::size_t)>& fn) {
  auto job = std::make_unique<Job>();
  job->chunks = chunks;
  job->fn = &fn;
  if (chunks > 1) {
    {
      const std::lock_guard lock(mu_);
      jobs_.push_back(job.get());
    }
    cv_.notify_all();
  }
  return Posted(this, std::move(job));
}

void Crew::join(Posted& posted) {
  if (!posted.job_) return;
  Job& job = *posted.job_;
  run(job);
  if (job.chunks > 1) {
    std::unique_lock lock(mu_);
    std::erase(jobs_, &job);
    // Lenders that took chunks finish them before they leave run().
    cv_.wait(lock, [&job] { return job.users == 0; });
  }
  const std::exception_ptr error = job.error;
  posted.job_.reset();
  if (error) std::rethrow_exception(error);
}

void Crew::share(std::size_t chunks, const std::function<void(std::size_t)>& fn) {
  if (chunks == 0) return;
  Posted p = post(chunks, fn);
  join(p);
}

void Crew::lend() {
  std::unique_lock lock(mu_);
  for (;;) {
    Job* job = nullptr;
    cv_.wait(lock, [&] {
      if (closed_) return true;
      const auto it = std::find_if(jobs_.begin(), jobs_.end(), [](Job* j) { return j->next < j->chunks; });
      if (it == jobs_.end()) return false;
      job = *it;
      return true;
    });
    if (!job) return;  // closed
    ++job->users;
    lock.unlock();
    run(*job);
    lock.lock();
    --job->users;
    if (job->users == 0) cv_.notify_all();
  }
}

void Crew::close() {
  {
    const std::lock_guard lock(mu_);
    closed_ = true;
  }
  cv_.notify_all();
}

}  // namespace rwcalc

namespace rwcalc {

OwnCrew::OwnCrew(unsigned threads) {
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  threads_.reserve(threads - 1);
  for (unsigned i = 1; i < threads; ++i) threads_.emplace_back([this] { crew_.lend(); });
}

OwnCrew::~OwnCrew() {
  crew_.close();
  threads_.clear();  // joins
}

}  // namespace rwcalc
