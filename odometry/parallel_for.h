#pragma once
// Runs fn(i) for i in [0, n) on up to num_threads threads (0 = all cores). Used where work splits
// into independent runs: loading run files, evaluating per-run costs. Exceptions are collected and
// the one with the lowest index is rethrown after all threads have joined, so errors come out in
// the same order as in a sequential loop.

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <thread>
#include <vector>

namespace fitcal {

inline int ResolveThreadCount(int num_threads) {
  if (num_threads > 0) return num_threads;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw == 0 ? 1 : static_cast<int>(hw);
}

template <typename Fn>
void ParallelFor(std::size_t n, int num_threads, Fn&& fn) {
  const std::size_t threads =
      std::min<std::size_t>(n, static_cast<std::size_t>(ResolveThreadCount(num_threads)));
  if (threads <= 1) {
    for (std::size_t i = 0; i < n; ++i) fn(i);
    return;
  }
  std::atomic<std::size_t> next{0};
  std::vector<std::exception_ptr> errors(n);
  auto worker = [&]() {
    for (std::size_t i = next++; i < n; i = next++) {
      try {
        fn(i);
      } catch (...) {
        errors[i] = std::current_exception();
      }
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(threads - 1);
  for (std::size_t t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (auto& thread : pool) thread.join();
  for (const auto& error : errors) {
    if (error) std::rethrow_exception(error);
  }
}

}  // namespace fitcal
