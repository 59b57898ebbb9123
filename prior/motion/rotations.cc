#include "prior/motion/rotations.h"

#include <algorithm>
#include <cctype>
#include <cmath>

#include "prior/motion/errors.h"

namespace mf {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Below this cos(middle angle) the first and third axes coincide to working
// precision and only their combined angle is determined.
constexpr double kGimbalEpsilon = 1e-10;

Eigen::Vector3d unit_axis(Axis a) { return Eigen::Vector3d::Unit(static_cast<int>(a)); }

// Axis indices of an order and its parity: +1 for cyclic orders (XYZ, YZX, ZXY),
// where e_i x e_j = e_k, -1 for the others.
struct OrderIndices {
  int i, j, k;
  double parity;
};

OrderIndices indices_of(const EulerOrder& order) {
  OrderIndices o{static_cast<int>(order[0]), static_cast<int>(order[1]), static_cast<int>(order[2]), 1.0};
  o.parity = ((o.j - o.i + 3) % 3 == 1) ? 1.0 : -1.0;
  return o;
}

// Maps an angle to (-pi, pi].
double wrap_pi(double a) {
  a = std::remainder(a, 2.0 * kPi);
  return a <= -kPi ? a + 2.0 * kPi : a;
}

// The 2*pi wrap of `a` nearest to `target`.
double wrap_near(double a, double target) { return a + 2.0 * kPi * std::round((target - a) / (2.0 * kPi)); }

Eigen::Vector3d wrap_near(const Eigen::Vector3d& a, const Eigen::Vector3d& target) {
  return {wrap_near(a[0], target[0]), wrap_near(a[1], target[1]), wrap_near(a[2], target[2])};
}

bool is_gimbal_locked(const Eigen::Matrix3d& m, const OrderIndices& o) {
  return std::hypot(m(o.i, o.i), m(o.i, o.j)) < kGimbalEpsilon;
}

}  // namespace

EulerOrder euler_order_from_string(const std::string& s) {
  if (s.size() != 3) throw InputError("Euler order '" + s + "' must be three axis letters, e.g. ZXY");
  EulerOrder order{};
  for (int n = 0; n < 3; ++n) {
    const int letter = std::toupper(static_cast<unsigned char>(s[n]));
    if (letter < 'X' || letter > 'Z') throw InputError("Euler order '" + s + "' has an axis other than X, Y or Z");
    order[n] = static_cast<Axis>(letter - 'X');
  }
  if (order[0] == order[1] || order[1] == order[2] || order[0] == order[2])
    throw InputError("Euler order '" + s + "' must name three distinct axes");
  return order;
}

std::string to_string(const EulerOrder& order) {
  std::string s;
  for (Axis a : order) s += "XYZ"[static_cast<int>(a)];
  return s;
}

Eigen::Quaterniond quat_from_euler(const Eigen::Vector3d& angles, const EulerOrder& order) {
  Eigen::Quaterniond q = Eigen::Quaterniond(Eigen::AngleAxisd(angles[0], unit_axis(order[0]))) *
                         Eigen::Quaterniond(Eigen::AngleAxisd(angles[1], unit_axis(order[1]))) *
                         Eigen::Quaterniond(Eigen::AngleAxisd(angles[2], unit_axis(order[2])));
  return q.normalized();
}

