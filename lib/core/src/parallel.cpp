#include "articula/core/parallel.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace articula {

namespace {
std::atomic<int> configured_threads{0};
}

void setWorkerThreads(int threads) { configured_threads = std::max(threads, 0); }

int workerThreads() {
  const int n = configured_threads;
  if (n > 0) return n;
  return static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

void parallelFor(std::ptrdiff_t n, std::ptrdiff_t min_chunk,
                 const std::function<void(std::ptrdiff_t begin, std::ptrdiff_t end)>& body) {
  if (n <= 0) return;
  const std::ptrdiff_t by_size = n / std::max<std::ptrdiff_t>(min_chunk, 1);
  const std::ptrdiff_t parts = std::clamp<std::ptrdiff_t>(by_size, 1, workerThreads());
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
  std::vector<std::thread> threads;
  for (std::ptrdiff_t k = 1; k < parts; ++k) threads.emplace_back(run, n * k / parts, n * (k + 1) / parts);
  run(0, n / parts);
  for (auto& t : threads) t.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace articula
