// The failure of a fuzz target's own check: prints what broke and aborts, so
// libFuzzer (or the replay driver) reports the input as a crash. Exceptions the
// target does not expect are left to escape: std::terminate aborts as well.
#pragma once

#include <cstdio>
#include <cstdlib>

#define MF_FUZZ_CHECK(cond)                                                               \
  do {                                                                                    \
    if (!(cond)) {                                                                        \
      std::fprintf(stderr, "%s:%d: fuzz check failed: %s\n", __FILE__, __LINE__, #cond); \
      std::abort();                                                                       \
    }                                                                                     \
  } while (0)
