#pragma once
/// @file crew.hpp
/// Threads lent to parallel loops. A loop run through Crew::share() is done by its calling thread
/// and by every lender that is free now or becomes free before the loop's chunks run out; with no
/// lender the calling thread does it all. `rwcalc batch` lends each worker that has no file left
/// to the analyses still running, so the last runs take up the cores as they free, and no core is
/// ever given two threads (a run started on a fixed number of threads while another still holds
/// a core would share that core). The loops that take a crew split their work into chunks whose
/// results are combined exactly (integer sums, minima), so the results do not depend on who ran
/// which chunk.
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <memory>
#include <mutex>
#include <vector>

#include "rwcalc/thread.hpp"

namespace rwcalc {

class Crew {
  struct Job;

 public:
  Crew() = default;
  Crew(const Crew&) = delete;
  Crew& operator=(const Crew&) = delete;
  ~Crew() = default;

  /// fn(c) for every chunk c in [0, chunks), each exactly once, on this thread and on lenders;
  /// returns when all have run. The first exception a chunk throws is rethrown here (chunks not
  /// yet started are then skipped).
  void share(std::size_t chunks, const std::function<void(std::size_t)>& fn);

  /// The same in two steps: post() offers the chunks to the lenders at once and returns, so the
  /// calling thread can do other work meanwhile; join() then runs the chunks nobody has taken and
  /// waits for the others (and rethrows as share() does). `fn` must live until join() returns; a
  /// Posted destroyed unjoined (an exception on the way) joins in its destructor, dropping the
  /// loop's own exception.
  class Posted {
   public:
    Posted(Posted&&) noexcept;
    Posted& operator=(Posted&&) = delete;
    ~Posted();

   private:
    friend class Crew;
    Posted(Crew* crew, std::unique_ptr<Job> job);
    Crew* crew_ = nullptr;
    std::unique_ptr<Job> job_;
  };
  [[nodiscard]] Posted post(std::size_t chunks, const std::function<void(std::size_t)>& fn);
  void join(Posted& posted);

  /// Lend the calling thread: it runs chunks of the loops under way until close().
  void lend();

  /// Release the lenders (once no share() is under way or will be).
  void close();

 private:
  void run(Job& job);
  std::mutex mu_;
  std::condition_variable cv_;
  std::vector<Job*> jobs_;
  bool closed_ = false;
};

/// A crew with threads of its own, lent to it from construction to destruction: the helper
/// threads of one command, started once (a thread that sleeps between loops wakes on the core it
/// ran on, where a thread started for each loop may first wait on its creator's core). For a
/// budget of `threads` threads in all (0: the hardware's), the calling thread one of them, so
/// `threads` − 1 of its own; get() is the crew, or null when that leaves none.
class OwnCrew {
 public:
  explicit OwnCrew(unsigned threads);
  ~OwnCrew();
  OwnCrew(const OwnCrew&) = delete;
  OwnCrew& operator=(const OwnCrew&) = delete;
  [[nodiscard]] Crew* get() noexcept { return threads_.empty() ? nullptr : &crew_; }

 private:
  Crew crew_;
  std::vector<Thread> threads_;
};

}  // namespace rwcalc
