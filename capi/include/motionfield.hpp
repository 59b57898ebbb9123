// motionfield.hpp: a small header-only C++17 layer over motionfield.h.
//
// It adds no behaviour of its own: every call is one C call (or a size query
// and the call), with C++ types around it.
//   - Handles (Model, Motion, Encoding, CancelToken) own one C handle each and
//     free it when they go out of scope. They are move-only; a moved-from or
//     default-constructed handle is empty (get() == nullptr). An empty Model is
//     "no model", which the tasks accept for methods that do not need one.
//   - A failed call throws motionfield::Error, carrying the C status
//     (MF_ERROR_*) and mf_last_error_message(). Nothing else is thrown, except
//     std::bad_alloc and what a progress callback throws (see TaskOptions).
//   - Buffers and strings come back as std::vector and std::string, in the
//     layouts of motionfield.h ("Arrays": row-major, quaternions w, x, y, z,
//     metres, seconds).
// The namespace is `motionfield`, so programs may also link motionfield's
// C++ internals (namespace mf) without a clash. Threads: as motionfield.h says
// (models and motions may be shared; one call per CancelToken is thread-safe).
//
//   motionfield::Model model = motionfield::Model::load_default();
//   motionfield::Motion walk = motionfield::Motion::load_bvh("walk.bvh");
//   motionfield::Motion out = motionfield::inbetween(model, walk, {0, 30, 60});
//   out.save_bvh("out.bvh");
#ifndef MOTIONFIELD_HPP
#define MOTIONFIELD_HPP

#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "motionfield.h"

namespace motionfield {

// ---------------------------------------------------------------- errors

/// A C call that returned a status other than MF_OK.
class Error : public std::runtime_error {
 public:
  Error(int status, const std::string& message) : std::runtime_error(message), status_(status) {}
  /// The MF_ERROR_* code.
  int status() const noexcept { return status_; }
  /// Its name, e.g. "MF_ERROR_IO".
  const char* status_name() const noexcept { return mf_status_name(status_); }

 private:
  int status_;
};

/// Throws Error(status, mf_last_error_message()) unless status is MF_OK.
inline void check(int status) {
  if (status != MF_OK) throw Error(status, mf_last_error_message());
}

namespace detail {

// Owns one C handle; Destroy accepts NULL, as every *_destroy does.
template <class T, void (*Destroy)(T*)>
class Handle {
 public:
  Handle() noexcept = default;
  explicit Handle(T* handle) noexcept : handle_(handle) {}
  Handle(Handle&& other) noexcept : handle_(std::exchange(other.handle_, nullptr)) {}
  Handle& operator=(Handle&& other) noexcept {
    if (this != &other) Destroy(std::exchange(handle_, std::exchange(other.handle_, nullptr)));
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() { Destroy(handle_); }

  /// The C handle (still owned by this object), or nullptr when empty.
  T* get() const noexcept { return handle_; }
  /// Gives up ownership: the caller destroys the returned handle.
  T* release() noexcept { return std::exchange(handle_, nullptr); }
  explicit operator bool() const noexcept { return handle_ != nullptr; }

 private:
  T* handle_ = nullptr;
};

// A string getter: `get(out, capacity, needed)`, a size query first.
template <class Get>
std::string read_string(Get&& get) {
  size_t needed = 0;
  check(get(nullptr, 0, &needed));
  std::string text(needed, '\0');
  check(get(text.data(), text.size(), &needed));
  text.resize(needed > 0 ? needed - 1 : 0);
  return text;
}

// An array getter: `get(out, capacity, needed)` with capacity in elements.
template <class T, class Get>
std::vector<T> read_array(Get&& get) {
  size_t needed = 0;
  check(get(nullptr, 0, &needed));
  std::vector<T> values(needed);
  check(get(values.data(), values.size(), &needed));
  return values;
}

template <class T, class Get>
T read_value(Get&& get) {
  T value{};
  check(get(&value));
  return value;
}

}  // namespace detail

// ---------------------------------------------------------------- library

/// mf_version_string(): the loaded library's version, e.g. "0.2.0".
inline std::string version() { return mf_version_string(); }
/// mf_abi_version(): the loaded library's ABI major (compare with MF_ABI_VERSION).
inline uint32_t abi_version() { return mf_abi_version(); }
/// mf_printable_text: `text` as the library records messages (non-printable
/// bytes escaped, at most MF_MESSAGE_MAX_BYTES), for messages of your own.
inline std::string printable_text(const std::string& text) {
  return detail::read_string([&](char* out, size_t capacity, size_t* needed) {
    return mf_printable_text(text.data(), text.size(), out, capacity, needed);
  });
}
/// mf_set_num_threads: intra-op threads of the whole process (1..1024).
inline void set_num_threads(int32_t threads) { check(mf_set_num_threads(threads)); }
inline int32_t num_threads() { return detail::read_value<int32_t>(mf_get_num_threads); }

// ---------------------------------------------------------------- handles

/// A loaded model (the prior, with the transformers and rig anatomy next to
/// it). Empty means "no model".
class Model : public detail::Handle<mf_model, mf_model_destroy> {
 public:
  using Handle::Handle;

