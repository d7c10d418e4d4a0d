#pragma once
// Work split over threads, for loops whose iterations are independent (the
// signed distances of many points): every iteration computes the same value
// whatever the number of threads, so results do not depend on --threads.
// One process-wide thread count, set from --threads.
#include <cstddef>
#include <functional>

namespace articula {

/// Threads parallelFor may use (>= 1); 0 or less means every hardware thread.
void setWorkerThreads(int threads);
int workerThreads();

/// Calls body(begin, end) on contiguous ranges covering [0, n), on up to
/// workerThreads() threads, each range at least `min_chunk` long (a small n
/// runs on the calling thread). The first exception thrown by a range is
/// rethrown here after every thread has finished.
void parallelFor(std::ptrdiff_t n, std::ptrdiff_t min_chunk,
                 const std::function<void(std::ptrdiff_t begin, std::ptrdiff_t end)>& body);

}  // namespace articula
