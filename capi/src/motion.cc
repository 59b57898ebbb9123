// mf_motion: creation from arrays and BVH, BVH output, queries.
#include <algorithm>
#include <cerrno>
#include <cstring>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>

#include "capi/src/capi_internal.h"
#include "prior/runtime/nemf_runtime.h"
#include "prior/motion/errors.h"
#include "prior/motion/motion_bvh.h"
#include "prior/motion/fbx_reader.h"
#include "prior/motion/gltf_reader.h"
#include "prior/motion/motion_file.h"
#include "prior/motion/motion_gltf.h"
#include "prior/rig/units.h"
#include "prior/util/binary_io.h"

namespace mf::capi {
namespace {

constexpr int32_t kMaxJoints = 1024;
constexpr int32_t kMaxFrames = 10'000'000;

const mf_motion& get(const mf_motion* motion) {
  require(motion, "motion");
  return *motion;
}

// Range checks on counts shared by the array constructors.
void check_counts(int32_t joint_count, int32_t frame_count, double fps) {
  if (joint_count < 1 || joint_count > kMaxJoints)
    throw ApiError(MF_ERROR_INVALID_ARGUMENT, "joint_count must be between 1 and " + std::to_string(kMaxJoints) +
                                                  ", not " + std::to_string(joint_count));
  if (frame_count < 1 || frame_count > kMaxFrames)
    throw ApiError(MF_ERROR_INVALID_ARGUMENT, "frame_count must be between 1 and " + std::to_string(kMaxFrames) +
                                                  ", not " + std::to_string(frame_count));
  if (!(std::isfinite(fps) && fps > 0))
    throw ApiError(MF_ERROR_INVALID_ARGUMENT, "fps must be finite and positive");
}

// A motion from caller arrays on `skeleton` (whose joint count the caller has
// checked). Validation errors (non-finite numbers, zero quaternions) throw
// InputError.
Motion motion_from_arrays(const Skeleton& skeleton, int32_t frame_count, double fps, const float* rotations,
                          const float* root_positions) {
  require(rotations, "rotations");
  require(root_positions, "root_positions");
  Motion m;
  m.skeleton = skeleton;
  m.fps = fps;
  const size_t J = static_cast<size_t>(skeleton.num_joints()), F = static_cast<size_t>(frame_count);
  m.rotations.resize(F * J);
  m.root_positions.resize(F);
  for (size_t i = 0; i < F * J; ++i) {
    const float* q = rotations + 4 * i;
    m.rotations[i] = Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
  }
  for (size_t f = 0; f < F; ++f) {
    const float* p = root_positions + 3 * f;
    m.root_positions[f] = Eigen::Vector3d(p[0], p[1], p[2]);
  }
  m.validate();
  return m;
}

// The names mf_length_unit_scale knows (prior/rig/units.h).
constexpr const char* kUnitNames[] = {"cm", "m", "mm", "in", "ft", "asf"};

// The options' length_scale: 0 (the default) or finite and positive.
double length_scale_of(const mf_bvh_options* options) {
  const mf_bvh_options o = read_options(options, "mf_bvh_options");
  if (!(std::isfinite(o.length_scale) && o.length_scale >= 0))
    throw ApiError(MF_ERROR_INVALID_ARGUMENT, "mf_bvh_options.length_scale must be finite and positive (or 0)");
  return o.length_scale;
}

BvhUnits units_of(const mf_bvh_options* options, double fallback) {
  const double scale = length_scale_of(options);
  BvhUnits u;
  u.length_scale = scale == 0.0 ? fallback : scale;
  return u;
}

// The name of the unit of `metres` per unit, or "custom".
std::string unit_name(double metres) {
  for (const char* name : kUnitNames)
    if (length_unit_from_name(name).metres == metres) return name;
  return "custom";
}

// Sets the handle's unit: `given` metres per unit, or (0) the one detected
// from the document's skeleton.
void set_unit(mf_motion* handle, const BvhDocument& doc, double given) {
  if (given > 0) {
    handle->length_scale = given;
    handle->unit = unit_name(given);
    handle->unit_detected = false;
    return;
  }
  bool detected = false;
  const LengthUnit unit = detect_bvh_length_unit(doc, &detected);
  handle->length_scale = unit.metres;
  handle->unit = unit.name;
  handle->unit_detected = detected;
}

mf_motion* motion_from_document(BvhDocument doc, const mf_bvh_options* options, const std::string& source) {
  const double given = length_scale_of(options);
  auto handle = std::make_unique<mf_motion>();
  try {
    set_unit(handle.get(), doc, given);
    BvhUnits units;
    units.length_scale = handle->length_scale;
    handle->motion = motion_from_bvh(doc, units);
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());
  }
  handle->layout_fps = handle->motion.fps;
  doc.values.clear();
  doc.values.shrink_to_fit();
  doc.num_frames = 0;
  handle->layout = std::make_shared<const BvhDocument>(std::move(doc));
  return handle.release();
}

double frame_time_of(const mf_motion& m) {
  if (m.layout && m.motion.fps == m.layout_fps) return m.layout->frame_time;
  return 1.0 / m.motion.fps;
}

BvhDocument document_of(const mf_motion& m, const BvhUnits& units) {
  BvhDocument doc =
      motion_to_bvh(m.motion, m.layout ? *m.layout : default_bvh_layout(m.motion.skeleton, units), units);
  doc.frame_time = frame_time_of(m);
  return doc;
}

// The glTF format of `options` for `path` ("" for memory: binary by default).
GltfFormat gltf_format_of(const mf_gltf_options* options, const std::string& path) {
  const mf_gltf_options o = read_options(options, "mf_gltf_options");
  if (o.format == MF_GLTF_BINARY) return GltfFormat::Binary;
  if (o.format == MF_GLTF_EMBEDDED) return GltfFormat::Embedded;
  if (o.format != MF_GLTF_AUTO)
    throw ApiError(MF_ERROR_INVALID_ARGUMENT, "mf_gltf_options.format must be MF_GLTF_AUTO, MF_GLTF_BINARY or "
                                              "MF_GLTF_EMBEDDED, not " + std::to_string(o.format));
  GltfFormat format = GltfFormat::Binary;
  if (!path.empty() && !gltf_format_from_path(path, &format))
    throw ApiError(MF_ERROR_INVALID_ARGUMENT, "cannot tell the glTF format of " + path +
                                                  ": name it .glb (binary) or .gltf (JSON), or set "
                                                  "mf_gltf_options.format");
  return format;
}

// What a file is called in the messages of its reading ("cannot read BVH file
// F: ...", as mf_motion_load_bvh says): by its name, BVH unless it is named
// .glb, .gltf or .fbx.
std::string file_kind(const std::string& path) {
  MotionFormat format = MotionFormat::Bvh;
  try {
    format = detect_motion_format(path, nullptr, 0);
  } catch (const InputError&) {
  }
  return std::string(to_string(format)) + " file";
}

// A motion read from a glTF or FBX file: no BVH layout, the unit it came in.
mf_motion* scene_motion(Motion motion, double metres_per_unit) {
  auto handle = std::make_unique<mf_motion>();
  handle->motion = std::move(motion);
  handle->length_scale = metres_per_unit;
  handle->unit = unit_name(metres_per_unit);
  handle->unit_from_file = true;
  return handle.release();
}

// mf_motion_load's reading of `size` bytes named `source`; `base_dir`: where
// a glTF's external buffers are ("" from memory).
mf_motion* load_motion(const uint8_t* data, size_t size, const mf_motion_load_options& o, const std::string& source,
                       const std::string& base_dir) {
  if (o.format < MF_FORMAT_AUTO || o.format > MF_FORMAT_FBX)
    throw ApiError(MF_ERROR_INVALID_ARGUMENT, "mf_motion_load_options.format must be MF_FORMAT_AUTO, _BVH, _GLTF or "
                                              "_FBX, not " + std::to_string(o.format));
  mf_bvh_options bvh;
  std::memset(&bvh, 0, sizeof bvh);
  bvh.struct_size = sizeof bvh;
  bvh.length_scale = o.length_scale;
  length_scale_of(&bvh);
  const MotionFormat format = o.format == MF_FORMAT_BVH    ? MotionFormat::Bvh
                              : o.format == MF_FORMAT_GLTF ? MotionFormat::Gltf
                              : o.format == MF_FORMAT_FBX  ? MotionFormat::Fbx
                                                           : detect_motion_format(source, data, size);
  if (format == MotionFormat::Bvh) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    return motion_from_document(parse_bvh(text, source), &bvh, source);
  }
  SceneReadOptions scene;
  scene.animation = o.animation ? o.animation : "";
  scene.animation_index = o.animation_index;
  scene.fps = o.fps;
  try {
    if (format == MotionFormat::Gltf) return scene_motion(read_gltf_motion(data, size, base_dir, scene), 1.0);
    double unit = 1.0;
    Motion m = read_fbx_motion(data, size, scene, &unit);
    return scene_motion(std::move(m), unit);
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());
  }
}

}  // namespace

