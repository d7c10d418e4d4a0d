#include "articula/core/parallel.hpp"

#include <algorithm>
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
  const std::ptrdiff_t by_size = n / std::max<std::ptrdiff_t>(min_chunk, 1);
  const std::ptrdiff_t parts = std::clamp<std::ptrdiff_t>(by_size, 1, resolveThreads(threads));
  if (parts == 1) {
    body(0, n);
    return;
  }
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto run = [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
    try {
      body(begin, end);
    } catch (...) {
      std::lock_guard<std::mutex> lock(failure_mutex);
      if (!failure) failure = std::current_exception();
    }
  };
  std::vector<std::thread> workers;
  for (std::ptrdiff_t k = 1; k < parts; ++k) workers.emplace_back(run, n * k / parts, n * (k + 1) / parts);
  run(0, n / parts);
  for (auto& t : workers) t.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace articula
