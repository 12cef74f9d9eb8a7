// ParallelRuns: a loop's range split into runs on worker threads, every index once, the split
// independent of timing, a run's exception rethrown.

#include "core/parallel_runs.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <mutex>
#include <stdexcept>
#include <utility>
#include <vector>

namespace ihs {
namespace {

TEST(ParallelRunsTest, EveryIndexIsRunOnceInContiguousRuns) {
  for (int threads : {1, 2, 3, 8}) {
    for (std::size_t count : {0u, 1u, 2u, 5u, 1000u}) {
      std::vector<std::atomic<int>> seen(count);
      std::mutex mutex;
      std::vector<std::pair<std::size_t, std::size_t>> runs;
      ParallelRuns(count, threads, [&](std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) ++seen[i];
        std::lock_guard<std::mutex> lock(mutex);
        runs.emplace_back(begin, end);
      });
      for (std::size_t i = 0; i < count; ++i) EXPECT_EQ(seen[i], 1) << i;
      EXPECT_LE(runs.size(), static_cast<std::size_t>(threads));
      if (count > 0) {
        EXPECT_EQ(runs.size(), std::min<std::size_t>(count, threads));
      }
      for (const auto& [begin, end] : runs) EXPECT_LT(begin, end);
    }
  }
}

TEST(ParallelRunsTest, TheSplitDependsOnlyOnTheCountAndTheThreads) {
  auto split = [](std::size_t count, int threads) {
    std::mutex mutex;
    std::vector<std::pair<std::size_t, std::size_t>> runs;
    ParallelRuns(count, threads, [&](std::size_t begin, std::size_t end) {
      std::lock_guard<std::mutex> lock(mutex);
      runs.emplace_back(begin, end);
    });
    std::sort(runs.begin(), runs.end());
    return runs;
  };
  const auto first = split(101, 4);
  EXPECT_EQ(split(101, 4), first);
  ASSERT_EQ(first.size(), 4u);
  EXPECT_EQ(first.front().first, 0u);
  EXPECT_EQ(first.back().second, 101u);
  for (std::size_t r = 1; r < first.size(); ++r) EXPECT_EQ(first[r].first, first[r - 1].second);
}

TEST(ParallelRunsTest, ARunsExceptionIsRethrownAfterAllRuns) {
  std::atomic<int> finished{0};
  EXPECT_THROW(ParallelRuns(8, 4,
                            [&](std::size_t begin, std::size_t) {
                              if (begin == 4) throw std::runtime_error("run failed");
                              ++finished;
                            }),
               std::runtime_error);
  EXPECT_EQ(finished, 3);
}

TEST(ParallelRunsTest, ZeroThreadsMeansOnePerCore) {
  EXPECT_GE(ThreadsFor(0), 1);
  EXPECT_EQ(ThreadsFor(3), 3);
}

}  // namespace
}  // namespace ihs
