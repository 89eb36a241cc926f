#pragma once
// Test instrumentation for "allocates nothing per packet/scan" tests. A test
// binary that links adit_allocation_counter (tests/CMakeLists.txt) has every
// replaceable global operator new/delete replaced by malloc/free plus a count.
// Link it only into such a test's own executable: it changes the whole binary.

#include <cstdint>

#include "sanitizers.hpp"

// Sanitizers bring their own operator new; counting is done in plain builds only.
#define ADIT_COUNTING_ALLOCATIONS (!ADIT_SANITIZED)

namespace adit::test {

inline constexpr bool kCountingAllocations = ADIT_COUNTING_ALLOCATIONS != 0;

// Global operator new calls (every form) in this process so far.
std::uint64_t allocations();

}  // namespace adit::test

#define ADIT_REQUIRE_ALLOCATION_COUNTING() \
  if (!adit::test::kCountingAllocations) GTEST_SKIP() << "allocations are counted in builds without sanitizers"
