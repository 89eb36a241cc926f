#include "adit/daemon/allocator.hpp"

#ifdef __GLIBC__
#include <malloc.h>
#endif

#include <climits>

namespace adit::daemon {

bool keep_large_blocks_mmapped(std::size_t threshold_bytes) {
#ifdef __GLIBC__
  if (threshold_bytes > static_cast<std::size_t>(INT_MAX)) return false;
  return mallopt(M_MMAP_THRESHOLD, static_cast<int>(threshold_bytes)) == 1;
#else
  (void)threshold_bytes;
  return false;
#endif
}

void return_free_pages() {
#ifdef __GLIBC__
  malloc_trim(0);
#endif
}

}  // namespace adit::daemon