mf_motion* derived_motion(Motion motion, const mf_motion& like) {
  auto handle = std::make_unique<mf_motion>();
  handle->motion = std::move(motion);
  handle->layout = like.layout;
  handle->layout_fps = like.layout_fps;
  handle->length_scale = like.length_scale;
  handle->unit = like.unit;
  handle->unit_detected = like.unit_detected;
  handle->unit_from_file = like.unit_from_file;
  return handle.release();
}

}  // namespace mf::capi

using mf::capi::ApiError;
using mf::capi::guard;
using mf::capi::require;

extern "C" {

int mf_motion_create(int32_t joint_count, const char* const* joint_names, const int32_t* parents, const float* offsets,
                     int32_t frame_count, double fps, const float* rotations, const float* root_positions,
                     mf_motion** out) {
  return guard([&] {
    require(out, "out");
    mf::capi::check_counts(joint_count, frame_count, fps);
    require(joint_names, "joint_names");
    require(parents, "parents");
    require(offsets, "offsets");
    mf::Skeleton s;
    for (int32_t j = 0; j < joint_count; ++j) {
      if (!joint_names[j]) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "joint_names[" + std::to_string(j) + "] is NULL");
      s.names.emplace_back(joint_names[j]);
      s.parents.push_back(parents[j]);
      s.offsets.emplace_back(offsets[3 * j], offsets[3 * j + 1], offsets[3 * j + 2]);
    }
    s.validate();
    auto handle = std::make_unique<mf_motion>();
    handle->motion = mf::capi::motion_from_arrays(s, frame_count, fps, rotations, root_positions);
    *out = handle.release();
  });
}

