// mf_model: loading (file, memory, default model, the transformer
// in-betweeners and the rig anatomy next to the prior's file) and
// skeleton/config queries.
#include <dlfcn.h>

#include <nlohmann/json.hpp>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "capi/src/capi_internal.h"
#include "prior/inbetween/inbetweener_kinds.h"
#include "prior/model/model_container.h"
#include "prior/motion/errors.h"
#include "prior/rig/retarget.h"
#include "prior/runtime/inbetween_runtime.h"
#include "prior/runtime/nemf_runtime.h"
#include "prior/util/binary_io.h"
#include "tasks/context/model_rig.h"
#include "tasks/transformer/inbetweener_files.h"

namespace mf::capi {
namespace {

namespace fs = std::filesystem;

constexpr char kModelFileName[] = "motionfield-prior.mfm";

// The directory holding libmotionfield.so itself.
fs::path library_directory() {
  Dl_info info;
  if (dladdr(reinterpret_cast<void*>(&mf_version_string), &info) == 0 || !info.dli_fname) return {};
  std::error_code ec;
  const fs::path lib = fs::canonical(info.dli_fname, ec);
  return ec ? fs::path() : lib.parent_path();
}

std::string default_path() {
  if (const char* env = std::getenv("MF_MODEL"); env && *env) return env;
  // Installed: <prefix>/<libdir>/libmotionfield.so and
  // <prefix>/share/motionfield/motionfield-prior.mfm, libdir being "lib" or
  // "lib/<multiarch>".
  const fs::path dir = library_directory();
  if (!dir.empty()) {
    std::error_code ec;
    for (const fs::path& prefix : {dir.parent_path(), dir.parent_path().parent_path()}) {
      const fs::path candidate = prefix / "share" / "motionfield" / kModelFileName;
      if (fs::is_regular_file(candidate, ec)) return candidate.string();
    }
  }
  return mf::default_model_path();
}

// The prior of a model file's bytes.
// With the `file` the bytes are, its pages are given back as the weights are copied.
std::unique_ptr<mf_model> load_bytes(const uint8_t* data, size_t size, const std::string& source,
                                     const FileBytes* file = nullptr) {
  try {
    auto handle = std::make_unique<mf_model>();
    handle->model = std::make_shared<const runtime::NemfRuntime>(
        file ? runtime::NemfRuntime::from_file(*file, source) : runtime::NemfRuntime::from_bytes(data, size, source));
    return handle;
  } catch (const InputError& e) {
    throw ApiError(MF_ERROR_MODEL, e.what());
  }
}

// The bytes of a file; MF_ERROR_IO when it cannot be read.
FileBytes read_file(const std::string& file) { return read_file_bytes(file); }  // FileError: MF_ERROR_IO

// The in-betweener file `file` for the prior of `model`: MF_ERROR_IO when
// unreadable, MF_ERROR_MODEL when it is not an in-betweener or not on the
// prior's skeleton.
std::shared_ptr<const runtime::InbetweenerRuntime> load_user_inbetweener(const std::string& file,
                                                                         const mf_model& model) {
  const FileBytes bytes = read_file(file);
  try {
    return inbetweener_from_bytes(bytes.data(), bytes.size(), file, "", model.model.get());
  } catch (const InputError& e) {
    throw ApiError(MF_ERROR_MODEL, e.what());
  }
}

// The rig anatomy next to `prior_file`, if any; a broken file is kept as the
// error tasks on other rigs report (the prior stays usable on its own rig).
void load_anatomy(mf_model* handle, const std::string& prior_file) {
  try {
    handle->model_anatomy = load_rig_anatomy_next_to(prior_file, handle->model->rig().skeleton);
  } catch (const std::exception& e) {
    handle->model_anatomy_error = e.what();
  }
}

const runtime::NemfRuntime& get(const mf_model* model) {
  require(model, "model");
  return *model->model;
}

}  // namespace

std::unique_ptr<mf_model> load_model_set(const char* path, const char* const* inbetweeners, size_t count) {
  std::string file;
  if (path) {
    file = path;
    if (file.empty()) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "the model path is empty");
  } else {
    file = default_path();
    if (file.empty())
      throw ApiError(MF_ERROR_IO, "no default model: set MF_MODEL or install models/motionfield-prior.mfm (see README)");
  }
  std::unique_ptr<mf_model> handle;
  {
    // The prior's bytes go before the in-betweeners load (the peak memory of a load).
    const FileBytes bytes = read_file(file);
    handle = load_bytes(bytes.data(), bytes.size(), file, &bytes);
  }
  load_inbetweeners_next_to(file, handle.get());
  load_anatomy(handle.get(), file);
  for (size_t i = 0; i < count; ++i) {
    require(inbetweeners[i], "an in-betweener path");
    if (!*inbetweeners[i]) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "the transformer model path is empty");
    handle->add_inbetweener(load_user_inbetweener(inbetweeners[i], *handle));
  }
  return handle;
}

}  // namespace mf::capi

using mf::capi::ApiError;
using mf::capi::guard;
using mf::capi::require;

