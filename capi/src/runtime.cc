// Version, status codes and messages, threads, cancel tokens, methods.
#include <cstdio>
#include <mutex>
#include <new>

#include "capi/src/capi_internal.h"
#include "prior/motion/errors.h"
#include "prior/util/binary_io.h"
#include "prior/util/blas.h"
#include "tasks/methods/jobs.h"

namespace mf::capi {
namespace {

thread_local std::string t_message;
thread_local const char* t_message_ptr = "";

std::atomic<int> g_num_threads{0};

// The code point of the valid UTF-8 sequence at s[i] (0x80 and up) and its
// length in *n; -1 when the bytes there are not valid UTF-8 (overlong,
// surrogate, beyond U+10FFFF, truncated).
long utf8_at(const std::string& s, size_t i, size_t* n) {
  const unsigned char c = static_cast<unsigned char>(s[i]);
  size_t len = 0;
  long cp = 0, min = 0;
  if (c >= 0xC2 && c <= 0xDF) {
    len = 2;
    cp = c & 0x1F;
    min = 0x80;
  } else if (c >= 0xE0 && c <= 0xEF) {
    len = 3;
    cp = c & 0x0F;
    min = 0x800;
  } else if (c >= 0xF0 && c <= 0xF4) {
    len = 4;
    cp = c & 0x07;
    min = 0x10000;
  } else {
    return -1;
  }
  if (i + len > s.size()) return -1;
  for (size_t k = 1; k < len; ++k) {
    const unsigned char d = static_cast<unsigned char>(s[i + k]);
    if ((d & 0xC0) != 0x80) return -1;
    cp = (cp << 6) | (d & 0x3F);
  }
  if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return -1;
  *n = len;
  return cp;
}

// Code points a terminal acts on rather than shows: C1 controls, the
// bidirectional overrides and isolates, line and paragraph separators.
bool unprintable(long cp) {
  return (cp >= 0x80 && cp <= 0x9F) || (cp >= 0x202A && cp <= 0x202E) || (cp >= 0x2066 && cp <= 0x2069) ||
         cp == 0x2028 || cp == 0x2029 || cp == 0x200E || cp == 0x200F || cp == 0x061C;
}

std::string escaped(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  char buf[16];
  for (size_t i = 0; i < s.size();) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (c >= 0x20 && c < 0x7F) {
      out += static_cast<char>(c);
      ++i;
    } else if (c == '\n' || c == '\t' || c == '\r') {
      out += c == '\n' ? "\\n" : c == '\t' ? "\\t" : "\\r";
      ++i;
    } else if (c < 0x80) {
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      out += buf;
      ++i;
    } else {
      size_t n = 0;
      const long cp = utf8_at(s, i, &n);
      if (cp < 0) {
        std::snprintf(buf, sizeof buf, "\\x%02x", c);
        out += buf;
        ++i;
      } else if (unprintable(cp)) {
        std::snprintf(buf, sizeof buf, "\\u%04lx", cp);
        out += buf;
        i += n;
      } else {
        out.append(s, i, n);
        i += n;
      }
    }
  }
  return out;
}

// Moves a cut at `at` back to the start of a UTF-8 sequence (for the head).
size_t char_boundary(const std::string& s, size_t at) {
  while (at > 0 && at < s.size() && (static_cast<unsigned char>(s[at]) & 0xC0) == 0x80) --at;
  return at;
}

}  // namespace

std::string printable_text(const std::string& text, size_t max_bytes) {
  std::string out = escaped(text);
  if (out.size() <= max_bytes) return out;
  // Keep the start (the file and what was wrong) and the end (the reason),
  // the result never longer than max_bytes, so applying it again keeps it.
  const std::string note = "... (" + std::to_string(out.size()) + " bytes left out) ...";  // >= the final note
  const size_t room = max_bytes > note.size() ? max_bytes - note.size() : 0;
  const size_t head = char_boundary(out, room * 3 / 4);
  size_t tail_start = out.size() - (room - room * 3 / 4);
  while (tail_start < out.size() && (static_cast<unsigned char>(out[tail_start]) & 0xC0) == 0x80) ++tail_start;
  const size_t left_out = tail_start - head;
  return out.substr(0, head) + "... (" + std::to_string(left_out) + " bytes left out) ..." + out.substr(tail_start);
}

int fail(int status, const char* message) noexcept {
  try {
    t_message = printable_text(message);
    t_message_ptr = t_message.c_str();
  } catch (...) {
    t_message_ptr = "out of memory (while recording an error message)";
  }
  return status;
}

