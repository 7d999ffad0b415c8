// A minimal parallel-for on std::threads for vocabulary training and feature extraction.
// (Plain threads rather than TBB so that ThreadSanitizer sees every synchronisation: Debian's
// TBB is not instrumented and makes TSan report its own internals.)
#pragma once

#include <cstddef>
#include <functional>

namespace pkslam::bow_internal {

// Worker threads to use for `requested` (0 = one per hardware thread); at least 1.
int ResolveThreadCount(int requested);

// Calls fn(i) for every i in [0, n) on up to `threads` threads (the calling thread is one of
// them), handing out indices in increasing order, and returns when all calls have returned.
// fn must be safe to call concurrently for different i. If calls throw, the exception of the
// lowest index is rethrown after all threads have stopped (remaining indices are skipped).
void ParallelFor(std::size_t n, int threads, const std::function<void(std::size_t)>& fn);

}  // namespace pkslam::bow_internal
