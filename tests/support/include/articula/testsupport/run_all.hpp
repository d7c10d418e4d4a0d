#pragma once
// Independent cases of a benchmark over threads, each case on one thread
// (each fit single-threaded inside it): the next free thread takes the next case.
#include <atomic>
#include <thread>
#include <vector>

namespace articula::testsupport {

/// Runs `work(i)` for i in [0, n) on `jobs` threads.
template <class Work>
void runAll(int n, int jobs, Work work) {
  std::atomic<int> next{0};
  std::vector<std::thread> threads;
  for (int j = 0; j < jobs; ++j)
    threads.emplace_back([&] {
      for (int i = next++; i < n; i = next++) work(i);
    });
  for (auto& t : threads) t.join();
}

}  // namespace articula::testsupport
