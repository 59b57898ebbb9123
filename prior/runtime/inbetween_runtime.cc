#include "prior/runtime/inbetween_runtime.h"

#include <sstream>
#include <utility>

#include "prior/inbetween/inbetween_config.h"
#include "prior/model/model_container.h"
#include "prior/motion/errors.h"
#include "prior/runtime/citl_runtime.h"
#include "prior/runtime/keyframe_runtime.h"
#include "prior/runtime/two_stage_runtime.h"
#include "prior/runtime/weight_reader.h"
#include "prior/util/binary_io.h"

namespace mf::runtime {

InbetweenerRuntime::InbetweenerRuntime(const RigInfo& rig, InbetweenNormalisation normalisation)
    : rig_(rig), normalisation_(std::move(normalisation)) {}

std::string InbetweenerRuntime::describe() const {
  std::ostringstream s;
  s << kind() << ", window " << window() << " at " << fps() << " fps";
  return s.str();
}

int InbetweenerRuntime::checked_frames(const InbetweenWindow& in, int window, const std::string& name) const {
  const Eigen::Index J = rig_.num_joints(), D = pose_size(), T = in.pose.rows();
  if (in.pose.cols() != D) throw InputError(name + ": pose must be [T, " + std::to_string(D) + "]");
  if (T < 1 || T > window) {
    throw InputError(name + ": windows must have 1 to " + std::to_string(window) + " frames (got " +
                     std::to_string(T) + ")");
  }
  if (in.known.rows() != T || in.known.cols() != J + 1) {
    throw InputError(name + ": known must be [T, " + std::to_string(J + 1) + "] matching pose");
  }
  if (in.valid.size() != T) throw InputError(name + ": valid must be [T] matching pose");
  return static_cast<int>(T);
}

std::unique_ptr<const InbetweenerRuntime> inbetweener_runtime_from_bytes(const uint8_t* data, size_t size,
                                                                         const std::string& source) {
  const std::vector<std::string> kinds = {kTwoStageKind, kCitlKind, kKeyframeKind};
  return read_model_file(data, size, source, kinds, nullptr, [&](ModelFileContents& c) {
    check_window_and_fps(c.hyperparameters, source);
    if (c.rig.num_joints() < 1) throw InputError(source + ": the rig has no joints");
    const int64_t D = c.rig.num_joints() * 6 + 3;
    WeightReader w(&c.tensors, source);
    InbetweenNormalisation n;
    n.mean = w.vector("stats.pose_mean", D);
    n.scale = w.vector("stats.pose_std", D).cwiseMax(1e-6f);
    auto config = [&](auto parse) {
      try {
        return parse(c.hyperparameters);
      } catch (const InputError& e) {
        throw InputError(source + ": invalid hyperparameters: " + e.what());
      }
    };
    std::unique_ptr<const InbetweenerRuntime> model;
    if (c.kind == kTwoStageKind) {
      model = std::make_unique<TwoStageRuntime>(config(parse_two_stage_config), c.rig, n, w);
    } else if (c.kind == kCitlKind) {
      model = std::make_unique<CitlRuntime>(config(parse_citl_config), c.rig, n, w);
    } else {
      model = std::make_unique<KeyframeRuntime>(config(parse_keyframe_config), c.rig, n, w);
    }
    w.finish();
    return model;
  });
}

std::unique_ptr<const InbetweenerRuntime> load_inbetweener_runtime(const std::string& path) {
  const FileBytes bytes = read_file_bytes(path);
  return inbetweener_runtime_from_bytes(bytes.data(), bytes.size(), path);
}

}  // namespace mf::runtime
