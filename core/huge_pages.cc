#include "core/huge_pages.h"

#include <cstdlib>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace ihs {

void* AllocateHugePageMemory(std::size_t bytes) {
  if (bytes < kHugePageBytes) {
    void* memory = std::malloc(bytes == 0 ? 1 : bytes);
    if (memory == nullptr) throw std::bad_alloc();
    return memory;
  }
  // aligned_alloc wants a multiple of the alignment.
  const std::size_t rounded = (bytes + kHugePageBytes - 1) / kHugePageBytes * kHugePageBytes;
  void* memory = std::aligned_alloc(kHugePageBytes, rounded);
  if (memory == nullptr) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  // Before the first write, so that the pages are faulted in large; a refusal (huge pages
  // disabled) leaves ordinary ones.
  madvise(memory, rounded, MADV_HUGEPAGE);
#endif
  return memory;
}

void FreeHugePageMemory(void* memory) noexcept { std::free(memory); }

}  // namespace ihs
