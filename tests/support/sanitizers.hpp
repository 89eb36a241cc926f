#pragma once
// Whether this test binary is built with AddressSanitizer or ThreadSanitizer
// (GCC defines __SANITIZE_*__, clang answers __has_feature). Such builds run
// several times slower: tests that load the pipeline in real time pick a
// rate such a build can keep up with.

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define ADIT_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define ADIT_SANITIZED 1
#endif
#endif
#ifndef ADIT_SANITIZED
#define ADIT_SANITIZED 0
#endif

namespace adit::test {

inline constexpr bool kSanitized = ADIT_SANITIZED != 0;

}  // namespace adit::test
