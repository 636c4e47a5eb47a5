// Tests of what happens when memory runs out: the test runs again in a fresh process (the same test binary,
// only this test), which caps its own address space. A fresh process, because freed memory that a process
// keeps mapped is reused without growing the address space: a cap in a forked child of a long test run
// would depend on what the tests before it freed.
#pragma once

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstddef>
#include <cstdlib>
#include <fstream>
#include <string>

#include "../sanitized.hpp"


namespace vsd_test {

/// True in the fresh process that run_capped() starts.
inline bool in_capped_run() { return std::getenv("VSD_TEST_CAPPED_RUN") != nullptr; }

/// Runs the current test again in a fresh process (where in_capped_run() is true); returns its exit status
/// (0: the test passed there).
inline int run_capped() {
  const testing::TestInfo& t = *testing::UnitTest::GetInstance()->current_test_info();
  const std::string filter = std::string("--gtest_filter=") + t.test_suite_name() + "." + t.name();
  const pid_t child = ::fork();
  if (child == 0) {
    ::setenv("VSD_TEST_CAPPED_RUN", "1", 1);
    ::unsetenv("GTEST_OUTPUT");  // the report of the outer run is not to be overwritten
    ::execl("/proc/self/exe", "/proc/self/exe", filter.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 100 + WTERMSIG(status);
}

/// Caps the address space of this process at what it uses now plus @p extra bytes.
inline void cap_memory(std::size_t extra) {
  std::size_t pages = 0;
  std::ifstream("/proc/self/statm") >> pages;
  const rlimit cap{pages * static_cast<std::size_t>(::sysconf(_SC_PAGESIZE)) + extra, RLIM_INFINITY};
  ::setrlimit(RLIMIT_AS, &cap);
}

}  // namespace vsd_test

/// Makes the rest of the test body run in a fresh process with a capped address space (see above); skipped
/// under sanitizers, whose allocators abort instead of failing an allocation.
#ifdef VSD_TEST_SANITIZED
#define VSD_TEST_RUN_CAPPED() GTEST_SKIP() << "memory caps do not work under sanitizers"
#else
#define VSD_TEST_RUN_CAPPED()                                                                \
  if (!vsd_test::in_capped_run()) {                                                          \
    EXPECT_EQ(vsd_test::run_capped(), 0) << "the test failed in its capped process (above)"; \
    return;                                                                                  \
  }
#endif
