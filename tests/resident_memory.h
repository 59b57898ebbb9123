// The resident set size of the running test process, for the tests that bound
// how much memory something holds (tests/capi/capi_leak_test.cc,
// tests/runtime/runtime_standalone_test.cc). Header-only: the test binaries
// that use it link different libraries.
#pragma once

#include <unistd.h>

#include <fstream>

namespace mf::test {

/// Resident set size of this process in bytes (/proc/self/statm, field 2),
/// 0 when it cannot be read.
inline long long resident_bytes() {
  std::ifstream statm("/proc/self/statm");
  long long size = 0, resident = 0;
  statm >> size >> resident;
  return resident * ::sysconf(_SC_PAGESIZE);
}

}  // namespace mf::test
