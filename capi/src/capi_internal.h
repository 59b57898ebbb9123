// Internals of the C API shared by its translation units: the handle structs,
// the exception guard every exported body runs in, and helpers for options
// structs and caller buffers. Not installed.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "motionfield.h"
#include "prior/motion/bvh.h"
#include "prior/motion/motion.h"
#include "tasks/constraints/constraint_report.h"
#include "tasks/constraints/constraint_spec.h"
#include "tasks/context/task_context.h"
#include "tasks/methods/jobs.h"


/// The prior, the in-betweeners by kind and the rig anatomy loaded together
/// (tasks/context/task_context.h ModelSet): mf_model_load loads the in-betweeners and
/// the anatomy found next to the prior's file and keeps why a file there did
/// not load; mf_model_with_inbetweener adds one.
struct mf_model : mf::ModelSet {};

struct mf_motion {
  mf::Motion motion;
  /// The BVH document the motion (or the task input it came from) was read
  /// from, without its values; null for motions made from arrays.
  std::shared_ptr<const mf::BvhDocument> layout;
  /// The fps motion_from_bvh derived from layout->frame_time: a motion at this
  /// fps is written with the layout's frame time as written.
  double layout_fps = 0.0;
  /// Metres per BVH unit the motion was read with: the default for writing.
  double length_scale = 0.01;
  /// That unit's name ("cm", "m", ..., "custom") and whether it was detected
  /// from the skeleton (mf_bvh_options.length_scale 0 and humanoid legs found).
  std::string unit = "cm";
  bool unit_detected = false;
  /// The unit was set by the file (glTF: metres; FBX: its UnitScaleFactor).
  bool unit_from_file = false;
  /// Warnings of the task that made this motion, one per line ("" if none):
  /// mf_motion_get_warnings. Not passed on to motions derived from it.
  std::string warnings;
};

/// A caller's constraints, by joint name (tasks/constraints/constraint_spec.h).
struct mf_constraints {
  mf::ConstraintSpec spec;
};

/// The result of mf_solve and mf_transition.
struct mf_solution {
  std::vector<std::unique_ptr<mf_motion>> motions;
  std::vector<mf::ConstraintReport> reports;
  std::vector<std::string> warnings;
  double length_scale = 0.01;  ///< metres per input unit
  std::string unit;
  bool trajectory = false;  ///< the constraints had a trajectory (its report fields are written)
  const char* method = "";  ///< the registered method's name (static storage)
  /// mf_transition: the generated frames and the first one in the whole clip; 0: not a transition.
  int32_t transition_frames = 0;
  int32_t transition_first = 0;
};

struct mf_cancel_token {
  std::atomic<int> flag{0};
};

namespace mf::capi {

/// An error with its status code, thrown inside exported bodies.
class ApiError : public std::runtime_error {
 public:
  ApiError(int status, const std::string& message) : std::runtime_error(message), status_(status) {}
  int status() const { return status_; }

