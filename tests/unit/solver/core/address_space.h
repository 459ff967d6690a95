// For tests that cap a forked child's address space (RLIMIT_AS) to see allocations fail: the
// process's mapped address space now, and whether this is a sanitizer build (ASan reserves
// terabytes of shadow address space and answers an allocation that does not fit under a cap with
// its own report, then a failed CHECK that hangs the child, as seen in build/asan; such
// tests skip there).
#pragma once

#include <cstddef>
#include <fstream>
#include <limits>
#include <string>

namespace inbetween::solver::testing {

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
inline constexpr bool kSanitizerBuild = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
inline constexpr bool kSanitizerBuild = true;
#else
inline constexpr bool kSanitizerBuild = false;
#endif
#else
inline constexpr bool kSanitizerBuild = false;
#endif

// VmSize of /proc/self/status in bytes, 0 if it cannot be read.
inline size_t AddressSpaceBytes() {
  std::ifstream in("/proc/self/status");
  std::string key;
  while (in >> key) {
    if (key == "VmSize:") {
      size_t kb = 0;
      in >> kb;
      return kb * 1024;
    }
    in.ignore(std::numeric_limits<std::streamsize>::max(), '\n');
  }
  return 0;
}

}  // namespace inbetween::solver::testing
