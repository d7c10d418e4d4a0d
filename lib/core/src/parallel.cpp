#include "articula/core/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace articula {

int hardwareThreads() { return static_cast<int>(std::max(1u, std::thread::hardware_concurrency())); }

int resolveThreads(int threads) { return threads > 0 ? threads : hardwareThreads(); }

void parallelFor(std::ptrdiff_t n, std::ptrdiff_t min_chunk, int threads,
                 const std::function<void(std::ptrdiff_t begin, std::ptrdiff_t end)>& body) {
  if (n <= 0) return;
  const std::ptrdiff_t chunk_floor = std::max<std::ptrdiff_t>(min_chunk, 1);
  const std::ptrdiff_t parts = std::clamp<std::ptrdiff_t>(n / chunk_floor, 1, resolveThreads(threads));
  if (parts == 1) {
    body(0, n);
    return;
  }
  // Ranges handed out in turn, several per thread: iterations cost unevenly
  // (a profile with a socket in it, a vertex the caller skips), and equal
  // shares of the range left one thread idle for a third of the mesh stage.
  // Each iteration is computed alone, so the split changes no result.
  constexpr std::ptrdiff_t kRangesPerThread = 16;
  const std::ptrdiff_t chunk = std::max(chunk_floor, (n + parts * kRangesPerThread - 1) / (parts * kRangesPerThread));
  std::atomic<std::ptrdiff_t> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto run = [&] {
    try {
      for (std::ptrdiff_t begin = next.fetch_add(chunk); begin < n; begin = next.fetch_add(chunk))
        body(begin, std::min(n, begin + chunk));
    } catch (...) {
      std::lock_guard<std::mutex> lock(failure_mutex);
      if (!failure) failure = std::current_exception();
      next = n;  // the others stop at their range's end
    }
  };
  std::vector<std::thread> workers;
  for (std::ptrdiff_t k = 1; k < parts; ++k) workers.emplace_back(run);
  run();
  for (auto& t : workers) t.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace articula
