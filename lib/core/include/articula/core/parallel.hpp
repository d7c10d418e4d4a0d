#pragma once
// Work split over threads, for loops whose iterations are independent (the
// signed distances of many points): every iteration computes the same value
// whatever the number of threads, so results do not depend on --threads.
// The thread count travels with the work (an options struct's `threads`, as
// Ceres's Solver::Options::num_threads), not in a process-wide setting.
#include <cstddef>
#include <functional>

namespace articula {

/// The machine's hardware threads (>= 1).
int hardwareThreads();

/// `threads` where positive, else every hardware thread.
int resolveThreads(int threads);

/// Calls body(begin, end) on contiguous ranges covering [0, n), on up to
/// `threads` threads (0: every hardware thread), each range at least
/// `min_chunk` long (a small n runs on the calling thread). The first
/// exception thrown by a range is rethrown here after every thread has
/// finished.
void parallelFor(std::ptrdiff_t n, std::ptrdiff_t min_chunk, int threads,
                 const std::function<void(std::ptrdiff_t begin, std::ptrdiff_t end)>& body);

}  // namespace articula
