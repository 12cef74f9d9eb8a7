// Memory for large scattered-access arrays: aligned to huge pages from their size up, ordinary
// below, usable through std::vector.

#include "core/huge_pages.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

namespace ihs {
namespace {

TEST(HugePagesTest, LargeBlocksAreAlignedToAHugePage) {
  for (std::size_t bytes : {kHugePageBytes, kHugePageBytes + 1, 5 * kHugePageBytes + 17}) {
    void* memory = AllocateHugePageMemory(bytes);
    ASSERT_NE(memory, nullptr);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(memory) % kHugePageBytes, 0u) << bytes;
    static_cast<unsigned char*>(memory)[bytes - 1] = 1;  // The whole size is usable.
    FreeHugePageMemory(memory);
  }
  void* small = AllocateHugePageMemory(100);
  ASSERT_NE(small, nullptr);
  FreeHugePageMemory(small);
}

TEST(HugePagesTest, AVectorKeepsItsValues) {
  std::vector<std::uint64_t, HugePageAllocator<std::uint64_t>> values(3 * kHugePageBytes / 8, 7);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(values.data()) % kHugePageBytes, 0u);
  values.back() = 9;
  EXPECT_EQ(values.front(), 7u);
  EXPECT_EQ(values.back(), 9u);
  values.resize(10);
  EXPECT_EQ(values[9], 7u);
}

}  // namespace
}  // namespace ihs
