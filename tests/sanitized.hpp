// VSD_TEST_SANITIZED: defined in a build with AddressSanitizer or ThreadSanitizer, where tests scale their
// work down or skip what the sanitizers' allocators and shadow memory make meaningless. One macro for both
// compilers: GCC defines __SANITIZE_ADDRESS__, clang (14) answers only __has_feature.
#pragma once

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define VSD_TEST_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define VSD_TEST_SANITIZED 1
#endif
#endif