  /// mf_model_load(path).
  static Model load(const std::string& path) {
    mf_model* m = nullptr;
    check(mf_model_load(path.c_str(), &m));
    return Model(m);
  }
  /// mf_model_load(NULL): the default model; Error MF_ERROR_IO if none exists.
  static Model load_default() {
    mf_model* m = nullptr;
    check(mf_model_load(nullptr, &m));
    return Model(m);
  }
  /// mf_model_load_from_memory: the bytes of a model file (copied).
  static Model load_from_memory(const void* data, size_t size) {
    mf_model* m = nullptr;
    check(mf_model_load_from_memory(data, size, &m));
    return Model(m);
  }
  /// mf_model_with_inbetweener: a new model with the transformer file at `path`.
  Model with_inbetweener(const std::string& path) const {
    mf_model* m = nullptr;
    check(mf_model_with_inbetweener(get(), path.c_str(), &m));
    return Model(m);
  }
  /// mf_model_load_set: the model at `path` ("" = the default model) with
  /// the transformer files `inbetweeners` added in order.
  static Model load_set(const std::string& path, const std::vector<std::string>& inbetweeners) {
    std::vector<const char*> files;
    for (const std::string& file : inbetweeners) files.push_back(file.c_str());
    mf_model* m = nullptr;
    check(mf_model_load_set(path.empty() ? nullptr : path.c_str(), files.data(), files.size(), &m));
    return Model(m);
  }
  /// mf_model_get_load_warnings: the files next to the model that did not load, one warning per line.
  std::string load_warnings() const {
    return detail::read_string(
        [&](char* out, size_t capacity, size_t* needed) { return mf_model_get_load_warnings(get(), out, capacity, needed); });
  }
  /// mf_model_has_inbetweener: kind "twostage" or "citl".
  bool has_inbetweener(const std::string& kind) const {
    int32_t has = 0;
    check(mf_model_has_inbetweener(get(), kind.c_str(), &has));
    return has != 0;
  }

  /// mf_model_describe: the format version, the transformers and what did
  /// not load next to the prior, as JSON text.
  std::string describe() const {
    return detail::read_string(
        [&](char* out, size_t capacity, size_t* needed) { return mf_model_describe(get(), out, capacity, needed); });
  }

  int32_t joint_count() const {
    return detail::read_value<int32_t>([&](int32_t* n) { return mf_model_get_joint_count(get(), n); });
  }
  std::vector<std::string> joint_names() const {
    std::vector<std::string> names;
    for (int32_t j = 0, n = joint_count(); j < n; ++j)
      names.push_back(detail::read_string([&](char* out, size_t capacity, size_t* needed) {
        return mf_model_get_joint_name(get(), j, out, capacity, needed);
      }));
    return names;
  }
  /// Frame rate of the training data.
  double fps() const {
    return detail::read_value<double>([&](double* fps) { return mf_model_get_fps(get(), fps); });
  }
  /// Frames per window (one latent code).
  int32_t window() const {
    return detail::read_value<int32_t>([&](int32_t* n) { return mf_model_get_window(get(), n); });
  }
};

/// mf_model_default_path: "" when no default model exists.
inline std::string default_model_path() { return detail::read_string(mf_model_default_path); }

/// mf_motion_load_options, as C++ values (every default is the C default).
struct LoadOptions {
  int32_t format = MF_FORMAT_AUTO;
  double length_scale = 0.0;   ///< BVH: metres per file unit, 0 detects it
  std::string animation;       ///< glTF, FBX: by name ("": by index)
  int32_t animation_index = 0;
  double fps = 0.0;            ///< glTF, FBX: the sampling rate, 0 = the keys' rate
};

/// A skeleton with per-frame local rotations and root positions (immutable).
class Motion : public detail::Handle<mf_motion, mf_motion_destroy> {
 public:
  using Handle::Handle;

  /// mf_motion_load: a BVH, glTF or FBX file, the format from its content or name.
  static Motion load(const std::string& path, const LoadOptions& options = {}) {
    const mf_motion_load_options o = load_options(options);
    mf_motion* m = nullptr;
    check(mf_motion_load(path.c_str(), &o, &m));
    return Motion(m);
  }
  /// mf_motion_load_from_memory.
  static Motion load_from_memory(const std::vector<uint8_t>& bytes, const LoadOptions& options = {}) {
    const mf_motion_load_options o = load_options(options);
    mf_motion* m = nullptr;
    check(mf_motion_load_from_memory(bytes.data(), bytes.size(), &o, &m));
    return Motion(m);
  }
  /// mf_motion_load_bvh; length_scale 0 detects the unit (metres per file unit).
  static Motion load_bvh(const std::string& path, double length_scale = 0.0) {
    const mf_bvh_options o = bvh_options(length_scale);
    mf_motion* m = nullptr;
    check(mf_motion_load_bvh(path.c_str(), &o, &m));
    return Motion(m);
  }
  /// mf_motion_load_bvh_from_memory: BVH text.
  static Motion load_bvh_from_memory(const std::string& text, double length_scale = 0.0) {
    const mf_bvh_options o = bvh_options(length_scale);
    mf_motion* m = nullptr;
    check(mf_motion_load_bvh_from_memory(text.data(), text.size(), &o, &m));
    return Motion(m);
  }
  /// mf_motion_save_bvh (atomic); length_scale 0 keeps the unit it was read in.
  void save_bvh(const std::string& path, double length_scale = 0.0) const {
    const mf_bvh_options o = bvh_options(length_scale);
    check(mf_motion_save_bvh(get(), path.c_str(), &o));
  }
  /// mf_motion_save_bvh_to_memory: the BVH text save_bvh would write.
  std::string to_bvh(double length_scale = 0.0) const {
    const mf_bvh_options o = bvh_options(length_scale);
    return detail::read_string([&](char* out, size_t capacity, size_t* needed) {
      return mf_motion_save_bvh_to_memory(get(), &o, out, capacity, needed);
    });
  }