extern "C" {

int mf_model_default_path(char* out, size_t capacity, size_t* needed) {
  return guard([&] { mf::capi::write_string(mf::capi::default_path(), out, capacity, needed); });
}

int mf_model_load(const char* path, mf_model** out) {
  return guard([&] {
    require(out, "out");
    *out = mf::capi::load_model_set(path, nullptr, 0).release();
  });
}

int mf_model_load_set(const char* path, const char* const* inbetweeners, size_t count, mf_model** out) {
  return guard([&] {
    require(out, "out");
    if (count > 0) require(inbetweeners, "inbetweeners");
    *out = mf::capi::load_model_set(path, inbetweeners, count).release();
  });
}

int mf_model_get_load_warnings(const mf_model* model, char* out, size_t capacity, size_t* needed) {
  return guard([&] {
    require(model, "model");
    std::string warnings;
    for (const mf::InbetweenerKind& kind : mf::inbetweener_kinds()) {
      const auto error = model->inbetweener_errors.find(kind.name);
      if (error != model->inbetweener_errors.end() && !error->second.empty())
        warnings += kind.file_name + " next to the model did not load, so the methods that need it cannot run "
                    "and the default method does without it: " + error->second + "\n";
    }
    mf::capi::write_string(warnings, out, capacity, needed);
  });
}

int mf_model_load_from_memory(const void* data, size_t size, mf_model** out) {
  return guard([&] {
    require(out, "out");
    if (!data && size != 0) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "data is NULL");
    static const uint8_t kEmpty = 0;
    *out = mf::capi::load_bytes(data ? static_cast<const uint8_t*>(data) : &kEmpty, size, "<memory>").release();
  });
}

void mf_model_destroy(mf_model* model) { delete model; }

int mf_model_with_inbetweener(const mf_model* model, const char* path, mf_model** out) {
  return guard([&] {
    require(model, "model");
    require(path, "path");
    require(out, "out");
    if (!*path) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "the transformer model path is empty");
    auto handle = std::make_unique<mf_model>(*model);
    handle->add_inbetweener(mf::capi::load_user_inbetweener(path, *model));
    *out = handle.release();
  });
}

int mf_model_has_inbetweener(const mf_model* model, const char* kind, int32_t* out) {
  return guard([&] {
    require(model, "model");
    require(kind, "kind");
    require(out, "out");
    *out = model->inbetweener(mf::inbetweener_kind(kind).name) ? 1 : 0;
  });
}

int mf_model_describe(const mf_model* model, char* out, size_t capacity, size_t* needed) {
  return guard([&] {
    const mf::runtime::NemfRuntime& m = mf::capi::get(model);
    nlohmann::ordered_json j;
    j["format_version"] = mf::kModelFormatVersion;
    j["joints"] = m.rig().num_joints();
    j["fps"] = m.config().fps;
    j["window"] = m.config().window;
    nlohmann::ordered_json kinds = nlohmann::ordered_json::object();
    for (const mf::InbetweenerKind& kind : mf::inbetweener_kinds()) {
      const auto error = model->inbetweener_errors.find(kind.name);
      kinds[kind.name] = {{"file", kind.file_name},
                          {"loaded", model->inbetweener(kind.name) != nullptr},
                          {"error", error == model->inbetweener_errors.end() ? "" : error->second}};
    }
    j["inbetweeners"] = kinds;
    j["rig_anatomy"] = model->model_anatomy != nullptr;
    j["rig_anatomy_error"] = model->model_anatomy_error;
    mf::capi::write_string(j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace), out, capacity, needed);
  });
}

int mf_model_get_joint_count(const mf_model* model, int32_t* out) {
  return guard([&] {
    const mf::runtime::NemfRuntime& m = mf::capi::get(model);
    require(out, "out");
    *out = m.rig().num_joints();
  });
}

int mf_model_get_joint_name(const mf_model* model, int32_t joint, char* out, size_t capacity, size_t* needed) {
  return guard([&] { mf::capi::skeleton_joint_name(mf::capi::get(model).rig().skeleton, joint, out, capacity, needed); });
}

int mf_model_get_parents(const mf_model* model, int32_t* out, size_t capacity, size_t* needed) {
  return guard([&] { mf::capi::skeleton_parents(mf::capi::get(model).rig().skeleton, out, capacity, needed); });
}

int mf_model_get_offsets(const mf_model* model, float* out, size_t capacity, size_t* needed) {
  return guard([&] { mf::capi::skeleton_offsets(mf::capi::get(model).rig().skeleton, out, capacity, needed); });
}

int mf_model_get_fps(const mf_model* model, double* out) {
  return guard([&] {
    const mf::runtime::NemfRuntime& m = mf::capi::get(model);
    require(out, "out");
    *out = m.config().fps;
  });
}

int mf_model_get_window(const mf_model* model, int32_t* out) {
  return guard([&] {
    const mf::runtime::NemfRuntime& m = mf::capi::get(model);
    require(out, "out");
    *out = m.config().window;
  });
}

int mf_model_get_latent_sizes(const mf_model* model, int32_t* local_size, int32_t* global_size) {
  return guard([&] {
    const mf::runtime::NemfRuntime& m = mf::capi::get(model);
    if (!local_size && !global_size) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "local_size and global_size are both NULL");
    if (local_size) *local_size = m.config().zl;
    if (global_size) *global_size = m.config().zg;
  });
}

}  // extern "C"
