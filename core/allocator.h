#pragma once
// How the C library's allocator treats freed memory, for programs that process frame after frame.

namespace ihs {

/// Asks the allocator to keep freed memory for reuse rather than hand it back to the system.
/// Every frame allocates and frees buffers of up to a few megabytes (images, masks, feature
/// pyramids); glibc returns them to the system and the next frame then pays a page fault per
/// 4 KiB page: on 150 bowling-pin frames (`inhandscan-scan`) that cost 1.5 ms of tracking, 1 ms of
/// masking and 3.5 ms of feature matching per frame. The memory kept is what the process needed at
/// its peak anyway. Call it first thing in main(); with another C library it does nothing.
void KeepFreedMemoryForReuse();

}  // namespace ihs