  /// mf_motion_save_gltf (atomic); format MF_GLTF_AUTO: from the extension (.glb, .gltf).
  void save_gltf(const std::string& path, int32_t format = MF_GLTF_AUTO) const {
    const mf_gltf_options o = gltf_options(format);
    check(mf_motion_save_gltf(get(), path.c_str(), &o));
  }
  /// mf_motion_save_gltf_to_memory: the bytes save_gltf would write (binary by default).
  std::vector<uint8_t> to_gltf(int32_t format = MF_GLTF_BINARY) const {
    const mf_gltf_options o = gltf_options(format);
    return detail::read_array<uint8_t>([&](uint8_t* out, size_t capacity, size_t* needed) {
      return mf_motion_save_gltf_to_memory(get(), &o, out, capacity, needed);
    });
  }

  int32_t frame_count() const { return value<int32_t>(mf_motion_get_frame_count); }
  int32_t joint_count() const { return value<int32_t>(mf_motion_get_joint_count); }
  double fps() const { return value<double>(mf_motion_get_fps); }
  /// Seconds between frames as a BVH save writes them.
  double frame_time() const { return value<double>(mf_motion_get_frame_time); }
  /// Metres per file unit the motion was read with.
  double length_scale() const { return value<double>(mf_motion_get_length_scale); }

  std::vector<std::string> joint_names() const {
    std::vector<std::string> names;
    for (int32_t j = 0, n = joint_count(); j < n; ++j)
      names.push_back(detail::read_string([&](char* out, size_t capacity, size_t* needed) {
        return mf_motion_get_joint_name(get(), j, out, capacity, needed);
      }));
    return names;
  }
  /// [joints] parent indices, -1 for joint 0.
  std::vector<int32_t> parents() const { return array<int32_t>(mf_motion_get_parents); }
  /// [joints][3] rest offsets, metres.
  std::vector<float> offsets() const { return array<float>(mf_motion_get_offsets); }
  /// [frames][joints][4] local rotations (w, x, y, z).
  std::vector<float> rotations() const { return array<float>(mf_motion_get_rotations); }
  /// [frames][3] root positions, metres.
  std::vector<float> root_positions() const { return array<float>(mf_motion_get_root_positions); }
  /// [frames][joints][3] global joint positions, metres.
  std::vector<float> global_positions() const { return array<float>(mf_motion_get_global_positions); }
  /// mf_motion_get_warnings: what the task that made this motion wants the
  /// user to know, one sentence per line; "" if nothing.
  std::string warnings() const {
    return detail::read_string([&](char* out, size_t capacity, size_t* needed) {
      return mf_motion_get_warnings(get(), out, capacity, needed);
    });
  }

 private:
  static mf_bvh_options bvh_options(double length_scale) {
    mf_bvh_options o;
    check(mf_bvh_options_init(&o));
    o.length_scale = length_scale;
    return o;
  }
  static mf_motion_load_options load_options(const LoadOptions& options) {
    mf_motion_load_options o;
    check(mf_motion_load_options_init(&o));
    o.format = options.format;
    o.length_scale = options.length_scale;
    o.animation = options.animation.c_str();
    o.animation_index = options.animation_index;
    o.fps = options.fps;
    return o;
  }
  static mf_gltf_options gltf_options(int32_t format) {
    mf_gltf_options o;
    check(mf_gltf_options_init(&o));
    o.format = format;
    return o;
  }
  template <class T, class Get>
  T value(Get get_value) const {
    return detail::read_value<T>([&](T* out) { return get_value(get(), out); });
  }
  template <class T, class Get>
  std::vector<T> array(Get get_array) const {
    return detail::read_array<T>(
        [&](T* out, size_t capacity, size_t* needed) { return get_array(get(), out, capacity, needed); });
  }
};

/// A flag that stops running tasks; cancel() may be called from any thread.
class CancelToken : public detail::Handle<mf_cancel_token, mf_cancel_token_destroy> {
 public:
  using Handle::Handle;

  /// A new, not cancelled token.
  static CancelToken create() {
    mf_cancel_token* t = nullptr;
    check(mf_cancel_token_create(&t));
    return CancelToken(t);
  }
  void cancel() { check(mf_cancel_token_cancel(get())); }
  void reset() { check(mf_cancel_token_reset(get())); }
  bool is_cancelled() const {
    return detail::read_value<int32_t>([&](int32_t* out) { return mf_cancel_token_is_cancelled(get(), out); }) != 0;
  }
};

// ---------------------------------------------------------------- methods

/// A registered method (mf_method_get).
struct MethodInfo {
  std::string name, description;
  uint32_t flags = 0;  ///< MF_METHOD_* bits
  bool needs_model() const { return (flags & MF_METHOD_NEEDS_MODEL) != 0; }
  bool completes() const { return (flags & MF_METHOD_COMPLETES) != 0; }
  bool resamples() const { return (flags & MF_METHOD_RESAMPLES) != 0; }
};

namespace detail {
inline MethodInfo method_at(int32_t index) {
  const char* name = nullptr;
  const char* description = nullptr;
  uint32_t flags = 0;
  check(mf_method_get(index, &name, &description, &flags));
  return {name, description, flags};
}
}  // namespace detail

/// Every registered method, in the library's order.
inline std::vector<MethodInfo> methods() {
  std::vector<MethodInfo> all;
  for (int32_t i = 0, n = detail::read_value<int32_t>(mf_method_count); i < n; ++i) all.push_back(detail::method_at(i));
  return all;
}
/// The method named `name`; Error MF_ERROR_INVALID_ARGUMENT (listing the
/// methods) if there is none.
inline MethodInfo find_method(const std::string& name) {
  int32_t index = 0;
  check(mf_method_find(name.c_str(), &index));
  return detail::method_at(index);
}
/// mf_default_method: the in-betweening method used when none is named.
inline std::string default_method(const Model& model) {
  const char* name = nullptr;
  check(mf_default_method(model.get(), &name));
  return name;
}

// ---------------------------------------------------------------- tasks

/// mf_task_options in C++ types.
struct TaskOptions {
  TaskOptions() = default;
  /// Only a method: `inbetween(model, motion, keys, {"interp"})`.
  TaskOptions(std::string method_name) : method(std::move(method_name)) {}

