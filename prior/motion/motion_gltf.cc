#include "prior/motion/motion_gltf.h"

#include <tiny_gltf.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <sstream>

#include "prior/motion/errors.h"
#include "prior/util/binary_io.h"
#include "prior/util/file_writer.h"

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "glTF buffers are little-endian: the floats are copied as is");

namespace mf {
namespace {

// glTF's GLB chunk lengths are 32-bit; keep well inside them.
constexpr size_t kMaxGltfBufferBytes = size_t{1} << 31;

float to_float(double value, const char* what) {
  const float f = static_cast<float>(value);
  if (!std::isfinite(f))
    throw InputError(std::string("cannot write glTF: ") + what + " " + std::to_string(value) +
                     " does not fit in a 32-bit float");
  return f;
}

// Appends `values` (float components, `components` per element) to the buffer
// as a bufferView and an accessor of `type`; returns the accessor's index.
// `bounds`: with min and max (required for animation inputs).
int append_accessor(tinygltf::Model& model, const std::vector<float>& values, int type, int components, bool bounds) {
  std::vector<unsigned char>& data = model.buffers[0].data;
  const size_t bytes = values.size() * sizeof(float);
  if (bytes > kMaxGltfBufferBytes - data.size())
    throw InputError("cannot write glTF: the motion needs more than 2 GiB of buffer (too many frames and joints)");
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = data.size();
  view.byteLength = bytes;
  const auto* p = reinterpret_cast<const unsigned char*>(values.data());
  data.insert(data.end(), p, p + bytes);
  model.bufferViews.push_back(view);

  tinygltf::Accessor accessor;
  accessor.bufferView = static_cast<int>(model.bufferViews.size()) - 1;
  accessor.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
  accessor.type = type;
  accessor.count = values.size() / static_cast<size_t>(components);
  if (bounds) {
    accessor.minValues.assign(components, std::numeric_limits<double>::infinity());
    accessor.maxValues.assign(components, -std::numeric_limits<double>::infinity());
    for (size_t i = 0; i < values.size(); ++i) {
      double& lo = accessor.minValues[i % components];
      double& hi = accessor.maxValues[i % components];
      lo = std::min<double>(lo, values[i]);
      hi = std::max<double>(hi, values[i]);
    }
  }
  model.accessors.push_back(accessor);
  return static_cast<int>(model.accessors.size()) - 1;
}

void add_channel(tinygltf::Animation& animation, int input, int output, int node, const char* path) {
  tinygltf::AnimationSampler sampler;
  sampler.input = input;
  sampler.output = output;
  sampler.interpolation = "LINEAR";
  animation.samplers.push_back(sampler);
  tinygltf::AnimationChannel channel;
  channel.sampler = static_cast<int>(animation.samplers.size()) - 1;
  channel.target_node = node;
  channel.target_path = path;
  animation.channels.push_back(channel);
}

// One node per joint (node j = joint j), the hierarchy of the skeleton, rest
// offsets as translations; the scene's root is joint 0.
void add_skeleton(tinygltf::Model& model, const Skeleton& skeleton) {
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    tinygltf::Node node;
    node.name = skeleton.names[j];
    for (int k = 0; k < 3; ++k) node.translation.push_back(to_float(skeleton.offsets[j][k], "an offset"));
    model.nodes.push_back(node);
  }
  for (int j = 1; j < skeleton.num_joints(); ++j) model.nodes[skeleton.parents[j]].children.push_back(j);
  tinygltf::Scene scene;
  scene.name = "motion";
  scene.nodes.push_back(0);
  model.scenes.push_back(scene);
  model.defaultScene = 0;
}

// The frame times, strictly increasing as floats (a glTF requirement).
std::vector<float> frame_times(const Motion& motion) {
  std::vector<float> times(static_cast<size_t>(motion.num_frames()));
  for (size_t f = 0; f < times.size(); ++f) {
    times[f] = to_float(static_cast<double>(f) / motion.fps, "a frame time");
    if (f > 0 && !(times[f] > times[f - 1]))
      throw InputError("cannot write glTF: the frame times " + std::to_string(times[f]) +
                       " s and the one before are equal as 32-bit floats (too many frames at this rate)");
  }
  return times;
}

// The animation: a rotation channel per joint, the root's translation.
void add_animation(tinygltf::Model& model, const Motion& motion) {
  tinygltf::Animation animation;
  animation.name = "motion";
  const int input = append_accessor(model, frame_times(motion), TINYGLTF_TYPE_SCALAR, 1, true);
  const size_t frames = static_cast<size_t>(motion.num_frames());
  std::vector<float> values;
  for (int j = 0; j < motion.num_joints(); ++j) {
    values.resize(4 * frames);
    for (size_t f = 0; f < frames; ++f) {
      const Eigen::Quaterniond q = motion.rotation(static_cast<int>(f), j).normalized();
      const double xyzw[4] = {q.x(), q.y(), q.z(), q.w()};
      for (int k = 0; k < 4; ++k) values[4 * f + k] = static_cast<float>(xyzw[k]);
    }
    add_channel(animation, input, append_accessor(model, values, TINYGLTF_TYPE_VEC4, 4, false), j, "rotation");
  }
  values.resize(3 * frames);
  for (size_t f = 0; f < frames; ++f)
    for (int k = 0; k < 3; ++k) values[3 * f + k] = to_float(motion.root_positions[f][k], "a root position");
  add_channel(animation, input, append_accessor(model, values, TINYGLTF_TYPE_VEC3, 3, false), 0, "translation");
  model.animations.push_back(animation);
}

}  // namespace

bool gltf_format_from_path(const std::string& path, GltfFormat* format) {
  const size_t dot = path.rfind('.');
  if (dot == std::string::npos || path.find('/', dot) != std::string::npos) return false;
  std::string ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == "glb") *format = GltfFormat::Binary;
  else if (ext == "gltf") *format = GltfFormat::Embedded;
  else return false;
  return true;
}

std::vector<uint8_t> format_gltf(const Motion& motion, GltfFormat format) {
  motion.validate();
  if (motion.num_frames() < 1) throw InputError("cannot write glTF: the motion has no frames");
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "motionfield";
  model.buffers.emplace_back();
  add_skeleton(model, motion.skeleton);
  add_animation(model, motion);
  std::ostringstream out;
  tinygltf::TinyGLTF writer;
  const bool binary = format == GltfFormat::Binary;
  if (!writer.WriteGltfSceneToStream(&model, out, /*prettyPrint=*/!binary, binary) || !out)
    throw std::runtime_error("tinygltf could not serialise the glTF document");
  const std::string bytes = out.str();
  return std::vector<uint8_t>(bytes.begin(), bytes.end());
}

void write_gltf_file(const std::string& path, const Motion& motion, GltfFormat format) {
  write_file_atomically(path, format_gltf(motion, format));
}

}  // namespace mf
