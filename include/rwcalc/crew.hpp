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
#include <mutex>
#include <vector>

namespace rwcalc {

class Crew {
 public:
  Crew() = default;
  Crew(const Crew&) = delete;
  Crew& operator=(const Crew&) = delete;
  ~Crew() = default;

  /// fn(c) for every chunk c in [0, chunks), each exactly once, on this thread and on lenders;
  /// returns when all have run. The first exception a chunk throws is rethrown here (chunks not
  /// yet started are then skipped).
  void share(std::size_t chunks, const std::function<void(std::size_t)>& fn);

  /// Lend the calling thread: it runs chunks of the loops under way until close().
  void lend();

  /// Release the lenders (once no share() is under way or will be).
  void close();

 private:
  struct Job;
  void run(Job& job);
  std::mutex mu_;
  std::condition_variable cv_;
  std::vector<Job*> jobs_;
  bool closed_ = false;
};

}  // namespace rwcalc
