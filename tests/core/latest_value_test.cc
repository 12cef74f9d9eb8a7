#include "core/latest_value.h"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

namespace ihs {
namespace {

TEST(LatestValueTest, TakeReturnsTheNewestValueOnce) {
  LatestValue<int> box;
  EXPECT_FALSE(box.Take().has_value());
  box.Put(1);
  box.Put(2);
  EXPECT_EQ(box.version(), 2u);
  EXPECT_EQ(box.overwritten(), 1u);
  EXPECT_EQ(box.Peek().value(), 2);
  EXPECT_EQ(box.Take().value(), 2);
  EXPECT_FALSE(box.Take().has_value());
}

TEST(LatestValueTest, ReaderSeesNonDecreasingValuesWhileAWriterPuts) {
  LatestValue<int> box;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (int i = 1; i <= 100000; ++i) box.Put(i);
    done = true;
  });
  int last = 0, taken = 0;
  while (!done || box.Peek()) {
    if (auto value = box.Take()) {
      EXPECT_GT(*value, last);
      last = *value;
      ++taken;
    }
  }
  writer.join();
  EXPECT_EQ(last, 100000);
  EXPECT_EQ(box.overwritten() + taken, 100000u);
}

}  // namespace
}  // namespace ihs
