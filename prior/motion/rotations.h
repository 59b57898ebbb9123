// Rotation conversions in double precision (Eigen), for I/O and single poses.
// Quaternions are unit Hamilton quaternions (w, x, y, z) rotating column vectors
// (see skeleton.h). The batched, differentiable float versions are in
// rotations_torch.h; tests check the two against each other.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <string>

namespace mf {

enum class Axis { X = 0, Y = 1, Z = 2 };

/// Order of three rotation channels as they appear in a BVH file, e.g.
/// "Zrotation Xrotation Yrotation" is {Z, X, Y}. The rotation they describe is
/// R = R_{order[0]}(a0) * R_{order[1]}(a1) * R_{order[2]}(a2) (intrinsic, the
/// first channel outermost), which is BVH's convention.
using EulerOrder = std::array<Axis, 3>;

/// Parses "ZXY" (case-insensitive); throws mf::InputError on anything else
/// (three distinct axes are required).
EulerOrder euler_order_from_string(const std::string& s);
std::string to_string(const EulerOrder& order);

/// Angles in radians, in the channel order of `order`.
Eigen::Quaterniond quat_from_euler(const Eigen::Vector3d& angles, const EulerOrder& order);

/// Inverse of quat_from_euler. The middle angle lies in [-pi/2, pi/2]; at the
/// gimbal-lock singularity (middle angle +-pi/2, detected as cos(middle) < 1e-10)
/// the third angle is set to zero and the first carries the remaining rotation.
/// First and third angles in (-pi, pi]. quat_from_euler(euler_from_quat(q, o), o)
/// equals q up to sign for every q (to about 1e-15 rad, also near the lock).
/// `q` need not be normalised.
Eigen::Vector3d euler_from_quat(const Eigen::Quaterniond& q, const EulerOrder& order);

/// Like euler_from_quat, but of the two equivalent Euler triples (a0, a1, a2) and
/// (a0 + pi, pi - a1, a2 + pi), each angle shifted by the multiple of 2*pi nearest
/// `previous`, returns the one closest to `previous` (Euclidean distance), so that
/// curves written frame by frame stay continuous (angles may leave (-pi, pi]).
/// In gimbal lock, where only a0 +- a2 is determined, the third angle is kept at
/// previous[2] and the first takes the rest.
Eigen::Vector3d euler_from_quat_near(const Eigen::Quaterniond& q, const EulerOrder& order,
                                     const Eigen::Vector3d& previous);

/// 6D representation: the first two columns of the rotation matrix, stacked
/// (m00, m10, m20, m01, m11, m21).
using Vector6d = Eigen::Matrix<double, 6, 1>;
Vector6d sixd_from_matrix(const Eigen::Matrix3d& m);
/// Gram-Schmidt: normalise the first column, remove its part from the second and
/// normalise, third = cross product. Any 6-vector with two non-parallel halves works.
Eigen::Matrix3d matrix_from_sixd(const Vector6d& d6);

/// Spherical interpolation along the shortest path (flips q1 when q0.q1 < 0);
/// t = 0 gives q0, t = 1 gives q1 (up to sign). Falls back to normalised
/// linear interpolation when the quaternions are nearly equal.
Eigen::Quaterniond slerp(const Eigen::Quaterniond& q0, const Eigen::Quaterniond& q1, double t);

/// Angle in radians, in [0, pi], of the rotation taking a to b (double cover aware).
double geodesic_angle(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b);

}  // namespace mf