int fail_current_exception() noexcept {
  try {
    throw;
  } catch (const ApiError& e) {
    return fail(e.status(), e.what());
  } catch (const CancelledError&) {
    return fail(MF_ERROR_CANCELLED, "cancelled");
  } catch (const ModelMissingError& e) {
    return fail(MF_ERROR_MODEL, e.what());
  } catch (const FileError& e) {
    return fail(MF_ERROR_IO, e.what());
  } catch (const InputError& e) {
    return fail(MF_ERROR_INVALID_ARGUMENT, e.what());
  } catch (const std::bad_alloc&) {
    return fail(MF_ERROR_OUT_OF_MEMORY, "out of memory");
  } catch (const std::exception& e) {
    try {
      return fail(MF_ERROR_INTERNAL, (std::string("internal error: ") + e.what()).c_str());
    } catch (...) {
      return fail(MF_ERROR_INTERNAL, "internal error");
    }
  } catch (...) {
    return fail(MF_ERROR_INTERNAL, "internal error: unknown exception");
  }
}

void write_string(const std::string& s, char* out, size_t capacity, size_t* needed) {
  write_buffer(s.c_str(), s.size() + 1, out, capacity, needed);
}

void skeleton_joint_name(const Skeleton& s, int32_t joint, char* out, size_t capacity, size_t* needed) {
  if (joint < 0 || joint >= s.num_joints())
    throw ApiError(MF_ERROR_INVALID_ARGUMENT, "joint " + std::to_string(joint) + " is out of range: the skeleton has " +
                                                  std::to_string(s.num_joints()) + " joints");
  write_string(s.names[static_cast<size_t>(joint)], out, capacity, needed);
}

void skeleton_parents(const Skeleton& s, int32_t* out, size_t capacity, size_t* needed) {
  std::vector<int32_t> parents(s.parents.begin(), s.parents.end());
  write_buffer(parents.data(), parents.size(), out, capacity, needed);
}

void skeleton_offsets(const Skeleton& s, float* out, size_t capacity, size_t* needed) {
  std::vector<float> offsets;
  offsets.reserve(s.offsets.size() * 3);
  for (const Eigen::Vector3d& o : s.offsets)
    for (int k = 0; k < 3; ++k) offsets.push_back(static_cast<float>(o[k]));
  write_buffer(offsets.data(), offsets.size(), out, capacity, needed);
}

// Until the caller chooses a count, OpenBLAS's pool is held at one thread:
// left at one thread per core it made a caller who never chose one 10x slower
// on a busy machine.
TaskThreads::TaskThreads() {
  static std::once_flag blas_once;
  std::call_once(blas_once, [] {
    if (g_num_threads.load() == 0) mf::keep_blas_single_threaded();
  });
}

}  // namespace mf::capi

using mf::capi::ApiError;
using mf::capi::guard;
using mf::capi::require;

extern "C" {

uint32_t mf_abi_version(void) { return MF_ABI_VERSION; }
uint32_t mf_version_number(void) { return MF_VERSION_NUMBER; }
const char* mf_version_string(void) { return MF_VERSION_STRING; }

const char* mf_last_error_message(void) { return mf::capi::t_message_ptr; }

int mf_printable_text(const char* text, size_t length, char* out, size_t capacity, size_t* needed) {
  return guard([&] {
    if (!text && length != 0) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "text is NULL");
    mf::capi::write_string(mf::capi::printable_text(text ? std::string(text, length) : std::string()), out, capacity,
                           needed);
  });
}

const char* mf_status_name(int status) {
  switch (status) {
    case MF_OK: return "MF_OK";
    case MF_ERROR_INVALID_ARGUMENT: return "MF_ERROR_INVALID_ARGUMENT";
    case MF_ERROR_BUFFER_TOO_SMALL: return "MF_ERROR_BUFFER_TOO_SMALL";
    case MF_ERROR_IO: return "MF_ERROR_IO";
    case MF_ERROR_MODEL: return "MF_ERROR_MODEL";
    case MF_ERROR_CANCELLED: return "MF_ERROR_CANCELLED";
    case MF_ERROR_INTERNAL: return "MF_ERROR_INTERNAL";
    case MF_ERROR_UNSUPPORTED: return "MF_ERROR_UNSUPPORTED";
    case MF_ERROR_OUT_OF_MEMORY: return "MF_ERROR_OUT_OF_MEMORY";
    default: return "MF_ERROR_UNKNOWN";
  }
}