  std::string method;  ///< "" = the default method
  uint64_t seed = 0;
  /// Called with each progress report; return false to cancel. An exception
  /// it throws cancels the task and is rethrown from the task's call.
  std::function<bool(const mf_progress&)> progress;
  CancelToken* cancel = nullptr;  ///< optional; must outlive the call
  std::string rig_map;            ///< JSON text; "" = automatic
  std::string rig_map_path;       ///< a JSON file; "" = none
  int32_t max_iterations = 0;     ///< iteration budget of iterative methods; 0 = each method's own
  bool no_fallback = false;       ///< keep the latent solvers' result where it misses the keys (mf_task_options)
};

/// mf_renav_options in C++ types.
struct RenavOptions {
  int32_t path_kind = MF_PATH_PER_FRAME;  ///< or MF_PATH_POLYLINE
  int32_t frame_count = 0;                ///< polyline: output frames (0 = from the speed)
  double fps = 0.0;                       ///< 0 = the reference's
};

namespace detail {

// One task call: the C options (pointing into `options`) and the progress
// trampoline, which keeps exceptions from crossing the C boundary.
class TaskCall {
 public:
  explicit TaskCall(const TaskOptions& options) : options_(options) {
    check(mf_task_options_init(&c_));
    c_.method = options.method.empty() ? nullptr : options.method.c_str();
    c_.seed = options.seed;
    c_.cancel = options.cancel ? options.cancel->get() : nullptr;
    c_.rig_map = options.rig_map.empty() ? nullptr : options.rig_map.c_str();
    c_.rig_map_path = options.rig_map_path.empty() ? nullptr : options.rig_map_path.c_str();
    c_.max_iterations = options.max_iterations;
    c_.no_fallback = options.no_fallback ? 1 : 0;
    if (options.progress) {
      c_.progress = &TaskCall::on_progress;
      c_.user_data = this;
    }
  }
  TaskCall(const TaskCall&) = delete;
  TaskCall& operator=(const TaskCall&) = delete;

  const mf_task_options* options() const { return &c_; }

  // The result of the C call that returned `status` and `out`.
  Motion finish(int status, mf_motion* out) { return finish_handle(status, Motion(out)); }

  // The same for any handle the call made.
  template <class H>
  H finish_handle(int status, H result) {
    if (error_) std::rethrow_exception(error_);
    check(status);
    return result;
  }

 private:
  static int on_progress(void* self, const mf_progress* progress) noexcept {
    TaskCall* call = static_cast<TaskCall*>(self);
    try {
      return call->options_.progress(*progress) ? 0 : 1;
    } catch (...) {
      call->error_ = std::current_exception();
      return 1;
    }
  }

  const TaskOptions& options_;
  mf_task_options c_;
  std::exception_ptr error_;
};

}  // namespace detail

/// mf_inbetween: keeps `keyframes` (strictly increasing, at least two) and
/// produces every other frame.
inline Motion inbetween(const Model& model, const Motion& input, const std::vector<int32_t>& keyframes,
                        const TaskOptions& options = {}) {
  detail::TaskCall call(options);
  mf_motion* out = nullptr;
  const int status = mf_inbetween(model.get(), input.get(), keyframes.data(), keyframes.size(), call.options(), &out);
  return call.finish(status, out);
}

/// mf_fill: frames gap_begin..gap_end-1 are unknown.
inline Motion fill(const Model& model, const Motion& input, int32_t gap_begin, int32_t gap_end,
                   const TaskOptions& options = {}) {
  detail::TaskCall call(options);
  mf_motion* out = nullptr;
  const int status = mf_fill(model.get(), input.get(), gap_begin, gap_end, call.options(), &out);
  return call.finish(status, out);
}

/// mf_resample to `fps`, keeping the time span (see Motion::warnings()).
inline Motion resample(const Model& model, const Motion& input, double fps, const TaskOptions& options = {}) {
  detail::TaskCall call(options);
  mf_motion* out = nullptr;
  const int status = mf_resample(model.get(), input.get(), fps, call.options(), &out);
  return call.finish(status, out);
}

/// mf_renav along `path_xz` ([points][2] floats, metres).
inline Motion renav(const Model& model, const Motion& reference, const std::vector<float>& path_xz,
                    const RenavOptions& renav_options = {}, const TaskOptions& options = {}) {
  mf_renav_options r;
  check(mf_renav_options_init(&r));
  r.path_kind = renav_options.path_kind;
  r.frame_count = renav_options.frame_count;
  r.fps = renav_options.fps;
  detail::TaskCall call(options);
  mf_motion* out = nullptr;
  const int status =
      mf_renav(model.get(), reference.get(), path_xz.data(), path_xz.size() / 2, &r, call.options(), &out);
  return call.finish(status, out);
}

/// mf_resample_frame_count: the output frame count and whether it was rounded down.
struct ResampledFrameCount {
  int32_t frames = 0;
  bool rounded = false;
};
inline ResampledFrameCount resample_frame_count(int32_t frames, double fps_in, double fps_out) {
  int32_t n = 0, rounded = 0;
  check(mf_resample_frame_count(frames, fps_in, fps_out, &n, &rounded));
  return {n, rounded != 0};
}

/// mf_path_load_csv: [points][2] floats (x, z, metres).
inline std::vector<float> load_path_csv(const std::string& path) {
  return detail::read_array<float>([&](float* out, size_t capacity, size_t* needed) {
    return mf_path_load_csv(path.c_str(), out, capacity, needed);
  });
}

/// mf_length_unit_scale: metres per unit of "cm", "m", "mm", "in", "ft", "asf".
inline double length_unit_scale(const std::string& unit) {
  return detail::read_value<double>([&](double* out) { return mf_length_unit_scale(unit.c_str(), out); });
}

/// mf_rig_describe: how `motion`'s rig maps onto `model`'s, as JSON text.
inline std::string rig_describe(const Model& model, const Motion& motion, const std::string& rig_map_json = "") {
  return detail::read_string([&](char* out, size_t capacity, size_t* needed) {
    return mf_rig_describe(model.get(), motion.get(), rig_map_json.c_str(), out, capacity, needed);
  });
}

/// mf_rig_map_read_file: a rig map file's text, within the library's limit.
inline std::string rig_map_read_file(const std::string& path) {
  return detail::read_string([&](char* out, size_t capacity, size_t* needed) {
    return mf_rig_map_read_file(path.c_str(), out, capacity, needed);
  });
}

// ---------------------------------------------------------------- encode, decode

/// mf_codec_options in C++ types.
struct CodecOptions {
  int32_t hop = 0;                           ///< encoding: 0 = window / 2
  int32_t root_source = MF_ROOT_FROM_PRIOR;  ///< decoding: or MF_ROOT_FROM_INPUT
};

namespace detail {
inline mf_codec_options codec_options(const CodecOptions& options) {
  mf_codec_options o;
  check(mf_codec_options_init(&o));
  o.hop = options.hop;
  o.root_source = options.root_source;
  return o;
}
}  // namespace detail

/// A motion encoded by a model as window latents (immutable).
class Encoding : public detail::Handle<mf_encoding, mf_encoding_destroy> {
 public:
  using Handle::Handle;

