#include "core/allocator.h"

#include <cstdlib>  // Defines __GLIBC__ where it is glibc.

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace ihs {

void KeepFreedMemoryForReuse() {
#if defined(__GLIBC__)
  // Blocks below 32 MiB (glibc's largest threshold on 64-bit systems) come from the heap; a TSDF
  // of 256³ voxels (134 MB) is still mapped on its own. The heap's free top is kept up to
  // 512 MiB instead of 128 KiB.
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 512 << 20);
#endif
}

}  // namespace ihs
