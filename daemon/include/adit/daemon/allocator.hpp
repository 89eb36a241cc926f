#pragma once
// How the daemon asks glibc's malloc to give large blocks back.

#include <cstddef>

namespace adit::daemon {

// The mapping thread's tile work (compaction, eviction, reload, and in aditd
// the tiles handed to the publisher) allocates a whole tile at a time: 10 to
// 50 MB for a crowded 20 m tile, a few times a minute. glibc serves blocks
// from M_MMAP_THRESHOLD up with mmap and unmaps them on free, but its
// threshold starts at 128 KiB and rises to the size of every mmapped block
// freed (up to 32 MiB): after the first large tile, the next ones come from
// the thread's arena, which keeps their pages, fragments, and grows with the
// largest tile of the session. Setting the threshold fixes it (mallopt turns
// the dynamic rise off), so such blocks stay mmapped and leave RSS on free.
// 1 MiB stays above what the odometry's scans need (VLP-16: ~0.5 MB), which
// come from pools anyway. Process-wide: call once at start. Returns false
// where it cannot be set (not glibc, or mallopt refused).
bool keep_large_blocks_mmapped(std::size_t threshold_bytes = std::size_t{1} << 20);

// Gives the free pages of every arena back to the kernel (glibc's
// malloc_trim(0)); a thread's arena otherwise returns memory only from its
// top, so the high-water mark of a burst of small blocks (a tile evicted, a
// pose-graph solve) stays resident. It walks the heap: call it after such a
// burst, never per item. Does nothing where malloc is not glibc's.
void return_free_pages();

}  // namespace adit::daemon
