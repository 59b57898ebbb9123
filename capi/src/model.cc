// mf_model: loading (file, memory, default model, the transformer
// in-betweeners and the rig anatomy next to the prior's file) and
// skeleton/config queries.
#include <dlfcn.h>

#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "capi/src/capi_internal.h"
#include "prior/inbetween/inbetweener.h"
#include "prior/model/model_file.h"
#include "prior/model/nemf.h"
#include "prior/motion/errors.h"
#include "prior/rig/retarget.h"
#include "tasks/method.h"
#include "tasks/model_rig.h"
#include "tasks/transformer_methods.h"

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

std::unique_ptr<mf_model> make_model(NemfModel model) {
  model.set_requires_grad(false);
  auto handle = std::make_unique<mf_model>();
  handle->model = std::make_shared<const NemfModel>(std::move(model));
  return handle;
}

std::unique_ptr<mf_model> load_bytes(const uint8_t* data, size_t size, const std::string& source) {
  try {
    return make_model(deserialize_nemf(data, size, source));
  } catch (const InputError& e) {
    throw ApiError(MF_ERROR_MODEL, e.what());
  }
}

// The bytes of a file; MF_ERROR_IO when it cannot be read.
std::vector<uint8_t> read_file(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw ApiError(MF_ERROR_IO, "cannot open model file " + file + ": " + std::strerror(errno));
  std::error_code ec;
  if (fs::is_directory(file, ec)) throw ApiError(MF_ERROR_IO, "cannot read model file " + file + ": it is a directory");
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw ApiError(MF_ERROR_IO, "cannot read model file " + file);
  return bytes;
}

// A transformer file for `prior`: MF_ERROR_IO when unreadable, MF_ERROR_MODEL
// when it is not a transformer model or its skeleton is not the prior's.
std::shared_ptr<const InbetweenModel> load_transformer(const std::string& file, const NemfModel& prior) {
  const std::vector<uint8_t> bytes = read_file(file);
  std::unique_ptr<InbetweenModel> t;
  try {
    t = deserialize_inbetweener(bytes.data(), bytes.size(), file);
  } catch (const InputError& e) {
    throw ApiError(MF_ERROR_MODEL, e.what());
  }
  if (!t->rig().skeleton.same_as(prior.rig().skeleton))
    throw ApiError(MF_ERROR_MODEL, file + ": the transformer's skeleton (" + std::to_string(t->rig().num_joints()) +
                                       " joints) is not the prior's (" + std::to_string(prior.rig().num_joints()) +
                                       " joints): train it on the prior's data");
  t->set_requires_grad(false);
  t->train(false);
  return std::shared_ptr<const InbetweenModel>(std::move(t));
}

void set_transformer(mf_model* handle, std::shared_ptr<const InbetweenModel> t) {
  if (t->kind() == kCitlKind) {
    handle->citl = std::move(t);
    handle->citl_error.clear();
  } else {
    handle->twostage = std::move(t);
    handle->twostage_error.clear();
  }
}

// The transformer files next to `prior_file` that exist; failures are kept
// for the methods' error messages (the prior alone stays usable).
void load_companions(mf_model* handle, const std::string& prior_file) {
  for (const std::string kind : {kTwoStageKind, kCitlKind}) {
    const std::string file = inbetweener_path_next_to(prior_file, kind);
    std::error_code ec;
    if (!fs::exists(file, ec)) continue;
    try {
      std::shared_ptr<const InbetweenModel> t = load_transformer(file, *handle->model);
      if (t->kind() != kind) throw ApiError(MF_ERROR_MODEL, file + " holds a '" + t->kind() + "' model, not '" + kind + "'");
      set_transformer(handle, std::move(t));
    } catch (const std::exception& e) {
      (kind == kCitlKind ? handle->citl_error : handle->twostage_error) = e.what();
    }
  }
}

// The rig anatomy next to `prior_file`, if any; a broken file is kept as the
// error tasks on other rigs report (the prior stays usable on its own rig).
void load_anatomy(mf_model* handle, const std::string& prior_file) {
  try {
    handle->anatomy = load_rig_anatomy_next_to(prior_file, handle->model->rig().skeleton);
  } catch (const std::exception& e) {
    handle->anatomy_error = e.what();
  }
}

const NemfModel& get(const mf_model* model) {
  require(model, "model");
  return *model->model;
}

}  // namespace

void set_models(const mf_model* model, TaskContext* ctx) {
  if (!model) return;
  ctx->model = model->model;
  ctx->twostage = model->twostage;
  ctx->citl = model->citl;
  ctx->model_anatomy = model->anatomy;
}

void require_inbetweener(const mf_model* model, const std::string& method, const std::string& kind) {
  if (kind.empty()) return;
  const bool citl = kind == kCitlKind;
  if (model && (citl ? model->citl : model->twostage)) return;
  std::string message = missing_inbetweener_message("method '" + method + "'", kind);
  const std::string why = !model ? "" : citl ? model->citl_error : model->twostage_error;
  if (!why.empty()) message += "; the file next to the prior did not load: " + why;
  throw ApiError(MF_ERROR_MODEL, message);
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
    std::string file;
    if (path) {
      file = path;
      if (file.empty()) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "the model path is empty");
    } else {
      file = mf::capi::default_path();
      if (file.empty())
        throw ApiError(MF_ERROR_IO,
                       "no default model: set MF_MODEL or install models/motionfield-prior.mfm (see README)");
    }
    const std::vector<uint8_t> bytes = mf::capi::read_file(file);
    std::unique_ptr<mf_model> handle = mf::capi::load_bytes(bytes.data(), bytes.size(), file);
    mf::capi::load_companions(handle.get(), file);
    mf::capi::load_anatomy(handle.get(), file);
    *out = handle.release();
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
    mf::capi::set_transformer(handle.get(), mf::capi::load_transformer(path, *model->model));
    *out = handle.release();
  });
}

int mf_model_has_inbetweener(const mf_model* model, const char* kind, int32_t* out) {
  return guard([&] {
    require(model, "model");
    require(kind, "kind");
    require(out, "out");
    const std::string k = kind;
    if (k != mf::kTwoStageKind && k != mf::kCitlKind)
      throw ApiError(MF_ERROR_INVALID_ARGUMENT, "unknown transformer kind '" + k + "' (available: twostage, citl)");
    *out = (k == mf::kCitlKind ? model->citl : model->twostage) ? 1 : 0;
  });
}

int mf_model_get_joint_count(const mf_model* model, int32_t* out) {
  return guard([&] {
    const mf::NemfModel& m = mf::capi::get(model);
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
    const mf::NemfModel& m = mf::capi::get(model);
    require(out, "out");
    *out = m.config().fps;
  });
}

int mf_model_get_window(const mf_model* model, int32_t* out) {
  return guard([&] {
    const mf::NemfModel& m = mf::capi::get(model);
    require(out, "out");
    *out = m.config().window;
  });
}

int mf_model_get_latent_sizes(const mf_model* model, int32_t* local_size, int32_t* global_size) {
  return guard([&] {
    const mf::NemfModel& m = mf::capi::get(model);
    if (!local_size && !global_size) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "local_size and global_size are both NULL");
    if (local_size) *local_size = m.config().zl;
    if (global_size) *global_size = m.config().zg;
  });
}

}  // extern "C"