int mf_motion_create_for_model(const mf_model* model, int32_t joint_count, int32_t frame_count, double fps,
                               const float* rotations, const float* root_positions, mf_motion** out) {
  return guard([&] {
    require(model, "model");
    require(out, "out");
    const mf::Skeleton& s = model->model->rig().skeleton;
    if (joint_count != s.num_joints())
      throw ApiError(MF_ERROR_INVALID_ARGUMENT, "joint_count is " + std::to_string(joint_count) +
                                                    " but the model's skeleton has " +
                                                    std::to_string(s.num_joints()) + " joints");
    mf::capi::check_counts(joint_count, frame_count, fps);
    auto handle = std::make_unique<mf_motion>();
    handle->motion = mf::capi::motion_from_arrays(s, frame_count, fps, rotations, root_positions);
    *out = handle.release();
  });
}

int mf_motion_create_like(const mf_motion* like, int32_t joint_count, int32_t frame_count, double fps,
                          const float* rotations, const float* root_positions, mf_motion** out) {
  return guard([&] {
    const mf_motion& l = mf::capi::get(like);
    require(out, "out");
    if (joint_count != l.motion.num_joints())
      throw ApiError(MF_ERROR_INVALID_ARGUMENT, "joint_count is " + std::to_string(joint_count) +
                                                    " but the template motion has " +
                                                    std::to_string(l.motion.num_joints()) + " joints");
    mf::capi::check_counts(joint_count, frame_count, fps);
    *out = mf::capi::derived_motion(
        mf::capi::motion_from_arrays(l.motion.skeleton, frame_count, fps, rotations, root_positions), l);
  });
}

int mf_motion_load_bvh(const char* path, const mf_bvh_options* options, mf_motion** out) {
  return guard([&] {
    require(path, "path");
    require(out, "out");
    mf::capi::length_scale_of(options);
    const std::string text = mf::read_file_limited(path, "BVH file", mf::kMaxBvhFileBytes);  // FileError: MF_ERROR_IO
    *out = mf::capi::motion_from_document(mf::parse_bvh(text, path), options, path);
  });
}