int mf_set_num_threads(int32_t num_threads) {
  return guard([&] {
    if (num_threads < 1 || num_threads > 1024)
      throw ApiError(MF_ERROR_INVALID_ARGUMENT,
                     "the thread count must be between 1 and 1024, not " + std::to_string(num_threads));
    mf::capi::g_num_threads.store(num_threads);
    mf::set_blas_threads(num_threads);
  });
}

int mf_get_num_threads(int32_t* out) {
  return guard([&] {
    require(out, "out");
    const mf::capi::TaskThreads threads;
    const int n = mf::capi::g_num_threads.load();
    *out = n > 0 ? n : 1;
  });
}

int mf_cancel_token_create(mf_cancel_token** out) {
  return guard([&] {
    require(out, "out");
    *out = new mf_cancel_token();
  });
}

int mf_cancel_token_cancel(mf_cancel_token* token) {
  return guard([&] {
    require(token, "token");
    token->flag.store(1);
  });
}

int mf_cancel_token_reset(mf_cancel_token* token) {
  return guard([&] {
    require(token, "token");
    token->flag.store(0);
  });
}

int mf_cancel_token_is_cancelled(const mf_cancel_token* token, int32_t* out) {
  return guard([&] {
    require(token, "token");
    require(out, "out");
    *out = token->flag.load() != 0 ? 1 : 0;
  });
}

void mf_cancel_token_destroy(mf_cancel_token* token) { delete token; }

int mf_method_count(int32_t* out) {
  return guard([&] {
    require(out, "out");
    *out = static_cast<int32_t>(mf::registered_methods().size());
  });
}

int mf_method_get(int32_t index, const char** name, const char** description, uint32_t* flags) {
  return guard([&] {
    const auto& methods = mf::registered_methods();
    if (index < 0 || static_cast<size_t>(index) >= methods.size())
      throw ApiError(MF_ERROR_INVALID_ARGUMENT, "method index " + std::to_string(index) + " is out of range (there are " +
                                                    std::to_string(methods.size()) + " methods)");
    const mf::Method& m = methods[static_cast<size_t>(index)];
    if (name) *name = m.name.c_str();
    if (description) *description = m.description.c_str();
    if (flags)
      *flags = (m.needs_model ? MF_METHOD_NEEDS_MODEL : 0u) | (m.complete ? MF_METHOD_COMPLETES : 0u) |
               (m.resample ? MF_METHOD_RESAMPLES : 0u);
  });
}

int mf_method_find(const char* name, int32_t* index) {
  return guard([&] {
    require(name, "name");
    require(index, "index");
    const auto& methods = mf::registered_methods();
    std::string list;
    for (size_t i = 0; i < methods.size(); ++i) {
      if (methods[i].name == name) {
        *index = static_cast<int32_t>(i);
        return;
      }
      list += (list.empty() ? "" : ", ") + methods[i].name;
    }
    throw ApiError(MF_ERROR_INVALID_ARGUMENT, "unknown method '" + std::string(name) + "' (available: " + list + ")");
  });
}

int mf_default_method(const mf_model* model, const char** name) {
  return guard([&] {
    require(name, "name");
    mf::TaskContext ctx;
    if (model) static_cast<mf::ModelSet&>(ctx) = *model;
    const std::string d = mf::default_method(ctx);
    for (const mf::Method& m : mf::registered_methods()) {
      if (m.name == d) {
        *name = m.name.c_str();
        return;
      }
    }
    throw ApiError(MF_ERROR_INTERNAL, "the default method '" + d + "' is not registered");
  });
}

int mf_bvh_options_init(mf_bvh_options* options) {
  return guard([&] {
    require(options, "options");
    std::memset(options, 0, sizeof *options);
    options->struct_size = sizeof *options;
  });
}

int mf_gltf_options_init(mf_gltf_options* options) {
  return guard([&] {
    require(options, "options");
    std::memset(options, 0, sizeof *options);
    options->struct_size = sizeof *options;
  });
}

int mf_motion_load_options_init(mf_motion_load_options* options) {
  return guard([&] {
    require(options, "options");
    std::memset(options, 0, sizeof *options);
    options->struct_size = sizeof *options;
  });
}

int mf_task_options_init(mf_task_options* options) {
  return guard([&] {
    require(options, "options");
    std::memset(options, 0, sizeof *options);
    options->struct_size = sizeof *options;
  });
}

}  // extern "C"