  int32_t window_count() const {
    return detail::read_value<int32_t>([&](int32_t* n) { return mf_encoding_get_window_count(get(), n); });
  }
  /// Seconds from the first to the last encoded frame.
  double duration() const {
    return detail::read_value<double>([&](double* d) { return mf_encoding_get_duration(get(), d); });
  }
  std::vector<double> window_times() const { return array<double>(mf_encoding_get_window_times); }
  std::vector<float> local_latents() const { return array<float>(mf_encoding_get_local_latents); }
  std::vector<float> global_latents() const { return array<float>(mf_encoding_get_global_latents); }
  /// mf_encoding_with_latents; an empty vector keeps that part.
  Encoding with_latents(const std::vector<float>& local, const std::vector<float>& global) const {
    mf_encoding* e = nullptr;
    check(mf_encoding_with_latents(get(), local.empty() ? nullptr : local.data(), local.size(),
                                   global.empty() ? nullptr : global.data(), global.size(), &e));
    return Encoding(e);
  }
  /// mf_decode at i / fps; frame_count 0 = the frames that fit the encoded span.
  Motion decode(double fps, int32_t frame_count = 0, const CodecOptions& options = {}) const {
    const mf_codec_options o = detail::codec_options(options);
    mf_motion* m = nullptr;
    check(mf_decode(get(), fps, frame_count, &o, &m));
    return Motion(m);
  }
  /// mf_decode_times: one frame per time (seconds).
  Motion decode_times(const std::vector<double>& times, double fps, const CodecOptions& options = {}) const {
    const mf_codec_options o = detail::codec_options(options);
    mf_motion* m = nullptr;
    check(mf_decode_times(get(), times.data(), times.size(), fps, &o, &m));
    return Motion(m);
  }

 private:
  template <class T, class Get>
  std::vector<T> array(Get get_array) const {
    return detail::read_array<T>(
        [&](T* out, size_t capacity, size_t* needed) { return get_array(get(), out, capacity, needed); });
  }
};

/// mf_encode: `input` (on the model's skeleton) as window latents.
inline Encoding encode(const Model& model, const Motion& input, const CodecOptions& options = {}) {
  const mf_codec_options o = detail::codec_options(options);
  mf_encoding* e = nullptr;
  check(mf_encode(model.get(), input.get(), &o, &e));
  return Encoding(e);
}

// ---------------------------------------------------------------- constraints

/// mf_constraints: whole-pose and partial keys, end-effector targets and
/// contact pins, joints by name, positions in the input's unit
/// (docs/CONSTRAINTS.md). The add_* calls return *this for chaining.
class Constraints : public detail::Handle<mf_constraints, mf_constraints_destroy> {
 public:
  using Handle::Handle;

