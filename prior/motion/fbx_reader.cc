#include "prior/motion/fbx_reader.h"

#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/metadata.h>
#include <assimp/scene.h>

#include <cmath>

#include "prior/motion/errors.h"
#include "prior/util/binary_io.h"

namespace Assimp {
void aiAssertViolation(const char* expression, const char* file, int line);  // assimp_assert.cc
}  // namespace Assimp

namespace mf {
namespace {

// A reference that links assimp_assert.cc's handler into every program that
// links this reader from the static library.
[[gnu::used]] void (*volatile const kAssertHandler)(const char*, const char*, int) = &Assimp::aiAssertViolation;

// A number of the scene's metadata (FBX global settings), whatever its type.
bool metadata_number(const aiScene* scene, const char* key, double* out) {
  const aiMetadata* meta = scene->mMetaData;
  if (!meta) return false;
  for (unsigned i = 0; i < meta->mNumProperties; ++i) {
    if (std::string(meta->mKeys[i].C_Str()) != key) continue;
    const aiMetadataEntry& e = meta->mValues[i];
    if (!e.mData) return false;
    switch (e.mType) {
      case AI_BOOL: *out = *static_cast<const bool*>(e.mData); return true;
      case AI_INT32: *out = *static_cast<const int32_t*>(e.mData); return true;
      case AI_UINT64: *out = static_cast<double>(*static_cast<const uint64_t*>(e.mData)); return true;
      case AI_FLOAT: *out = *static_cast<const float*>(e.mData); return true;
      case AI_DOUBLE: *out = *static_cast<const double*>(e.mData); return true;
      default: return false;
    }
  }
  return false;
}

// FBX axis settings: file vectors to motionfield's axes (coord axis -> X, up
// -> Y, front -> Z, with their signs). A mirror is refused.
Eigen::Matrix3d axes_of(const aiScene* scene) {
  double up = 1, up_sign = 1, front = 2, front_sign = 1, coord = 0, coord_sign = 1;
  metadata_number(scene, "UpAxis", &up);
  metadata_number(scene, "UpAxisSign", &up_sign);
  metadata_number(scene, "FrontAxis", &front);
  metadata_number(scene, "FrontAxisSign", &front_sign);
  metadata_number(scene, "CoordAxis", &coord);
  metadata_number(scene, "CoordAxisSign", &coord_sign);
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  const double axes[3] = {coord, up, front}, signs[3] = {coord_sign, up_sign, front_sign};
  for (int row = 0; row < 3; ++row) {
    if (!(axes[row] == 0 || axes[row] == 1 || axes[row] == 2) || std::abs(signs[row]) != 1)
      throw InputError("the file's axis settings (UpAxis, FrontAxis, CoordAxis) are invalid");
    m(row, static_cast<int>(axes[row])) = signs[row];
  }
  if (std::abs(m.determinant() - 1) > 1e-9)
    throw InputError("the file's axis settings (UpAxis, FrontAxis, CoordAxis) are not a rotation (mirrored or "
                     "repeated axes)");
  return m;
}

Eigen::Affine3d affine_of(const aiMatrix4x4& m) {
  Eigen::Affine3d a = Eigen::Affine3d::Identity();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) a.matrix()(r, c) = m[r][c];
  return a;
}

// The bind pose of skinned meshes' bones as the rest pose: a bone's world
// transform at bind time is its mesh node's world transform times the inverse
// of its offset matrix (mesh space to bone space). Without a skin, the nodes'
// transforms stay the rest pose (Blender writes the current frame's pose).
void apply_bind_pose(const aiScene* scene, const std::vector<const aiNode*>& nodes, NodeAnimation& out) {
  const size_t n = nodes.size();
  std::vector<Eigen::Affine3d> world(n);
  std::vector<char> bound(n, 0);
  for (size_t i = 0; i < n; ++i)
    world[i] = (out.parents[i] < 0 ? Eigen::Affine3d::Identity() : world[out.parents[i]]) * to_affine(out.rest[i]);
  const std::vector<Eigen::Affine3d> rest_world = world;
  for (size_t i = 0; i < n; ++i) {
    for (unsigned k = 0; k < nodes[i]->mNumMeshes; ++k) {
      const unsigned index = nodes[i]->mMeshes[k];
      const aiMesh* mesh = index < scene->mNumMeshes ? scene->mMeshes[index] : nullptr;
      for (unsigned b = 0; mesh && b < mesh->mNumBones; ++b) {
        const aiBone* bone = mesh->mBones[b];
        for (size_t j = 0; bone && j < n; ++j) {
          if (bound[j] || out.names[j] != bone->mName.C_Str()) continue;
          const Eigen::Affine3d offset = affine_of(bone->mOffsetMatrix);
          if (!offset.matrix().allFinite() || std::abs(offset.linear().determinant()) < 1e-12) continue;
          world[j] = rest_world[i] * offset.inverse();
          bound[j] = 1;
        }
      }
    }
  }
  // The bind pose's world transforms (bones bound, the rest below them), then
  // the bound bones' local rest transforms from them.
  for (size_t j = 0; j < n; ++j) {
    const Eigen::Affine3d parent = out.parents[j] < 0 ? Eigen::Affine3d::Identity() : world[out.parents[j]];
    if (bound[j]) {
      out.rest[j] = transform_from_affine(parent.inverse() * world[j]);
    } else {
      world[j] = parent * to_affine(out.rest[j]);
    }
  }
}

// Key times in seconds and values of assimp keys (vector or quaternion).
template <class Key>
KeyTrack track_of(const Key* keys, unsigned count, double ticks_per_second) {
  KeyTrack t;
  constexpr bool kQuat = std::is_same<Key, aiQuatKey>::value;
  t.width = kQuat ? 4 : 3;
  for (unsigned k = 0; k < count; ++k) {
    t.times.push_back(keys[k].mTime / ticks_per_second);
    if constexpr (kQuat) {
      const aiQuaternion& q = keys[k].mValue;
      t.values.insert(t.values.end(), {q.x, q.y, q.z, q.w});
    } else {
      const aiVector3D& v = keys[k].mValue;
      t.values.insert(t.values.end(), {v.x, v.y, v.z});
    }
  }
  return t;
}

// The nodes depth first (parents first), their rest transforms.
void add_nodes(const aiNode* node, int parent, NodeAnimation& out, std::vector<const aiNode*>& nodes) {
  std::vector<std::pair<const aiNode*, int>> stack{{node, parent}};
  while (!stack.empty()) {
    const auto [n, p] = stack.back();
    stack.pop_back();
    if (nodes.size() >= 1'000'000) throw InputError("the file has more than a million nodes");
    const int index = static_cast<int>(nodes.size());
    nodes.push_back(n);
    out.names.push_back(n->mName.C_Str());
    out.parents.push_back(p);
    out.rest.push_back(transform_from_affine(affine_of(n->mTransformation)));
    for (unsigned c = n->mNumChildren; c-- > 0;)
      if (n->mChildren[c]) stack.push_back({n->mChildren[c], index});
  }
}

NodeAnimation animation_of(const aiScene* scene, const aiAnimation& anim) {
  NodeAnimation out;
  std::vector<const aiNode*> nodes;
  add_nodes(scene->mRootNode, -1, out, nodes);
  out.tracks.resize(nodes.size());
  std::vector<char> animated(nodes.size(), 0);
  const double tps = anim.mTicksPerSecond > 0 ? anim.mTicksPerSecond : 25.0;  // assimp's default
  for (unsigned c = 0; c < anim.mNumChannels; ++c) {
    const aiNodeAnim* ch = anim.mChannels[c];
    if (!ch) continue;
    for (size_t i = 0; i < nodes.size(); ++i) {
      if (out.names[i] != ch->mNodeName.C_Str()) continue;
      out.tracks[i].translation = track_of(ch->mPositionKeys, ch->mNumPositionKeys, tps);
      out.tracks[i].rotation = track_of(ch->mRotationKeys, ch->mNumRotationKeys, tps);
      out.tracks[i].scale = track_of(ch->mScalingKeys, ch->mNumScalingKeys, tps);
      animated[i] = 1;
      break;
    }
  }
  for (unsigned m = 0; m < scene->mNumMeshes; ++m)
    for (unsigned b = 0; scene->mMeshes[m] && b < scene->mMeshes[m]->mNumBones; ++b)
      for (size_t i = 0; i < nodes.size(); ++i)
        if (out.names[i] == scene->mMeshes[m]->mBones[b]->mName.C_Str()) animated[i] = 1;
  out.joints = mark_joints(out.parents, animated);
  apply_bind_pose(scene, nodes, out);
  out.to_y_up = axes_of(scene);
  return out;
}

}  // namespace

