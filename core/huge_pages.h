#pragma once
// Memory for large arrays read at scattered places (the TSDF's voxels): backed by 2 MiB pages
// where the system allows it, so that each page the processor's address cache (TLB) holds
// covers 512 times as much. A 134 MB voxel cube in 4 KiB pages misses that cache on nearly
// every voxel an integration or a raycast touches.

#include <cstddef>
#include <new>

namespace ihs {

/// Allocations of at least this many bytes are aligned to it and offered huge pages.
inline constexpr std::size_t kHugePageBytes = std::size_t{2} << 20;

/// `bytes` of memory; from `kHugePageBytes` up aligned to it and marked for transparent huge
/// pages (Linux's madvise; elsewhere, or where the kernel declines, ordinary pages). Throws
/// std::bad_alloc. Free with FreeHugePageMemory.
void* AllocateHugePageMemory(std::size_t bytes);
void FreeHugePageMemory(void* memory) noexcept;

/// A standard allocator over AllocateHugePageMemory, for std::vector.
template <typename T>
struct HugePageAllocator {
  using value_type = T;
  HugePageAllocator() = default;
  template <typename U>
  HugePageAllocator(const HugePageAllocator<U>&) noexcept {}
  T* allocate(std::size_t count) {
    if (count > static_cast<std::size_t>(-1) / sizeof(T)) throw std::bad_array_new_length();
    return static_cast<T*>(AllocateHugePageMemory(count * sizeof(T)));
  }
  void deallocate(T* memory, std::size_t) noexcept { FreeHugePageMemory(memory); }
  template <typename U>
  bool operator==(const HugePageAllocator<U>&) const noexcept {
    return true;
  }
};

}  // namespace ihs
