#include "core/allocator.h"

#include <gtest/gtest.h>

#include <cstddef>
#include <vector>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace ihs {
namespace {

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kOwnAllocator = true;  // The sanitizers bring their own allocator.
#else
constexpr bool kOwnAllocator = false;
#endif

// A freed frame-sized buffer stays in the heap (glibc alone would have mapped it on its own and
// handed it back to the system on free).
TEST(AllocatorTest, AFreedFrameSizedBufferStaysInTheHeap) {
#if defined(__GLIBC__)
  if (kOwnAllocator) GTEST_SKIP() << "a sanitizer's allocator is in charge";
  KeepFreedMemoryForReuse();
  constexpr std::size_t kBytes = 6 << 20;  // An RGB-D frame's raycast: 640 × 480 × 20 bytes.
  const std::size_t before = mallinfo2().fordblks;
  {
    std::vector<char> buffer(kBytes, 1);
    volatile char sink = buffer[kBytes / 2];
    (void)sink;
    EXPECT_EQ(mallinfo2().hblkhd, 0u) << "the buffer was mapped on its own";
  }
  EXPECT_GE(mallinfo2().fordblks, before + kBytes);
#else
  GTEST_SKIP() << "not glibc";
#endif
}

}  // namespace
}  // namespace ihs
