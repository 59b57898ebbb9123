// One window of a re-navigation problem (tasks/renav/renav.h) and the weights
// of its energy, as plain Eigen data: what both evaluations of the energy
// read, the libtorch one (evaluate_renav_energy(), tasks/reference/renav_energy.h) and the Eigen
// runtime's (RenavRuntimeEnergy, tasks/renav/renav_runtime_energy.h). No
// libtorch.
#pragma once

#include <Eigen/Core>

#include "prior/model/canonical_window.h"
#include "prior/motion/motion.h"
#include "prior/runtime/tensor_ops.h"
#include "tasks/renav/soft_dtw_kernels.h"

namespace mf {

struct RenavWeights {
  /// 2: at 1 a path turned from the reference's own direction
  /// could be traded for a slower walk (docs/BENCHMARKS.md, "Re-navigation").
  double path = 2.0;
  double joints = 0.5;
  double heading = 1.0;
  double foot_skating = 0.0;
  double continuity = 1.0;
  double gamma = kNemfSoftDtwGamma;  ///< soft-DTW smoothing (squared Euclidean cost)
};

/// One window of a re-navigation problem, canonical (see the top of
/// renav.h). Its GMP root path starts at the canonical origin. Float, one row
/// per frame; J joints.
struct RenavWindow {
  int length = 0;                        ///< T, output frames of the window (2 <= T <= the model's window)
  GroundTransform transform;             ///< canonical -> world
  runtime::MatrixRXf target_xz;          ///< [T, 2] target ground path (x, z), canonical
  runtime::MatrixRXf target_tangent;     ///< [T, 2] unit tangent (x, z) of the target path, canonical
  runtime::MatrixRXf reference_joints;   ///< [R, J * 3] heading-frame joint positions of the reference segment
  runtime::MatrixRXf reference_heading;  ///< [R, 1] the reference's c(t)
  /// Continuity with the previous window: its first S frames are shared with
  /// it (S = 0: no previous window).
  runtime::MatrixRXf shared_rotations;   ///< [S, J * 9] its local rotations there (root in this window's canonical frame)
  runtime::MatrixRXf shared_joints;      ///< [S, J * 3] its heading-frame joint positions there
  // For the initialisation.
  Motion reference_segment;              ///< the reference frames of this window (model fps, world)
  Motion turned_segment;                 ///< the same turned to follow the target, canonicalising at frame 0 to `transform`

  int num_shared() const { return static_cast<int>(shared_rotations.rows()); }
};

}  // namespace mf
