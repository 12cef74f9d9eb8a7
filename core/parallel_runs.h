#pragma once
// Data parallelism inside one call of a stage: a loop's range split into contiguous runs, each
// run on a worker thread that lives only for the call (joined before it returns). The
// pipeline's threads stay the only long-lived ones; this is for a rare heavy step (the hand
// tracker's global search, 0.6 s) during which the pipeline's other thread has nothing to do.

#include <cstddef>
#include <functional>

namespace ihs {

/// Calls `run(begin, end)` on contiguous runs that together cover [0, `count`) once, on up to
/// `threads` threads (0: one per core; the calling thread is one of them). The split depends
/// only on `count` and the number of threads, never on timing. `run` must be safe to call
/// concurrently on different runs. An exception thrown by a run is rethrown here after every
/// run has finished. Where no thread can be started, its run is done on the calling thread.
void ParallelRuns(std::size_t count, int threads,
                  const std::function<void(std::size_t, std::size_t)>& run);

/// The threads ParallelRuns uses for `threads` (0: the cores the system reports, at least 1).
int ThreadsFor(int threads);

}  // namespace ihs
