// Checks shared by the C API fuzz targets: the status is a documented one and
// never MF_ERROR_INTERNAL (which means an exception the library did not
// expect: a bug), and the message is never NULL.
#pragma once

#include <cstdio>
#include <cstdlib>

#include "motionfield.h"

namespace mf::fuzz {

inline int check_status(int status, const char* call) {
  const char* message = mf_last_error_message();
  if (!message || status < MF_OK || status > MF_ERROR_OUT_OF_MEMORY || status == MF_ERROR_INTERNAL) {
    std::fprintf(stderr, "%s returned %d (%s): %s\n", call, status, mf_status_name(status),
                 message ? message : "(NULL message)");
    std::abort();
  }
  return status;
}

}  // namespace mf::fuzz

#define MF_FUZZ_CALL(call) mf::fuzz::check_status((call), #call)