  static Constraints create() {
    mf_constraints* c = nullptr;
    check(mf_constraints_create(&c));
    return Constraints(c);
  }
  /// mf_constraints_parse_json: the constraints file format.
  static Constraints parse_json(const std::string& json) {
    mf_constraints* c = nullptr;
    check(mf_constraints_parse_json(json.data(), json.size(), &c));
    return Constraints(c);
  }
  /// mf_constraints_load_json.
  static Constraints load_json(const std::string& path) {
    mf_constraints* c = nullptr;
    check(mf_constraints_load_json(path.c_str(), &c));
    return Constraints(c);
  }
  Constraints& add_pose_keys(const std::vector<int32_t>& frames) {
    check(mf_constraints_add_pose_keys(get(), frames.data(), frames.size()));
    return *this;
  }
  /// `root`: MF_ROOT_NONE, or MF_ROOT_POSITION and/or MF_ROOT_ROTATION.
  Constraints& add_partial_key(int32_t frame, const std::vector<std::string>& joints, uint32_t root = MF_ROOT_NONE) {
    std::vector<const char*> names;
    for (const std::string& j : joints) names.push_back(j.c_str());
    check(mf_constraints_add_partial_key(get(), frame, names.data(), names.size(), root));
    return *this;
  }
  Constraints& add_target(int32_t frame, const std::string& joint, const float (&position)[3], float weight = 1.0f) {
    check(mf_constraints_add_target(get(), frame, joint.c_str(), position, weight));
    return *this;
  }
  Constraints& add_contact(const std::string& joint, int32_t first, int32_t last) {
    check(mf_constraints_add_contact(get(), joint.c_str(), first, last));
    return *this;
  }
  /// mf_constraints_add_trajectory: `rows` holds 4 values per frame (x, z,
  /// forward_x, forward_z); its size must be 4 * frames.size().
  Constraints& add_trajectory(const std::vector<int32_t>& frames, const std::vector<float>& rows) {
    if (rows.size() != frames.size() * 4)
      throw Error(MF_ERROR_INVALID_ARGUMENT, "add_trajectory: rows must hold 4 values per frame (" +
                                                 std::to_string(frames.size() * 4) + "), got " +
                                                 std::to_string(rows.size()));
    check(mf_constraints_add_trajectory(get(), frames.data(), rows.data(), frames.size()));
    return *this;
  }
  /// mf_constraints_load_trajectory_csv.
  Constraints& load_trajectory_csv(const std::string& path) {
    check(mf_constraints_load_trajectory_csv(get(), path.c_str()));
    return *this;
  }
  std::string to_json() const {
    return detail::read_string([&](char* out, size_t capacity, size_t* needed) {
      return mf_constraints_to_json(get(), out, capacity, needed);
    });
  }
};

/// mf_solution: the method's motion (index 0) and the alternatives.
class Solution : public detail::Handle<mf_solution, mf_solution_destroy> {
 public:
  using Handle::Handle;

  int32_t count() const {
    return detail::read_value<int32_t>([&](int32_t* out) { return mf_solution_get_count(get(), out); });
  }
  Motion motion(int32_t index) const {
    mf_motion* m = nullptr;
    check(mf_solution_get_motion(get(), index, &m));
    return Motion(m);
  }
  mf_constraint_report report(int32_t index) const {
    mf_constraint_report r;
    check(mf_constraint_report_init(&r));
    check(mf_solution_get_report(get(), index, &r));
    return r;
  }
  /// mf_solution_get_method: the method that ran.
  std::string method() const {
    const char* name = nullptr;
    check(mf_solution_get_method(get(), &name));
    return name;
  }
  /// mf_solution_get_report_json: every solution's report and the warnings.
  std::string report_json() const {
    return detail::read_string([&](char* out, size_t capacity, size_t* needed) {
      return mf_solution_get_report_json(get(), out, capacity, needed);
    });
  }
  /// mf_solution_get_transition: the transition's frame count (a solution of
  /// transition() only).
  int32_t transition_frames() const {
    int32_t frames = 0;
    check(mf_solution_get_transition(get(), &frames, nullptr));
    return frames;
  }
  /// mf_solution_get_transition: the transition's first frame in the whole clip.
  int32_t transition_first_frame() const {
    int32_t first = 0;
    check(mf_solution_get_transition(get(), nullptr, &first));
    return first;
  }
};

/// mf_solve: `input` under `constraints`, plus `alternatives` more solutions.
inline Solution solve(const Model& model, const Motion& input, const Constraints& constraints,
                      int32_t alternatives = 0, const TaskOptions& options = {}) {
  detail::TaskCall call(options);
  mf_solution* out = nullptr;
  const int status = mf_solve(model.get(), input.get(), constraints.get(), alternatives, call.options(), &out);
  return call.finish_handle(status, Solution(out));
}

// ---------------------------------------------------------------- transitions

/// mf_transition_options in C++ types (the same defaults).
struct TransitionOptions {
  int32_t frames = 0;             ///< generated frames; 0 = automatic
  int32_t from_frame = -1;        ///< A's last kept frame; negative from the end
  int32_t to_frame = 0;           ///< B's first kept frame; negative from the end
  int32_t place = MF_PLACE_AUTO;  ///< or MF_PLACE_KEEP
  bool only_transition = false;   ///< only the generated frames
};

/// mf_transition: the end of `a` and the start of `b` with a transition
/// between them; `constraints` may be an empty handle (Constraints()).
inline Solution transition(const Model& model, const Motion& a, const Motion& b,
                           const TransitionOptions& transition = {}, const Constraints& constraints = Constraints(),
                           int32_t alternatives = 0, const TaskOptions& options = {}) {
  mf_transition_options t;
  check(mf_transition_options_init(&t));
  t.frames = transition.frames;
  t.from_frame = transition.from_frame;
  t.to_frame = transition.to_frame;
  t.place = transition.place;
  t.only_transition = transition.only_transition ? 1 : 0;
  detail::TaskCall call(options);
  mf_solution* out = nullptr;
  const int status =
      mf_transition(model.get(), a.get(), b.get(), &t, constraints.get(), alternatives, call.options(), &out);
  return call.finish_handle(status, Solution(out));
}

// ---------------------------------------------------------------- output files

/// mf_output_set: the files one job reads and writes, checked together as
/// they are added, its outputs staged with write() and put in place by
/// commit(); destroyed uncommitted, it leaves no output behind.
class OutputSet : public detail::Handle<mf_output_set, mf_output_set_destroy> {
 public:
  using Handle::Handle;  // OutputSet() is no set; create() makes one