int mf_motion_load_bvh_from_memory(const char* data, size_t size, const mf_bvh_options* options, mf_motion** out) {
  return guard([&] {
    if (!data && size != 0) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "data is NULL");
    require(out, "out");
    mf::capi::length_scale_of(options);
    const std::string text = data ? std::string(data, size) : std::string();
    *out = mf::capi::motion_from_document(mf::parse_bvh(text, "<memory>"), options, "<memory>");
  });
}

int mf_motion_load(const char* path, const mf_motion_load_options* options, mf_motion** out) {
  return guard([&] {
    require(path, "path");
    require(out, "out");
    const mf_motion_load_options o = mf::capi::read_options(options, "mf_motion_load_options");
    // The BVH limit and the scene formats' are both 512 MiB.
    static_assert(mf::kMaxBvhFileBytes == mf::kMaxSceneFileBytes, "one read limit for every motion file");
    const std::string bytes = mf::read_file_limited(path, mf::capi::file_kind(path), mf::kMaxSceneFileBytes);
    const std::string p(path);
    const size_t slash = p.rfind('/');
    const std::string dir = slash == std::string::npos ? "./" : p.substr(0, slash + 1);
    *out = mf::capi::load_motion(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(), o, p, dir);
  });
}

int mf_motion_load_from_memory(const uint8_t* data, size_t size, const mf_motion_load_options* options,
                               mf_motion** out) {
  return guard([&] {
    if (!data && size != 0) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "data is NULL");
    require(out, "out");
    const mf_motion_load_options o = mf::capi::read_options(options, "mf_motion_load_options");
    static const uint8_t kEmpty = 0;
    *out = mf::capi::load_motion(data ? data : &kEmpty, size, o, "<memory>", "");
  });
}

int mf_motion_save_bvh(const mf_motion* motion, const char* path, const mf_bvh_options* options) {
  return guard([&] {
    const mf_motion& m = mf::capi::get(motion);
    require(path, "path");
    if (!*path) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "the output path is empty");
    const mf::BvhDocument doc = mf::capi::document_of(m, mf::capi::units_of(options, m.length_scale));
    mf::write_bvh_file(path, doc);  // FileError "cannot write <path>: <reason>": MF_ERROR_IO
  });
}

int mf_motion_save_bvh_to_memory(const mf_motion* motion, const mf_bvh_options* options, char* out, size_t capacity,
                                 size_t* needed) {
  return guard([&] {
    const mf_motion& m = mf::capi::get(motion);
    const std::string text = mf::format_bvh(mf::capi::document_of(m, mf::capi::units_of(options, m.length_scale)));
    mf::capi::write_string(text, out, capacity, needed);
  });
}

int mf_motion_save_gltf(const mf_motion* motion, const char* path, const mf_gltf_options* options) {
  return guard([&] {
    const mf_motion& m = mf::capi::get(motion);
    require(path, "path");
    if (!*path) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "the output path is empty");
    mf::write_gltf_file(path, m.motion, mf::capi::gltf_format_of(options, path));  // FileError: MF_ERROR_IO
  });
}

int mf_motion_save_gltf_to_memory(const mf_motion* motion, const mf_gltf_options* options, uint8_t* out,
                                  size_t capacity, size_t* needed) {
  return guard([&] {
    const mf_motion& m = mf::capi::get(motion);
    const std::vector<uint8_t> bytes = mf::format_gltf(m.motion, mf::capi::gltf_format_of(options, ""));
    mf::capi::write_buffer(bytes.data(), bytes.size(), out, capacity, needed);
  });
}

void mf_motion_destroy(mf_motion* motion) { delete motion; }

int mf_motion_get_joint_count(const mf_motion* motion, int32_t* out) {
  return guard([&] {
    const mf_motion& m = mf::capi::get(motion);
    require(out, "out");
    *out = m.motion.num_joints();
  });
}

int mf_motion_get_frame_count(const mf_motion* motion, int32_t* out) {
  return guard([&] {
    const mf_motion& m = mf::capi::get(motion);
    require(out, "out");
    *out = m.motion.num_frames();
  });
}