// With M = R_i(a) R_j(b) R_k(c) and parity s: M(i,k) = s sin b, the j and k
// entries of column k and of row i give a and c. Away from the singularity, c is
// taken from R_i(a)^T M = R_j(b) R_k(c), whose row j is row j of R_k(c): those
// entries are O(1), so a and c stay consistent even when cos b is tiny.
Eigen::Vector3d euler_from_quat(const Eigen::Quaterniond& q, const EulerOrder& order) {
  const OrderIndices o = indices_of(order);
  const double s = o.parity;
  const Eigen::Matrix3d m = q.normalized().toRotationMatrix();
  const double b = std::atan2(s * m(o.i, o.k), std::hypot(m(o.i, o.i), m(o.i, o.j)));
  double a, c;
  if (is_gimbal_locked(m, o)) {
    // M = R_i(a) R_j(+-pi/2): column j of M is R_i(a) e_j = cos a e_j + s sin a e_k.
    a = std::atan2(s * m(o.k, o.j), m(o.j, o.j));
    c = 0.0;
  } else {
    a = std::atan2(-s * m(o.j, o.k), m(o.k, o.k));
    const Eigen::Matrix3d p = Eigen::AngleAxisd(-a, unit_axis(order[0])).toRotationMatrix() * m;
    c = std::atan2(s * p(o.j, o.i), p(o.j, o.j));
  }
  return {wrap_pi(a), b, wrap_pi(c)};
}

Eigen::Vector3d euler_from_quat_near(const Eigen::Quaterniond& q, const EulerOrder& order,
                                     const Eigen::Vector3d& previous) {
  const OrderIndices o = indices_of(order);
  const Eigen::Vector3d e = euler_from_quat(q, order);
  if (is_gimbal_locked(q.normalized().toRotationMatrix(), o)) {
    // Only a + sigma * c is determined (sigma = s * sign(sin b)): keep the previous
    // third angle and give the first the rest.
    const double sigma = o.parity * (e[1] >= 0 ? 1.0 : -1.0);
    const double c = previous[2];
    return wrap_near(Eigen::Vector3d(e[0] - sigma * c, e[1], c), previous);
  }
  const Eigen::Vector3d first = wrap_near(e, previous);
  const Eigen::Vector3d second = wrap_near(Eigen::Vector3d(e[0] + kPi, kPi - e[1], e[2] + kPi), previous);
  return (first - previous).squaredNorm() <= (second - previous).squaredNorm() ? first : second;
}

Vector6d sixd_from_matrix(const Eigen::Matrix3d& m) {
  Vector6d d;
  d << m.col(0), m.col(1);
  return d;
}

Eigen::Matrix3d matrix_from_sixd(const Vector6d& d6) {
  constexpr double kTiny = 1e-12;
  Eigen::Vector3d x = d6.head<3>();
  Eigen::Vector3d y = d6.tail<3>();
  // Degenerate inputs (a zero or parallel half) get a deterministic completion
  // instead of NaNs.
  x = x.norm() > kTiny ? Eigen::Vector3d(x.normalized()) : Eigen::Vector3d::UnitX();
  y -= x.dot(y) * x;
  if (y.norm() <= kTiny) {
    const Eigen::Vector3d helper = std::abs(x.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
    y = helper - x.dot(helper) * x;
  }
  y.normalize();
  Eigen::Matrix3d m;
  m << x, y, x.cross(y);
  return m;
}

Eigen::Quaterniond slerp(const Eigen::Quaterniond& q0, const Eigen::Quaterniond& q1, double t) {
  const Eigen::Vector4d a = q0.normalized().coeffs();
  Eigen::Vector4d b = q1.normalized().coeffs();
  double d = a.dot(b);
  if (d < 0) {
    b = -b;
    d = -d;
  }
  Eigen::Vector4d r;
  if (d > 0.9995) {
    r = (1.0 - t) * a + t * b;
  } else {
    const double theta = std::acos(std::min(d, 1.0));
    const double sin_theta = std::sin(theta);
    r = (std::sin((1.0 - t) * theta) / sin_theta) * a + (std::sin(t * theta) / sin_theta) * b;
  }
  r.normalize();
  // coeffs() is (x, y, z, w); the constructor takes (w, x, y, z).
  return Eigen::Quaterniond(r[3], r[0], r[1], r[2]);
}

double geodesic_angle(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) {
  // atan2 of the half-angle's sine and cosine keeps full precision near zero,
  // where 2*acos(|a.b|) would round tiny angles to 0.
  const Eigen::Quaterniond rel = a.normalized().conjugate() * b.normalized();
  return 2.0 * std::atan2(rel.vec().norm(), std::abs(rel.w()));
}

}  // namespace mf