Motion read_fbx_motion(const uint8_t* data, size_t size, const SceneReadOptions& options, double* metres_per_unit) {
  if (size > kMaxSceneFileBytes) throw InputError("the FBX file is larger than 512 MiB");
  Assimp::Importer importer;
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_PRESERVE_PIVOTS, false);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_READ_MATERIALS, false);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_READ_TEXTURES, false);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_READ_CAMERAS, false);
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_READ_LIGHTS, false);
  const aiScene* scene = importer.ReadFileFromMemory(data, size, 0, "fbx");
  if (!scene || !scene->mRootNode)
    throw InputError(std::string("not a valid FBX file: ") + importer.GetErrorString());
  std::vector<std::string> names;
  for (unsigned a = 0; a < scene->mNumAnimations; ++a)
    names.push_back(scene->mAnimations[a] ? scene->mAnimations[a]->mName.C_Str() : "");
  const aiAnimation* anim = scene->mAnimations[pick_animation(names, options)];
  if (!anim) throw InputError("no animation: the file's animation is empty");
  NodeAnimation nodes = animation_of(scene, *anim);
  double unit_cm = 1;
  metadata_number(scene, "UnitScaleFactor", &unit_cm);
  if (!(std::isfinite(unit_cm) && unit_cm > 0))
    throw InputError("the file's UnitScaleFactor is " + std::to_string(unit_cm) + ": it must be positive");
  nodes.metres_per_unit = unit_cm / 100.0;
  if (metres_per_unit) *metres_per_unit = nodes.metres_per_unit;
  return motion_from_node_animation(nodes, options);
}

Motion read_fbx_file(const std::string& path, const SceneReadOptions& options, double* metres_per_unit) {
  const std::string bytes = read_file_limited(path, "FBX file", kMaxSceneFileBytes);
  try {
    return read_fbx_motion(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(), options, metres_per_unit);
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
}

}  // namespace mf