  /// An empty set (mf_output_set_create).
  static OutputSet create() {
    mf_output_set* out = nullptr;
    check(mf_output_set_create(&out));
    return OutputSet(out);
  }
  void add_input(const std::string& path, const std::string& role) {
    check(mf_output_set_add_input(get(), path.c_str(), role.c_str()));
  }
  void add_output(const std::string& path, const std::string& role) {
    check(mf_output_set_add_output(get(), path.c_str(), role.c_str()));
  }
  /// Adds every file of `job` under `label` ("line 3"), or none.
  void merge(const OutputSet& job, const std::string& label) {
    check(mf_output_set_merge(get(), job.get(), label.c_str()));
  }
  void write(const std::string& path, const void* data, size_t size) {
    check(mf_output_set_write(get(), path.c_str(), data, size));
  }
  void write(const std::string& path, const std::string& text) { write(path, text.data(), text.size()); }
  void write(const std::string& path, const std::vector<uint8_t>& bytes) { write(path, bytes.data(), bytes.size()); }
  void commit() { check(mf_output_set_commit(get())); }
};

// ---------------------------------------------------------------- programs
// How a program built on the library reports a failure, as the motionfield
// CLI and the job runner (mf_job_result) do: exit codes, "motionfield: ..."
// lines, the units option.

constexpr int kExitOk = 0;
constexpr int kExitInternal = 1;
constexpr int kExitBadInput = 2;

/// Bad input a program found itself (exit code 2): an Error with status
/// MF_ERROR_INVALID_ARGUMENT whose message is meant for the user as is.
class InputError : public Error {
 public:
  explicit InputError(const std::string& message) : Error(MF_ERROR_INVALID_ARGUMENT, message) {}
};

/// A failure as the user sees it: exit code 2 for bad input (the statuses
/// MF_ERROR_INVALID_ARGUMENT, MF_ERROR_IO, MF_ERROR_MODEL and
/// MF_ERROR_UNSUPPORTED), else 1 (internal); the message (for internal errors
/// after the status name).
struct Failure {
  int exit_code = kExitInternal;
  std::string message;
};

/// The Failure of the exception being handled; call only inside a catch block.
inline Failure current_failure() {
  try {
    throw;
  } catch (const Error& e) {
    const int s = e.status();
    if (s == MF_ERROR_INVALID_ARGUMENT || s == MF_ERROR_IO || s == MF_ERROR_MODEL || s == MF_ERROR_UNSUPPORTED)
      return {kExitBadInput, e.what()};
    return {kExitInternal, std::string(e.status_name()) + ": " + e.what()};
  } catch (const std::exception& e) {
    return {kExitInternal, e.what()};
  } catch (...) {
    return {kExitInternal, "unknown exception"};
  }
}

/// printable_text(text), or a note when even that fails (out of memory):
/// everything a program prints that holds a file name or input bytes.
inline std::string printable(const std::string& text) {
  try {
    return printable_text(text);
  } catch (...) {
    return "(a message that could not be made printable)";
  }
}

/// "motionfield: <prefix>error: <message>\n" ("internal error" for exit code 1), printable.
inline std::string failure_line(const Failure& failure, const std::string& prefix = "") {
  const char* kind = failure.exit_code == kExitBadInput ? "error" : "internal error";
  return "motionfield: " + printable(prefix + kind + ": " + failure.message) + "\n";
}

/// Each line of `warnings` as "motionfield: <prefix>warning: <line>\n", printable.
inline std::string warning_lines(const std::string& warnings, const std::string& prefix = "") {
  std::string out;
  for (size_t begin = 0; begin < warnings.size();) {
    size_t end = warnings.find('\n', begin);
    if (end == std::string::npos) end = warnings.size();
    out += "motionfield: " + printable(prefix + "warning: " + warnings.substr(begin, end - begin)) + "\n";
    begin = end + 1;
  }
  return out;
}

/// Metres per file unit of a units option (`what` names it in messages): ""
/// or "auto" = 0 (detected), a unit name (length_unit_scale) or a positive
/// number. InputError otherwise.
inline double units_scale(const std::string& units, const std::string& what) {
  if (units.empty() || units == "auto") return 0.0;
  double v = 0;
  const auto r = std::from_chars(units.data(), units.data() + units.size(), v);
  if (r.ec == std::errc() && r.ptr == units.data() + units.size()) {
    if (!(std::isfinite(v) && v > 0)) throw InputError(what + " must be positive, not " + units);
    return v;
  }
  try {
    return length_unit_scale(units);
  } catch (const Error& e) {
    throw InputError(what + ": " + e.what() + "; auto (the default) detects it");
  }
}

// ---------------------------------------------------------------- batch jobs

/// mf_job_runner_options in C++ types.
struct JobRunnerOptions {
  uint32_t flags = 0;                     ///< MF_JOB_VERBOSE, MF_JOB_QUIET, MF_JOB_PRELOAD_MODEL
  int32_t threads = 1;                    ///< named in the --verbose line
  std::string model;                      ///< "" = the default model
  std::vector<std::string> inbetweeners;  ///< transformer files added to the model
  std::string rig_map;                    ///< "" = none
  std::string units;                      ///< "" = auto
};

/// mf_job_result: a job's exit code, stderr lines and --json summary.
struct JobResult {
  int32_t exit_code = 0;
  std::string messages;  ///< each line "motionfield: ...\n"
  std::string json;      ///< one line, no newline

