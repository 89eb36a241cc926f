// keep_large_blocks_mmapped: after a large block was freed (which raises
// glibc's dynamic mmap threshold to its size), the next large block is still
// mmapped, so freeing it gives its pages back to the kernel.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#ifdef __GLIBC__
#include <malloc.h>
#endif

#include "adit/daemon/allocator.hpp"

namespace adit::daemon {
namespace {

#if defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 33))
// Keeps the compiler from eliding an allocation it can see is unused.
void escape(const void* p) { asm volatile("" : : "g"(p) : "memory"); }

std::size_t mmapped_bytes() { return mallinfo2().hblkhd; }

// The address and thread sanitizers replace malloc with their own allocator,
// which ignores mallopt (aditd then logs that it cannot fix the threshold).
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
constexpr bool kSanitizedMalloc = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
constexpr bool kSanitizedMalloc = true;
#else
constexpr bool kSanitizedMalloc = false;
#endif
#else
constexpr bool kSanitizedMalloc = false;
#endif

TEST(Allocator, ALargeBlockStaysMmappedAfterALargerOneWasFreed) {
  if (kSanitizedMalloc) GTEST_SKIP() << "a sanitizer's allocator replaces glibc's malloc: no mmap threshold to fix";
  ASSERT_TRUE(keep_large_blocks_mmapped());
  {
    std::vector<std::uint8_t> big(16u << 20, 1);  // a crowded tile's samples (glibc raises its threshold up to 32 MiB)
    escape(big.data());
  }
  const std::size_t before = mmapped_bytes();
  std::vector<std::uint8_t> next(4u << 20, 2);
  escape(next.data());
  EXPECT_GE(mmapped_bytes(), before + (4u << 20)) << "the 4 MiB block came from an arena, not from mmap";
}
#endif

}  // namespace
}  // namespace adit::daemon