 private:
  int status_;
};

/// `text` in the printable, bounded form every message is recorded in (see
/// MF_MESSAGE_MAX_BYTES in motionfield.h): the one place that makes it.
std::string printable_text(const std::string& text, size_t max_bytes = MF_MESSAGE_MAX_BYTES);

/// Records `message` (in printable_text's form) as this thread's last error
/// and returns `status`.
int fail(int status, const char* message) noexcept;

/// Maps the exception being handled to a status code and records its message.
int fail_current_exception() noexcept;

/// Runs `body` and maps every exception to a status code and message.
template <class Body>
int guard(Body&& body) noexcept {
  try {
    body();
    return MF_OK;
  } catch (...) {
    return fail_current_exception();
  }
}

/// Throws MF_ERROR_INVALID_ARGUMENT "<what> is NULL" when p is null.
inline void require(const void* p, const char* what) {
  if (!p) throw ApiError(MF_ERROR_INVALID_ARGUMENT, std::string(what) + " is NULL");
}

/// Byte offsets of the pointer fields of an options struct. A struct_size that
/// ends inside one is no version of the struct a caller could compile
/// (published versions end between fields) and would hand the library half a
/// pointer, so read_options refuses it.
template <class T>
struct OptionPointerFields {
  static constexpr size_t offsets[1] = {0};  // struct_size itself: no pointer
  static constexpr size_t count = 0;
};
template <>
struct OptionPointerFields<mf_task_options> {
  static constexpr size_t offsets[6] = {offsetof(mf_task_options, method),    offsetof(mf_task_options, progress),
                                        offsetof(mf_task_options, user_data), offsetof(mf_task_options, cancel),
                                        offsetof(mf_task_options, rig_map),   offsetof(mf_task_options, rig_map_path)};
  static constexpr size_t count = 6;
};
static_assert(sizeof(mf_task_options) == 72,
              "mf_task_options changed: list its pointer fields in OptionPointerFields");
template <>
struct OptionPointerFields<mf_motion_load_options> {
  static constexpr size_t offsets[1] = {offsetof(mf_motion_load_options, animation)};
  static constexpr size_t count = 1;
};
static_assert(sizeof(mf_motion_load_options) == 40,
              "mf_motion_load_options changed: list its pointer fields in OptionPointerFields");

/// Copies a caller's options struct of type T into a default-initialised T,
/// reading only what fits in its struct_size; larger (newer) structs must have
/// zeros in the part this library does not know. Every default is zero.
template <class T>
T read_options(const T* user, const char* type_name) {
  T out;
  std::memset(&out, 0, sizeof out);
  out.struct_size = static_cast<uint32_t>(sizeof(T));
  if (!user) return out;
  const uint32_t size = user->struct_size;
  if (size < sizeof(uint32_t) || size > 65536)
    throw ApiError(MF_ERROR_INVALID_ARGUMENT, std::string(type_name) + ".struct_size is " + std::to_string(size) +
                                                  ": call " + type_name + "_init() first");
  for (size_t i = 0; i < OptionPointerFields<T>::count; ++i) {
    const size_t at = OptionPointerFields<T>::offsets[i];
    if (size > at && size < at + sizeof(void*))
      throw ApiError(MF_ERROR_INVALID_ARGUMENT, std::string(type_name) + ".struct_size is " + std::to_string(size) +
                                                    ": it ends inside a pointer field (bytes " + std::to_string(at) +
                                                    " to " + std::to_string(at + sizeof(void*) - 1) +
                                                    "); call " + type_name + "_init() first");
  }
  std::memcpy(&out, user, size < sizeof(T) ? size : sizeof(T));
  if (size > sizeof(T)) {
    const unsigned char* tail = reinterpret_cast<const unsigned char*>(user) + sizeof(T);
    for (size_t i = 0; i < size - sizeof(T); ++i) {
      if (tail[i] != 0)
        throw ApiError(MF_ERROR_UNSUPPORTED, std::string(type_name) + " sets a field (at byte " +
                                                 std::to_string(sizeof(T) + i) +
                                                 ") that this version of motionfield (" MF_VERSION_STRING
                                                 ") does not know");
    }
  }
  out.struct_size = static_cast<uint32_t>(sizeof(T));
  return out;
}

/// The argument checks of write_buffer() alone (a NULL buffer with a non-zero
/// capacity; a size query without `needed`), for functions that should refuse
/// them before doing expensive work.
inline void check_buffer_arguments(const void* out, size_t capacity, const size_t* needed) {
  if (!out && capacity != 0) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "the output buffer is NULL but its capacity is not 0");
  if (!out && !needed) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "a size query (NULL buffer) needs a non-NULL `needed`");
}

/// The common part of every buffer getter: checks out/capacity against the
/// result's size and copies. See "Arrays" in motionfield.h.
template <class T>
void write_buffer(const T* data, size_t count, T* out, size_t capacity, size_t* needed) {
  check_buffer_arguments(out, capacity, needed);
  if (!out) {
    *needed = count;
    return;
  }
  if (capacity < count) {
    if (needed) *needed = count;
    throw ApiError(MF_ERROR_BUFFER_TOO_SMALL, "the buffer holds " + std::to_string(capacity) + " elements, " +
                                                  std::to_string(count) + " are needed");
  }
  if (count) std::memcpy(out, data, count * sizeof(T));
  if (needed) *needed = count;
}

/// A string into a caller buffer (capacity in bytes, including the NUL).
void write_string(const std::string& s, char* out, size_t capacity, size_t* needed);

/// Skeleton getters shared by models and motions.
void skeleton_joint_name(const Skeleton& s, int32_t joint, char* out, size_t capacity, size_t* needed);
void skeleton_parents(const Skeleton& s, int32_t* out, size_t capacity, size_t* needed);
void skeleton_offsets(const Skeleton& s, float* out, size_t capacity, size_t* needed);

/// The model set of mf_model_load_set: the prior at `path` (NULL: the
/// default model), the in-betweeners and the rig anatomy next to it, then the
/// `count` in-betweener files of `inbetweeners` added in order.
std::unique_ptr<mf_model> load_model_set(const char* path, const char* const* inbetweeners, size_t count);

/// A new motion handle carrying `motion` and the BVH layout of `like` (if any).
mf_motion* derived_motion(Motion motion, const mf_motion& like);

/// The solution handle of a constrained result: its motions derived from
/// `like` (layout, unit) with every warning, its reports, the method's name.
std::unique_ptr<mf_solution> new_solution(ConstrainedResult&& result, const mf_motion& like, bool trajectory);

/// The context of a task call from its options: models, seed, progress
/// callback, cancel token and rig map (read from rig_map_path if given).
TaskContext task_context(const mf_model* model, const mf_task_options& options);

/// Made at the start of every task call: holds the BLAS's thread pool at one
/// thread until mf_set_num_threads() chooses a count (the process-wide size
/// of that pool, prior/util/blas.h).
class TaskThreads {
 public:
  TaskThreads();
};

}  // namespace mf::capi
