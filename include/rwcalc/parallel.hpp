#pragma once
/// @file parallel.hpp
/// The one place where rwcalc starts threads. Every parallel loop of the library is a
/// parallel_for over independent items whose results are kept per item and combined in item
/// order afterwards, so a result never depends on the number of threads or on who ran what.
#include <cstddef>
#include <functional>

namespace rwcalc {

/// fn(i) for every i in [0, n), each exactly once, on up to worker_count() threads (the calling
/// thread is one of them); returns when all have run. The first exception thrown is rethrown here
/// (items not yet started are then skipped). A parallel_for inside another one runs its items on
/// the calling thread: the outer loop already has the cores busy.
void parallel_for(std::size_t n, const std::function<void(std::size_t)>& fn);

/// main() on this thread while beside() runs on another (a two-stage pipeline: the next piece of a
/// file read while this one is parsed); returns when both have run. main may use parallel_for.
/// main's exception is rethrown before beside's. With one worker (RWCALC_THREADS=1) or inside a
/// parallel_for's items, main then beside on this thread.
void run_beside(const std::function<void()>& main, const std::function<void()>& beside);

/// Threads a parallel_for may use: RWCALC_THREADS from the environment when set to a whole number
/// from 1 to 4096 (tests use it to show that results do not depend on it), else the hardware's.
unsigned worker_count();

/// True on a thread while it runs items of a parallel_for that uses several threads (a Progress
/// made there shows nothing: the items' lines would overwrite each other).
[[nodiscard]] bool inside_parallel_items() noexcept;

}  // namespace rwcalc
