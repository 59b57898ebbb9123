#include "prior/runtime/nemf_runtime.h"

#include "prior/model/model_container.h"
#include "prior/motion/errors.h"
#include "prior/util/binary_io.h"
#include "prior/runtime/local_features.h"
#include "prior/runtime/weight_reader.h"

namespace mf::runtime {

namespace {

constexpr int kFeaturesPerJoint = 15;

NemfRuntimeStats read_stats(WeightReader& w, int joints) {
  NemfRuntimeStats s;
  s.feature_mean = w.vector("stats.feature_mean", joints * kFeaturesPerJoint);
  s.feature_std = w.vector("stats.feature_std", joints * kFeaturesPerJoint);
  s.root_mean = w.vector("stats.root_mean", 6);
  s.root_std = w.vector("stats.root_std", 6);
  s.gmp_in_mean = w.vector("stats.gmp_in_mean", joints * 3 + 6);
  s.gmp_in_std = w.vector("stats.gmp_in_std", joints * 3 + 6);
  s.gmp_out_mean = w.vector("stats.gmp_out_mean", 4);
  s.gmp_out_std = w.vector("stats.gmp_out_std", 4);
  return s;
}

}  // namespace

NemfRuntime NemfRuntime::from_bytes(const uint8_t* data, size_t size, const std::string& source) {
  return read(data, size, source, nullptr);
}

NemfRuntime NemfRuntime::from_file(const FileBytes& file, const std::string& source) {
  return read(file.data(), file.size(), source, &file);
}

NemfRuntime NemfRuntime::read(const uint8_t* data, size_t size, const std::string& source, const FileBytes* file) {
  return read_model_file(data, size, source, {kNemfKind}, file, [&](ModelFileContents& c) {
    NemfRuntime r;
    r.config_ = checked_nemf_config(c.hyperparameters, source);
    r.rig_ = c.rig;
    const int J = r.rig_.num_joints(), F = r.rig_.num_feet();
    WeightReader w(&c.tensors, source, file);
    r.stats_ = read_stats(w, J);
    r.encoders_ = std::make_shared<const NemfEncoders>(r.config_, r.rig_.skeleton.parents, w);
    r.decoder_ = std::make_shared<const NemfDecoder>(r.config_, J, w);
    r.kinematics_ = std::make_shared<const Kinematics>(r.rig_.skeleton);
    r.gmp_ = std::make_shared<const NemfGmpNetwork>(r.config_, J, F, "gmp", w);
    if (r.config_.steering_gmp) {
      r.steering_gmp_ = std::make_shared<const NemfGmpNetwork>(r.config_, J, F, "steering_gmp", w);
    }
    w.finish();
    return r;
  });
}

NemfRuntime NemfRuntime::load(const std::string& path) {
  return from_file(read_file_bytes(path), path);
}

void NemfRuntime::decode(const Eigen::Ref<const Eigen::VectorXd>& frames, const Eigen::Ref<const Eigen::VectorXf>& z_l,
                         const Eigen::Ref<const Eigen::VectorXf>& z_g, DecoderWorkspace* ws, MatrixRXf* out) const {
  decoder_->decode(frames, z_l, z_g, ws, out);
}

void NemfRuntime::decode_vjp(DecoderWorkspace* ws, ConstMatrixRef g_out, Eigen::VectorXf* g_zl,
                             Eigen::VectorXf* g_zg) const {
  decoder_->decode_vjp(ws, g_out, g_zl, g_zg);
}

const NemfGmpNetwork& NemfRuntime::gmp(GmpUse use) const {
  return use == GmpUse::Steering && steering_gmp_ ? *steering_gmp_ : *gmp_;
}

void NemfRuntime::predict_global(ConstMatrixRef inputs, GmpUse use, GmpWorkspace* ws, MatrixRXf* out) const {
  if (inputs.cols() != stats_.gmp_in_mean.size()) {
    throw InputError("predict_global: expected inputs [T, " + std::to_string(stats_.gmp_in_mean.size()) + "]");
  }
  ws->x = ((inputs.array().rowwise() - stats_.gmp_in_mean.array()).rowwise() / stats_.gmp_in_std.array()).matrix();
  gmp(use).forward(ws->x, ws, out);
  out->leftCols(4) =
      ((out->leftCols(4).array().rowwise() * stats_.gmp_out_std.array()).rowwise() + stats_.gmp_out_mean.array())
          .matrix();
}

void NemfRuntime::predict_global_vjp(GmpWorkspace* ws, GmpUse use, ConstMatrixRef g_out, MatrixRXf* g_inputs) const {
  ws->g_y = g_out;
  ws->g_y.leftCols(4) = (ws->g_y.leftCols(4).array().rowwise() * stats_.gmp_out_std.array()).matrix();
  gmp(use).input_gradient(ws, ws->g_y, g_inputs);
  *g_inputs = (g_inputs->array().rowwise() / stats_.gmp_in_std.array()).matrix();
}

LatentGaussians NemfRuntime::encode_features(ConstMatrixRef features, ConstMatrixRef root6d,
                                             const Eigen::Ref<const Eigen::VectorXf>& mask) const {
  const Eigen::Index T = features.rows(), J = rig_.num_joints(), window = config_.window;
  if (T < 1 || T > window || features.cols() != J * kFeaturesPerJoint || root6d.rows() != T || root6d.cols() != 6 ||
      mask.size() != T) {
    throw InputError("encode: expected features [T, " + std::to_string(J * kFeaturesPerJoint) +
                     "], root 6D [T, 6] and a mask [T] with 1 <= T <= " + std::to_string(window));
  }
  MatrixRXf local = MatrixRXf::Zero(window, J * (kFeaturesPerJoint + 1)), global = MatrixRXf::Zero(window, 7);
  for (Eigen::Index t = 0; t < T; ++t) {
    const float m = mask[t];
    for (Eigen::Index j = 0; j < J; ++j) {
      const Eigen::Index f = j * kFeaturesPerJoint;
      local.row(t).segment(j * (kFeaturesPerJoint + 1), kFeaturesPerJoint) =
          ((features.row(t).segment(f, kFeaturesPerJoint) - stats_.feature_mean.segment(f, kFeaturesPerJoint))
               .array() /
           stats_.feature_std.segment(f, kFeaturesPerJoint).array() * m)
              .matrix();
      local(t, j * (kFeaturesPerJoint + 1) + kFeaturesPerJoint) = m;
    }
    global.row(t).head(6) = ((root6d.row(t) - stats_.root_mean).array() / stats_.root_std.array() * m).matrix();
    global(t, 6) = m;
  }
  const Eigen::VectorXf l = encoders_->local(local), g = encoders_->global(global);
  return {l.head(config_.zl), l.tail(config_.zl), g.head(config_.zg), g.tail(config_.zg)};
}

LatentGaussians NemfRuntime::encode_rotations(ConstMatrixRef local_rotations) const {
  const Eigen::Index T = local_rotations.rows();
  if (T < 1 || T > config_.window || local_rotations.cols() != rig_.num_joints() * 9) {
    throw InputError("encode: expected local rotations [T, " + std::to_string(rig_.num_joints() * 9) +
                     "] with 1 <= T <= " + std::to_string(config_.window));
  }
  MatrixRXf features, root6d;
  local_features(*kinematics_, local_rotations, rig_.root_forward.cast<float>(), config_.fps, &features, &root6d);
  return encode_features(features, root6d, Eigen::VectorXf::Ones(T));
}

}  // namespace mf::runtime
