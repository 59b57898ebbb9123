#include "prior/motion/gltf_reader.h"

#include <tiny_gltf.h>

#include <cstring>

#include "prior/motion/errors.h"
#include "prior/util/binary_io.h"

namespace mf {
namespace {

// tinygltf's file access: external buffers next to a file are read with the
// size limit; from memory (base_dir "") nothing outside the bytes is read.
bool file_exists(const std::string& path, void* allowed) {
  return allowed != nullptr && !path.empty();
}

std::string expand_path(const std::string& path, void*) { return path; }

bool read_whole_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* allowed) {
  if (!allowed) {
    *err = "external files are not read from memory";
    return false;
  }
  try {
    const std::string bytes = read_file_limited(path, "glTF buffer", kMaxSceneFileBytes);
    out->assign(bytes.begin(), bytes.end());
    return true;
  } catch (const InputError& e) {
    *err = e.what();
    return false;
  }
}

bool write_whole_file(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  *err = "not written";
  return false;
}

// Images are not needed: their data is left undecoded.
bool skip_image(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int, void*) {
  return true;
}

tinygltf::Model load_model(const uint8_t* data, size_t size, const std::string& base_dir) {
  if (size > kMaxSceneFileBytes) throw InputError("the glTF file is larger than 512 MiB");
  tinygltf::TinyGLTF loader;
  static int allowed = 1;
  loader.SetFsCallbacks({file_exists, expand_path, read_whole_file, write_whole_file,
                         base_dir.empty() ? nullptr : &allowed});
  loader.SetImageLoader(skip_image, nullptr);
  tinygltf::Model model;
  std::string err, warn;
  const bool glb = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  const unsigned int n = static_cast<unsigned int>(size);
  const bool ok = glb ? loader.LoadBinaryFromMemory(&model, &err, &warn, data, n, base_dir)
                      : loader.LoadASCIIFromString(&model, &err, &warn, reinterpret_cast<const char*>(data), n,
                                                   base_dir);
  if (!ok) {
    while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
    throw InputError("not a valid glTF file: " + (err.empty() ? std::string("unknown error") : err));
  }
  return model;
}

// An accessor's numbers as doubles (normalised integers mapped to [-1, 1] or
// [0, 1]), `components` per element; bounds checked against its buffer.
std::vector<double> read_accessor(const tinygltf::Model& model, int index, int components, const std::string& what) {
  if (index < 0 || index >= static_cast<int>(model.accessors.size()))
    throw InputError(what + ": accessor " + std::to_string(index) + " does not exist");
  const tinygltf::Accessor& a = model.accessors[index];
  if (a.sparse.isSparse) throw InputError(what + ": sparse accessors are not read");
  if (tinygltf::GetNumComponentsInType(static_cast<uint32_t>(a.type)) != components)
    throw InputError(what + ": the accessor has the wrong type (" + std::to_string(components) +
                     " components expected)");
  if (a.bufferView < 0 || a.bufferView >= static_cast<int>(model.bufferViews.size()))
    throw InputError(what + ": the accessor has no buffer view");
  const tinygltf::BufferView& view = model.bufferViews[a.bufferView];
  if (view.buffer < 0 || view.buffer >= static_cast<int>(model.buffers.size()))
    throw InputError(what + ": the buffer view has no buffer");
  const std::vector<unsigned char>& buffer = model.buffers[view.buffer].data;
  const int size = tinygltf::GetComponentSizeInBytes(static_cast<uint32_t>(a.componentType));
  const int stride = a.ByteStride(view);
  if (size <= 0 || stride <= 0) throw InputError(what + ": the accessor's component type or stride is invalid");
  if (a.count > static_cast<size_t>(kMaxSceneFrames))
    throw InputError(what + ": " + std::to_string(a.count) + " keys, more than " + std::to_string(kMaxSceneFrames));
  const size_t element = static_cast<size_t>(size) * components;
  const size_t needed = a.count == 0 ? 0 : a.byteOffset + static_cast<size_t>(stride) * (a.count - 1) + element;
  if (view.byteOffset > buffer.size() || view.byteLength > buffer.size() - view.byteOffset ||
      a.byteOffset > view.byteLength || needed > view.byteLength)
    throw InputError(what + ": the accessor reaches beyond its buffer (a truncated file?)");
  const bool is_float = a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT;
  if (!is_float && !a.normalized) throw InputError(what + ": the keys must be floats or normalised integers");
  std::vector<double> out(a.count * components);
  const unsigned char* base = buffer.data() + view.byteOffset + a.byteOffset;
  for (size_t e = 0; e < a.count; ++e) {
    for (int c = 0; c < components; ++c) {
      const unsigned char* p = base + e * stride + static_cast<size_t>(c) * size;
      double v = 0;
      switch (a.componentType) {
        case TINYGLTF_COMPONENT_TYPE_FLOAT: { float f; std::memcpy(&f, p, 4); v = f; break; }
        case TINYGLTF_COMPONENT_TYPE_BYTE: v = std::max(static_cast<int8_t>(*p) / 127.0, -1.0); break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: v = *p / 255.0; break;
        case TINYGLTF_COMPONENT_TYPE_SHORT: { int16_t s; std::memcpy(&s, p, 2); v = std::max(s / 32767.0, -1.0); break; }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: { uint16_t s; std::memcpy(&s, p, 2); v = s / 65535.0; break; }
        default: throw InputError(what + ": unsupported component type " + std::to_string(a.componentType));
      }
      out[e * components + c] = v;
    }
  }
  return out;
}

// The nodes in an order with parents first: depth first from the nodes no
// node lists as a child; old index -> new in `index`.
std::vector<int> node_order(const tinygltf::Model& model, std::vector<int>* parents_out) {
  const int n = static_cast<int>(model.nodes.size());
  std::vector<int> parent(n, -1);
  for (int i = 0; i < n; ++i) {
    for (int c : model.nodes[i].children) {
      if (c < 0 || c >= n) throw InputError("node " + std::to_string(i) + " has a child " + std::to_string(c) +
                                            " that does not exist");
      if (parent[c] >= 0 || c == i)
        throw InputError("node " + std::to_string(c) + " ('" + model.nodes[c].name + "') has two parents");
      parent[c] = i;
    }
  }
  std::vector<int> order, stack, index(n, -1);
  for (int i = n - 1; i >= 0; --i)
    if (parent[i] < 0) stack.push_back(i);
  while (!stack.empty()) {
    const int i = stack.back();
    stack.pop_back();
    index[i] = static_cast<int>(order.size());
    order.push_back(i);
    parents_out->push_back(parent[i] < 0 ? -1 : index[parent[i]]);
    const std::vector<int>& ch = model.nodes[i].children;
    for (auto it = ch.rbegin(); it != ch.rend(); ++it) stack.push_back(*it);
  }
  if (static_cast<int>(order.size()) != n) throw InputError("the node hierarchy has a cycle");
  return order;
}

NodeTransform rest_of(const tinygltf::Node& node) {
  NodeTransform t;
  if (node.matrix.size() == 16) {
    Eigen::Affine3d m = Eigen::Affine3d::Identity();
    for (int k = 0; k < 12; ++k) m.matrix()(k % 4, k / 4) = node.matrix[k];  // column-major
    m.translation() = Eigen::Vector3d(node.matrix[12], node.matrix[13], node.matrix[14]);
    return transform_from_affine(m);
  }
  if (node.translation.size() == 3) t.translation = Eigen::Vector3d(node.translation.data());
  if (node.rotation.size() == 4)
    t.rotation = Eigen::Quaterniond(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
  if (node.scale.size() == 3) t.scale = Eigen::Vector3d(node.scale.data());
  return t;
}

// The animation's tracks on the nodes (in new order); marks animated nodes.
void add_tracks(const tinygltf::Model& model, const tinygltf::Animation& anim, const std::vector<int>& index,
                NodeAnimation& out, std::vector<char>& animated) {
  for (const tinygltf::AnimationChannel& ch : anim.channels) {
    const bool t = ch.target_path == "translation", r = ch.target_path == "rotation", s = ch.target_path == "scale";
    if (!t && !r && !s) continue;  // morph weights
    if (ch.target_node < 0 || ch.target_node >= static_cast<int>(index.size()))
      throw InputError("an animation channel targets node " + std::to_string(ch.target_node) + ", which does not exist");
    if (ch.sampler < 0 || ch.sampler >= static_cast<int>(anim.samplers.size()))
      throw InputError("an animation channel has no sampler");
    const tinygltf::AnimationSampler& sampler = anim.samplers[ch.sampler];
    const int node = index[ch.target_node];
    const std::string what = ch.target_path + " of node '" + out.names[node] + "'";
    NodeTracks& tracks = out.tracks[node];
    KeyTrack& track = t ? tracks.translation : r ? tracks.rotation : tracks.scale;
    track.width = r ? 4 : 3;
    track.interpolation = sampler.interpolation == "STEP"          ? KeyInterpolation::Step
                          : sampler.interpolation == "CUBICSPLINE" ? KeyInterpolation::CubicSpline
                                                                   : KeyInterpolation::Linear;
    track.times = read_accessor(model, sampler.input, 1, what + " (key times)");
    track.values = read_accessor(model, sampler.output, track.width, what);
    animated[node] = 1;
  }
}

}  // namespace

Motion read_gltf_motion(const uint8_t* data, size_t size, const std::string& base_dir,
                        const SceneReadOptions& options) {
  const tinygltf::Model model = load_model(data, size, base_dir);
  std::vector<std::string> names;
  for (const tinygltf::Animation& a : model.animations) names.push_back(a.name);
  const tinygltf::Animation& anim = model.animations[pick_animation(names, options)];

  NodeAnimation out;
  const std::vector<int> order = node_order(model, &out.parents);
  std::vector<int> index(order.size());
  for (size_t k = 0; k < order.size(); ++k) {
    index[order[k]] = static_cast<int>(k);
    const tinygltf::Node& node = model.nodes[order[k]];
    out.names.push_back(node.name.empty() ? "node" + std::to_string(order[k]) : node.name);
    out.rest.push_back(rest_of(node));
  }
  out.tracks.resize(order.size());
  std::vector<char> animated(order.size(), 0);
  add_tracks(model, anim, index, out, animated);
  out.joints = mark_joints(out.parents, animated);
  // A skin names the joints: the first skin with an animated joint.
  for (const tinygltf::Skin& skin : model.skins) {
    std::vector<char> joints(order.size(), 0);
    bool any = false;
    for (int j : skin.joints) {
      if (j < 0 || j >= static_cast<int>(order.size())) throw InputError("a skin names a node that does not exist");
      joints[index[j]] = 1;
      any = any || animated[index[j]];
    }
    if (any) {
      out.joints = joints;
      break;
    }
  }
  return motion_from_node_animation(out, options);
}

Motion read_gltf_file(const std::string& path, const SceneReadOptions& options) {
  const std::string bytes = read_file_limited(path, "glTF file", kMaxSceneFileBytes);
  const size_t slash = path.rfind('/');
  const std::string dir = slash == std::string::npos ? "." : path.substr(0, slash + 1);
  try {
    return read_gltf_motion(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(), dir, options);
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
}

}  // namespace mf
