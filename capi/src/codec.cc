// mf_encoding: the prior as a codec (tasks/latent/prior_codec.h) at the C
// boundary, on the model set's prior (ModelSet::model, the Eigen runtime).
#include <cmath>
#include <cstring>

#include "capi/src/capi_internal.h"
#include "prior/motion/errors.h"
#include "prior/runtime/nemf_runtime.h"
#include "tasks/latent/prior_codec.h"
#include "tasks/methods/jobs.h"

struct mf_encoding {
  std::shared_ptr<const mf::runtime::NemfRuntime> model;
  mf::EncodedMotion code;
  /// Carries the input's BVH layout (its motion is empty).
  mf_motion shell;
};

namespace mf::capi {
namespace {

const mf_encoding& get(const mf_encoding* encoding) {
  require(encoding, "encoding");
  return *encoding;
}

mf_codec_options codec_options(const mf_codec_options* options) {
  const mf_codec_options o = read_options(options, "mf_codec_options");
  if (o.root_source != MF_ROOT_FROM_PRIOR && o.root_source != MF_ROOT_FROM_INPUT)
    throw ApiError(MF_ERROR_INVALID_ARGUMENT, "mf_codec_options.root_source must be MF_ROOT_FROM_PRIOR (0) or "
                                              "MF_ROOT_FROM_INPUT (1), not " + std::to_string(o.root_source));
  return o;
}

DecodeOptions decode_options(const mf_codec_options& o) {
  DecodeOptions d;
  d.root = o.root_source == MF_ROOT_FROM_INPUT ? RootSource::kInput : RootSource::kPrior;
  return d;
}

// Every window's latent of one kind, concatenated.
std::vector<float> latents(const EncodedMotion& code, bool local) {
  std::vector<float> out;
  for (const WindowCode& w : code.windows) {
    const Eigen::VectorXf& z = local ? w.z_l : w.z_g;
    out.insert(out.end(), z.data(), z.data() + z.size());
  }
  return out;
}

// Replaces one kind of latent of every window with `values` (count checked).
void replace_latents(EncodedMotion* code, bool local, int size, const float* values, size_t count) {
  const size_t expected = code->windows.size() * static_cast<size_t>(size);
  const char* what = local ? "local" : "global";
  if (count != expected)
    throw ApiError(MF_ERROR_INVALID_ARGUMENT, std::string(what) + "_count is " + std::to_string(count) + ", expected " +
                                                  std::to_string(expected) + " (" +
                                                  std::to_string(code->windows.size()) + " windows x " +
                                                  std::to_string(size) + ")");
  for (size_t i = 0; i < count; ++i)
    if (!std::isfinite(values[i]))
      throw ApiError(MF_ERROR_INVALID_ARGUMENT,
                     std::string(what) + " latent value " + std::to_string(i) + " is not finite");
  for (size_t w = 0; w < code->windows.size(); ++w)
    (local ? code->windows[w].z_l : code->windows[w].z_g) =
        Eigen::Map<const Eigen::VectorXf>(values + w * static_cast<size_t>(size), size);
}

void check_fps(double fps) {
  if (!(std::isfinite(fps) && fps > 0)) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "fps must be finite and positive");
}

}  // namespace
}  // namespace mf::capi

using mf::capi::ApiError;
using mf::capi::guard;
using mf::capi::require;