  /// Reads and destroys `result`.
  static JobResult take(mf_job_result* result) {
    detail::Handle<mf_job_result, mf_job_result_destroy> owned(result);
    JobResult r;
    check(mf_job_result_get_exit_code(result, &r.exit_code));
    r.messages = detail::read_string([&](char* out, size_t capacity, size_t* needed) {
      return mf_job_result_get_messages(result, out, capacity, needed);
    });
    r.json = detail::read_string(
        [&](char* out, size_t capacity, size_t* needed) { return mf_job_result_get_json(result, out, capacity, needed); });
    return r;
  }
};

/// mf_job: one line parsed and its files checked (JobRunner::check_line).
class Job : public detail::Handle<mf_job, mf_job_destroy> {
 public:
  using Handle::Handle;
  bool runnable() const { return mf_job_is_runnable(get()) != 0; }
  bool has_load_warnings() const { return mf_job_has_load_warnings(get()) != 0; }
};

/// mf_job_runner: the jobs of one run (a batch file), checked and run with the CLI's messages.
class JobRunner : public detail::Handle<mf_job_runner, mf_job_runner_destroy> {
 public:
  using Handle::Handle;

  /// mf_job_runner_create: loads options.model when given.
  static JobRunner create(const JobRunnerOptions& options) {
    mf_job_runner_options c;
    check(mf_job_runner_options_init(&c));
    std::vector<const char*> files;
    for (const std::string& file : options.inbetweeners) files.push_back(file.c_str());
    c.flags = options.flags;
    c.threads = options.threads;
    c.model = options.model.c_str();
    c.inbetweeners = files.data();
    c.inbetweener_count = files.size();
    c.rig_map = options.rig_map.empty() ? nullptr : options.rig_map.c_str();
    c.units = options.units.c_str();
    mf_job_runner* out = nullptr;
    check(mf_job_runner_create(&c, &out));
    return JobRunner(out);
  }
  /// mf_job_runner_check_line.
  Job check_line(const std::string& text, uint64_t line, const std::string& batch_path) {
    mf_job* out = nullptr;
    check(mf_job_runner_check_line(get(), text.data(), text.size(), line, batch_path.c_str(), &out));
    return Job(out);
  }
  /// mf_job_run, reporting progress to `progress` (may be empty; return false to cancel).
  JobResult run(Job& job, const std::function<bool(const mf_progress&)>& progress = {}) {
    Progress p{progress, nullptr};
    const mf_job_run_options options = run_options(0, p);
    mf_job_result* out = nullptr;
    const int status = mf_job_run(get(), job.get(), &options, &out);
    if (p.error) std::rethrow_exception(p.error);
    check(status);
    return JobResult::take(out);
  }
  /// mf_job_runner_run_line with `flags` (MF_JOB_SINGLE, MF_JOB_LOAD_WARNINGS).
  JobResult run_line(const std::string& text, uint64_t line, const std::string& batch_path, uint32_t flags,
                     const std::function<bool(const mf_progress&)>& progress = {}) {
    Progress p{progress, nullptr};
    const mf_job_run_options options = run_options(flags, p);
    mf_job_result* out = nullptr;
    const int status = mf_job_runner_run_line(get(), text.data(), text.size(), line, batch_path.c_str(), &options, &out);
    if (p.error) std::rethrow_exception(p.error);
    check(status);
    return JobResult::take(out);
  }
  /// mf_job_runner_load_model: the model (an empty Model when there is none).
  Model load_model() {
    mf_model* out = nullptr;
    check(mf_job_runner_load_model(get(), &out));
    return Model(out);
  }
  /// mf_job_runner_get_model_path: "" before a model is loaded.
  std::string model_path() const {
    return detail::read_string([&](char* out, size_t capacity, size_t* needed) {
      return mf_job_runner_get_model_path(get(), out, capacity, needed);
    });
  }

 private:
  struct Progress {
    const std::function<bool(const mf_progress&)>& fn;
    std::exception_ptr error;
  };
  static int on_progress(void* self, const mf_progress* progress) noexcept {
    Progress* p = static_cast<Progress*>(self);
    try {
      return p->fn(*progress) ? 0 : 1;
    } catch (...) {
      p->error = std::current_exception();
      return 1;
    }
  }
  static mf_job_run_options run_options(uint32_t flags, Progress& p) {
    mf_job_run_options options;
    check(mf_job_run_options_init(&options));
    options.flags = flags;
    if (p.fn) {
      options.progress = &JobRunner::on_progress;
      options.user_data = &p;
    }
    return options;
  }
};

/// The end of a batch (mf_job_batch_summary): its exit code and its last
/// standard-error line ("" when the batch prints none).
struct BatchSummary {
  int exit_code = kExitOk;
  std::string line;
};

/// mf_job_batch_summary of the jobs' exit codes; `flags`: MF_JOB_VERBOSE,
/// MF_JOB_QUIET, MF_JOB_PROGRESS_SHOWN.
inline BatchSummary batch_summary(const std::string& batch_path, const std::vector<int32_t>& exit_codes,
                                  uint32_t flags) {
  int32_t code = kExitOk;
  BatchSummary s;
  s.line = detail::read_string([&](char* out, size_t capacity, size_t* needed) {
    return mf_job_batch_summary(batch_path.c_str(), exit_codes.data(), exit_codes.size(), flags, &code, out, capacity,
                                needed);
  });
  s.exit_code = code;
  return s;
}

}  // namespace motionfield

#endif  // MOTIONFIELD_HPP
