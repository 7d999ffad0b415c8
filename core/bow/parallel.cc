#include "core/bow/parallel.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace pkslam::bow_internal {

int ResolveThreadCount(int requested) {
  if (requested > 0) return requested;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

void ParallelFor(std::size_t n, int threads, const std::function<void(std::size_t)>& fn) {
  if (n == 0) return;
  const auto workers = static_cast<std::size_t>(std::max(1, threads));
  if (workers == 1 || n == 1) {
    for (std::size_t i = 0; i < n; ++i) fn(i);
    return;
  }
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::mutex error_mutex;  // guards error and error_index
  std::exception_ptr error;
  std::size_t error_index = n;
  // Every index handed out is run, and indices go out in increasing order: so all indices
  // below a failing one run, and the lowest failing index is always the one reported.
  const auto run = [&] {
    while (!failed) {
      const std::size_t i = next++;
      if (i >= n) break;
      try {
        fn(i);
      } catch (...) {
        std::lock_guard lock(error_mutex);
        if (i < error_index) {
          error_index = i;
          error = std::current_exception();
        }
        failed = true;
      }
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(std::min(workers, n) - 1);
  for (std::size_t t = 1; t < std::min(workers, n); ++t) pool.emplace_back(run);
  run();
  for (std::thread& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace pkslam::bow_internal