int mf_motion_get_fps(const mf_motion* motion, double* out) {
  return guard([&] {
    const mf_motion& m = mf::capi::get(motion);
    require(out, "out");
    *out = m.motion.fps;
  });
}

int mf_motion_get_length_scale(const mf_motion* motion, double* out) {
  return guard([&] {
    const mf_motion& m = mf::capi::get(motion);
    require(out, "out");
    *out = m.length_scale;
  });
}

int mf_motion_get_warnings(const mf_motion* motion, char* out, size_t capacity, size_t* needed) {
  return guard([&] { mf::capi::write_string(mf::capi::get(motion).warnings, out, capacity, needed); });
}

int mf_length_unit_scale(const char* unit, double* out) {
  return guard([&] {
    require(unit, "unit");
    require(out, "out");
    *out = mf::length_unit_from_name(unit).metres;
  });
}

int mf_motion_get_frame_time(const mf_motion* motion, double* out) {
  return guard([&] {
    const mf_motion& m = mf::capi::get(motion);
    require(out, "out");
    *out = mf::capi::frame_time_of(m);
  });
}

int mf_motion_get_joint_name(const mf_motion* motion, int32_t joint, char* out, size_t capacity, size_t* needed) {
  return guard(
      [&] { mf::capi::skeleton_joint_name(mf::capi::get(motion).motion.skeleton, joint, out, capacity, needed); });
}

int mf_motion_get_parents(const mf_motion* motion, int32_t* out, size_t capacity, size_t* needed) {
  return guard([&] { mf::capi::skeleton_parents(mf::capi::get(motion).motion.skeleton, out, capacity, needed); });
}

int mf_motion_get_offsets(const mf_motion* motion, float* out, size_t capacity, size_t* needed) {
  return guard([&] { mf::capi::skeleton_offsets(mf::capi::get(motion).motion.skeleton, out, capacity, needed); });
}

int mf_motion_get_rotations(const mf_motion* motion, float* out, size_t capacity, size_t* needed) {
  return guard([&] {
    const mf::Motion& m = mf::capi::get(motion).motion;
    const size_t n = m.rotations.size() * 4;
    if (out && capacity >= n) {
      std::vector<float> buffer(n);
      for (size_t i = 0; i < m.rotations.size(); ++i) {
        const Eigen::Quaterniond& q = m.rotations[i];
        buffer[4 * i] = static_cast<float>(q.w());
        buffer[4 * i + 1] = static_cast<float>(q.x());
        buffer[4 * i + 2] = static_cast<float>(q.y());
        buffer[4 * i + 3] = static_cast<float>(q.z());
      }
      mf::capi::write_buffer(buffer.data(), n, out, capacity, needed);
    } else {
      mf::capi::write_buffer(static_cast<const float*>(nullptr), n, out, capacity, needed);
    }
  });
}

int mf_motion_get_root_positions(const mf_motion* motion, float* out, size_t capacity, size_t* needed) {
  return guard([&] {
    const mf::Motion& m = mf::capi::get(motion).motion;
    const size_t n = m.root_positions.size() * 3;
    std::vector<float> buffer;
    if (out && capacity >= n) {
      buffer.resize(n);
      for (size_t f = 0; f < m.root_positions.size(); ++f)
        for (int k = 0; k < 3; ++k) buffer[3 * f + k] = static_cast<float>(m.root_positions[f][k]);
    }
    mf::capi::write_buffer(buffer.empty() ? nullptr : buffer.data(), n, out, capacity, needed);
  });
}

int mf_motion_get_global_positions(const mf_motion* motion, float* out, size_t capacity, size_t* needed) {
  return guard([&] {
    const mf::Motion& m = mf::capi::get(motion).motion;
    const size_t n = m.rotations.size() * 3;
    std::vector<float> buffer;
    if (out && capacity >= n) {
      const mf::GlobalPose pose = mf::forward_kinematics(m);
      buffer.resize(n);
      for (size_t i = 0; i < pose.positions.size(); ++i)
        for (int k = 0; k < 3; ++k) buffer[3 * i + k] = static_cast<float>(pose.positions[i][k]);
    }
    mf::capi::write_buffer(buffer.empty() ? nullptr : buffer.data(), n, out, capacity, needed);
  });
}

}  // extern "C"
