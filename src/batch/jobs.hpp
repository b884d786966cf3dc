// Independent cases, `jobs` at a time: worker threads take the next index until all are done.
// Used by `fracflow sweep` (each case a child process) and `validate-saturated --jobs` (each case
// run in this process).
#pragma once
#include <algorithm>
#include <atomic>
#include <cstddef>
#include <thread>
#include <vector>

namespace ff::batch {

// Calls fn(i) once for every i in [0, n), from min(jobs, n) threads (jobs < 1 counts as 1). fn must
// not throw (catch inside and record the failure per case).
template <class Fn>
void run_jobs(std::size_t n, int jobs, Fn fn) {
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t i = next++; i < n; i = next++) fn(i);
  };
  const std::size_t threads = std::min<std::size_t>(std::size_t(std::max(jobs, 1)), n);
  std::vector<std::thread> pool;
  for (std::size_t t = 0; t < threads; ++t) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
}

}  // namespace ff::batch
