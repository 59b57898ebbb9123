#include "prior/runtime/inbetween_inputs.h"

#include "prior/runtime/transformer_blocks.h"

namespace mf::runtime {

std::vector<bool> flags_of(const Eigen::Ref<const Eigen::VectorXf>& values) {
  std::vector<bool> f(values.size());
  for (Eigen::Index t = 0; t < values.size(); ++t) f[t] = values[t] > 0.5f;
  return f;
}

MaskedWindow masked_window(const InbetweenWindow& in, const InbetweenNormalisation& n, int joints) {
  const Eigen::Index T = in.pose.rows(), J = joints, D = 6 * J + 3;
  MaskedWindow m;
  m.known = (in.known.array().colwise() * in.valid.array()).matrix();
  m.channel_known.resize(T, D);
  for (Eigen::Index j = 0; j < J; ++j) {
    m.channel_known.middleCols(6 * j, 6) = (m.known.col(j).array() > 0.5f).cast<float>().replicate(1, 6).matrix();
  }
  m.channel_known.rightCols(3) = (m.known.col(J).array() > 0.5f).cast<float>().replicate(1, 3).matrix();
  m.key = flags_of(m.known.rowwise().maxCoeff());
  m.valid = flags_of(in.valid);
  m.normalised = ((in.pose.array().rowwise() - n.mean.array()).rowwise() / n.scale.array()).matrix();
  return m;
}

MatrixRXf masked_pose_input(const InbetweenWindow& in, const MaskedWindow& m, const InbetweenNormalisation& n,
                            int joints) {
  const Eigen::Index T = in.pose.rows(), R = 6 * joints;
  MatrixRXf x(T, R + 3);
  x.leftCols(R) = (m.channel_known.leftCols(R).array() > 0.5f).select(m.normalised.leftCols(R), 0.0f);
  const MatrixRXf root = interpolate_known(in.pose.rightCols(3), flags_of(m.known.col(joints)));
  x.rightCols(3) = ((root.array().rowwise() - n.mean.tail(3).array()).rowwise() / n.scale.tail(3).array()).matrix();
  return x;
}

MatrixRXf where_known(const MatrixRXf& channel_known, const MatrixRXf& x, const MatrixRXf& y) {
  return (channel_known.array() > 0.5f).select(x, y);
}

MatrixRXf denormalised(const MatrixRXf& x, const InbetweenNormalisation& n) {
  return ((x.array().rowwise() * n.scale.array()).rowwise() + n.mean.array()).matrix();
}

MatrixRXf concat_columns(const MatrixRXf& a, const MatrixRXf& b) {
  MatrixRXf c(a.rows(), a.cols() + b.cols());
  c << a, b;
  return c;
}

}  // namespace mf::runtime
