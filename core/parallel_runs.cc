#include "core/parallel_runs.h"

#include <algorithm>
#include <exception>
#include <system_error>
#include <thread>
#include <vector>

namespace ihs {

int ThreadsFor(int threads) {
  if (threads > 0) return threads;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

void ParallelRuns(std::size_t count, int threads,
                  const std::function<void(std::size_t, std::size_t)>& run) {
  const std::size_t runs =
      std::min<std::size_t>(count, static_cast<std::size_t>(ThreadsFor(threads)));
  if (runs <= 1) {
    if (count > 0) run(0, count);
    return;
  }
  std::vector<std::exception_ptr> errors(runs);
  auto body = [&](std::size_t r) {
    try {
      run(count * r / runs, count * (r + 1) / runs);
    } catch (...) {
      errors[r] = std::current_exception();
    }
  };
  std::vector<std::thread> workers;
  workers.reserve(runs - 1);
  for (std::size_t r = 1; r < runs; ++r) {
    try {
      workers.emplace_back(body, r);
    } catch (const std::system_error&) {
      body(r);  // No thread to be had (the system's limit): the run is done here instead.
    }
  }
  body(0);
  for (std::thread& worker : workers) worker.join();
  for (const std::exception_ptr& error : errors) {
    if (error) std::rethrow_exception(error);
  }
}

}  // namespace ihs