extern "C" {

int mf_codec_options_init(mf_codec_options* options) {
  return guard([&] {
    require(options, "options");
    std::memset(options, 0, sizeof *options);
    options->struct_size = sizeof *options;
  });
}

int mf_encode(const mf_model* model, const mf_motion* input, const mf_codec_options* options, mf_encoding** out) {
  return guard([&] {
    require(model, "model");
    require(input, "input");
    require(out, "out");
    const mf_codec_options o = mf::capi::codec_options(options);
    if (!model->model) throw mf::ModelMissingError("encoding needs the prior, and none is loaded");
    const int model_joints = model->model->rig().num_joints();
    if (input->motion.num_joints() != model_joints)
      throw ApiError(MF_ERROR_INVALID_ARGUMENT, "the motion has " + std::to_string(input->motion.num_joints()) +
                                                    " joints but the model's skeleton has " +
                                                    std::to_string(model_joints));
    mf::CodecOptions co;
    co.hop = o.hop;
    const mf::capi::TaskThreads threads;
    auto handle = std::make_unique<mf_encoding>();
    handle->model = model->model;
    handle->code = mf::encode_motion(*model->model, input->motion, co);
    handle->shell.layout = input->layout;
    handle->shell.layout_fps = input->layout_fps;
    handle->shell.length_scale = input->length_scale;
    *out = handle.release();
  });
}

void mf_encoding_destroy(mf_encoding* encoding) { delete encoding; }

int mf_encoding_get_window_count(const mf_encoding* encoding, int32_t* out) {
  return guard([&] {
    const mf_encoding& e = mf::capi::get(encoding);
    require(out, "out");
    *out = static_cast<int32_t>(e.code.windows.size());
  });
}

int mf_encoding_get_duration(const mf_encoding* encoding, double* out) {
  return guard([&] {
    const mf_encoding& e = mf::capi::get(encoding);
    require(out, "out");
    const size_t n = e.code.source_root_positions.size();
    *out = n > 1 ? static_cast<double>(n - 1) / e.code.source_fps : 0.0;
  });
}

int mf_encoding_get_window_times(const mf_encoding* encoding, double* out, size_t capacity, size_t* needed) {
  return guard([&] {
    const mf_encoding& e = mf::capi::get(encoding);
    std::vector<double> times;
    for (const mf::WindowCode& w : e.code.windows) times.push_back(w.start / e.code.fps);
    mf::capi::write_buffer(times.data(), times.size(), out, capacity, needed);
  });
}

int mf_encoding_get_local_latents(const mf_encoding* encoding, float* out, size_t capacity, size_t* needed) {
  return guard([&] {
    const std::vector<float> z = mf::capi::latents(mf::capi::get(encoding).code, true);
    mf::capi::write_buffer(z.data(), z.size(), out, capacity, needed);
  });
}

int mf_encoding_get_global_latents(const mf_encoding* encoding, float* out, size_t capacity, size_t* needed) {
  return guard([&] {
    const std::vector<float> z = mf::capi::latents(mf::capi::get(encoding).code, false);
    mf::capi::write_buffer(z.data(), z.size(), out, capacity, needed);
  });
}

int mf_encoding_with_latents(const mf_encoding* encoding, const float* local_latents, size_t local_count,
                             const float* global_latents, size_t global_count, mf_encoding** out) {
  return guard([&] {
    const mf_encoding& e = mf::capi::get(encoding);
    require(out, "out");
    if (!local_latents && local_count != 0) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "local_latents is NULL");
    if (!global_latents && global_count != 0) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "global_latents is NULL");
    auto handle = std::make_unique<mf_encoding>();
    handle->model = e.model;
    handle->code = e.code;
    handle->shell.layout = e.shell.layout;
    handle->shell.layout_fps = e.shell.layout_fps;
    handle->shell.length_scale = e.shell.length_scale;
    const mf::NemfConfig& config = e.model->config();
    if (local_latents) mf::capi::replace_latents(&handle->code, true, config.zl, local_latents, local_count);
    if (global_latents) mf::capi::replace_latents(&handle->code, false, config.zg, global_latents, global_count);
    *out = handle.release();
  });
}

int mf_decode(const mf_encoding* encoding, double fps, int32_t frame_count, const mf_codec_options* options,
              mf_motion** out) {
  return guard([&] {
    const mf_encoding& e = mf::capi::get(encoding);
    require(out, "out");
    const mf_codec_options o = mf::capi::codec_options(options);
    mf::capi::check_fps(fps);
    if (frame_count < 0)
      throw ApiError(MF_ERROR_INVALID_ARGUMENT, "frame_count must not be negative (" + std::to_string(frame_count) + ")");
    int frames = frame_count;
    if (frames == 0)
      frames = mf::resampled_frame_count(static_cast<int>(e.code.source_root_positions.size()), e.code.source_fps,
                                         fps, nullptr);
    const mf::capi::TaskThreads threads;
    *out = mf::capi::derived_motion(mf::decode_motion(*e.model, e.code, fps, frames, mf::capi::decode_options(o)),
                                    e.shell);
  });
}

int mf_decode_times(const mf_encoding* encoding, const double* times, size_t time_count, double fps,
                    const mf_codec_options* options, mf_motion** out) {
  return guard([&] {
    const mf_encoding& e = mf::capi::get(encoding);
    require(times, "times");
    require(out, "out");
    const mf_codec_options o = mf::capi::codec_options(options);
    mf::capi::check_fps(fps);
    if (time_count < 1) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "time_count must be at least 1");
    if (time_count > 10'000'000) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "time_count is above 10 million");
    std::vector<double> t(times, times + time_count);
    for (size_t i = 0; i < t.size(); ++i)
      if (!std::isfinite(t[i]))
        throw ApiError(MF_ERROR_INVALID_ARGUMENT, "times[" + std::to_string(i) + "] is not finite");
    const mf::capi::TaskThreads threads;
    *out = mf::capi::derived_motion(mf::decode_times(*e.model, e.code, t, fps, mf::capi::decode_options(o)), e.shell);
  });
}

}  // extern "C"
