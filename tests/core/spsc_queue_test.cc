#include "core/spsc_queue.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <future>
#include <memory>
#include <thread>
#include <vector>

namespace ihs {
namespace {

using namespace std::chrono_literals;

TEST(SpscQueueTest, PassesOneMillionItemsInOrderBetweenTwoThreads) {
  constexpr std::int64_t kCount = 1'000'000;
  SpscQueue<std::int64_t> queue(64);
  std::thread producer([&] {
    for (std::int64_t i = 0; i < kCount; ++i) ASSERT_TRUE(queue.Push(i));
    queue.Close();
  });
  std::int64_t expected = 0;
  std::int64_t value = -1;
  while (queue.Pop(value) == PopStatus::kItem) {
    ASSERT_EQ(value, expected);
    ++expected;
  }
  producer.join();
  EXPECT_EQ(expected, kCount);
  EXPECT_EQ(queue.Pop(value, 1ms), PopStatus::kClosed);
}

TEST(SpscQueueTest, TryPushFailsWhenFullAndLeavesQueuedItemsIntact) {
  SpscQueue<int> queue(3);
  EXPECT_EQ(queue.capacity(), 3u);
  int dropped = 0;
  for (int i = 0; i < 5; ++i) {
    if (!queue.TryPush(i)) ++dropped;
  }
  EXPECT_EQ(dropped, 2);
  EXPECT_EQ(queue.SizeApprox(), 3u);
  int value = -1;
  for (int i = 0; i < 3; ++i) {
    ASSERT_EQ(queue.Pop(value, 0us), PopStatus::kItem);
    EXPECT_EQ(value, i);
  }
  EXPECT_EQ(queue.Pop(value, 0us), PopStatus::kTimeout);
}

TEST(SpscQueueTest, PopTimesOutOnAnOpenEmptyQueue) {
  SpscQueue<int> queue(4);
  int value = 0;
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(queue.Pop(value, 20ms), PopStatus::kTimeout);
  EXPECT_GE(std::chrono::steady_clock::now() - start, 19ms);
}

TEST(SpscQueueTest, CloseWakesAConsumerWaitingWithoutLimit) {
  SpscQueue<int> queue(4);
  auto consumer = std::async(std::launch::async, [&] {
    int value = 0;
    return queue.Pop(value);
  });
  EXPECT_EQ(consumer.wait_for(50ms), std::future_status::timeout);  // Really waiting.
  queue.Close();
  ASSERT_EQ(consumer.wait_for(2s), std::future_status::ready);
  EXPECT_EQ(consumer.get(), PopStatus::kClosed);
}

TEST(SpscQueueTest, ConsumerDrainsQueuedItemsAfterCloseEvenWhenFull) {
  SpscQueue<int> queue(2);
  ASSERT_TRUE(queue.Push(1));
  ASSERT_TRUE(queue.Push(2));
  queue.Close();  // Full: the end marker cannot be queued, yet the consumer must end cleanly.
  EXPECT_FALSE(queue.TryPush(3));
  EXPECT_FALSE(queue.Push(3));
  std::optional<int> a = queue.Pop(), b = queue.Pop(), c = queue.Pop();
  ASSERT_TRUE(a && b);
  EXPECT_EQ(*a, 1);
  EXPECT_EQ(*b, 2);
  EXPECT_FALSE(c.has_value());
}

TEST(SpscQueueTest, AbandonReleasesAProducerBlockedOnAFullQueue) {
  SpscQueue<int> queue(1);
  ASSERT_TRUE(queue.Push(0));
  auto producer = std::async(std::launch::async, [&] { return queue.Push(1); });
  EXPECT_EQ(producer.wait_for(50ms), std::future_status::timeout);  // Blocked: queue is full.
  queue.Abandon();
  ASSERT_EQ(producer.wait_for(2s), std::future_status::ready);
  EXPECT_FALSE(producer.get());
  EXPECT_FALSE(queue.Push(2));
  int value = 0;
  EXPECT_EQ(queue.Pop(value, 0us), PopStatus::kClosed);
}

TEST(SpscQueueTest, PopLatestSkipsToTheNewestAndCountsTheSkipped) {
  SpscQueue<int> queue(8);
  for (int i = 0; i < 5; ++i) ASSERT_TRUE(queue.TryPush(i));
  int value = -1;
  std::size_t skipped = 99;
  ASSERT_EQ(queue.PopLatest(value, 0us, &skipped), PopStatus::kItem);
  EXPECT_EQ(value, 4);
  EXPECT_EQ(skipped, 4u);
  EXPECT_EQ(queue.PopLatest(value, 0us, &skipped), PopStatus::kTimeout);
  EXPECT_EQ(skipped, 0u);
  ASSERT_TRUE(queue.TryPush(7));
  queue.Close();
  ASSERT_EQ(queue.PopLatest(value, 0us, &skipped), PopStatus::kItem);
  EXPECT_EQ(value, 7);
  EXPECT_EQ(queue.PopLatest(value, 0us, &skipped), PopStatus::kClosed);
}

TEST(SpscQueueTest, CarriesMoveOnlySharedFramesWithoutCopies) {
  SpscQueue<std::unique_ptr<std::vector<int>>> queue(2);
  auto payload = std::make_unique<std::vector<int>>(1000, 7);
  const int* data = payload->data();
  ASSERT_TRUE(queue.Push(std::move(payload)));
  std::unique_ptr<std::vector<int>> out;
  ASSERT_EQ(queue.Pop(out, 0us), PopStatus::kItem);
  EXPECT_EQ(out->data(), data);
}

TEST(SpscQueueTest, LiveProducerNeverBlocksAndCountsDropsAgainstASlowConsumer) {
  constexpr int kCount = 2000;
  SpscQueue<int> queue(4);
  int dropped = 0;
  std::thread producer([&] {
    for (int i = 0; i < kCount; ++i) {
      if (!queue.TryPush(i)) ++dropped;
    }
    queue.Close();
  });
  int received = 0, last = -1, value = 0;
  while (queue.Pop(value) == PopStatus::kItem) {
    EXPECT_GT(value, last);  // Order is kept even when items are dropped.
    last = value;
    ++received;
    if (received % 16 == 0) std::this_thread::sleep_for(50us);
  }
  producer.join();
  EXPECT_EQ(received + dropped, kCount);
}

TEST(SpscQueueTest, RejectsZeroCapacity) { EXPECT_THROW(SpscQueue<int>(0), std::invalid_argument); }

}  // namespace
}  // namespace ihs
