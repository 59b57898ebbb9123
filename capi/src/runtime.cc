// Version, status codes and messages, threads, cancel tokens, methods.
#include <ATen/Parallel.h>

#include <new>

#include "capi/src/capi_internal.h"
#include "prior/motion/errors.h"
#include "tasks/jobs.h"
#include "prior/util/threads.h"

namespace mf::capi {
namespace {

thread_local std::string t_message;
thread_local const char* t_message_ptr = "";

std::atomic<int> g_num_threads{0};

}  // namespace

int fail(int status, const char* message) noexcept {
  try {
    t_message = message;
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

void apply_num_threads() {
  const int n = g_num_threads.load();
  if (n > 0 && at::get_num_threads() != n) mf::set_compute_threads(n);
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
    mf::set_compute_threads(num_threads);
  });
}

int mf_get_num_threads(int32_t* out) {
  return guard([&] {
    require(out, "out");
    mf::capi::apply_num_threads();
    *out = static_cast<int32_t>(at::get_num_threads());
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

int mf_task_options_init(mf_task_options* options) {
  return guard([&] {
    require(options, "options");
    std::memset(options, 0, sizeof *options);
    options->struct_size = sizeof *options;
  });
}

}  // extern "C"
