// Helpers shared by the unit tests: a small test skeleton and random motions.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "prior/inbetween/inbetweener.h"
#include "prior/model/nemf.h"
#include "prior/motion/motion.h"
#include "tasks/latent/window_problem.h"

namespace mf::test {

/// A 7-joint skeleton (hips, spine, head, two legs with feet), offsets in metres.
Skeleton small_skeleton();

/// A motion with smooth random local rotations and root path, deterministic in `seed`.
Motion random_motion(const Skeleton& skeleton, int frames, double fps, uint32_t seed);

/// The largest absolute difference of any rotation coefficient or root
/// position coordinate of two motions of the same size.
double max_abs_difference(const Motion& a, const Motion& b);

/// True when every rotation coefficient and root position of `m` is finite.
bool all_finite(const Motion& m);

/// A tiny prior (32-frame window, 3x32 decoder, z_l 8, z_g 4) for fast tests.
NemfConfig tiny_nemf_config();
/// The rig of small_skeleton(), measured from one random motion.
RigInfo tiny_rig();
/// A tiny random prior, frozen (no gradients), its weights drawn after
/// at::manual_seed(seed).
NemfModel tiny_prior(uint64_t seed = 0, const NemfConfig& config = tiny_nemf_config(),
                     const RigInfo& rig = tiny_rig());
/// A tiny random transformer in-betweener of `kind` (kTwoStageKind or
/// kCitlKind; width 16, one layer, window 32), drawn after at::manual_seed(seed).
std::unique_ptr<InbetweenModel> tiny_transformer(const std::string& kind, const RigInfo& rig, uint64_t seed = 0);

/// A fresh empty directory under the build tree's test scratch area.
std::string scratch_dir(const std::string& name);

/// Column `name` of a trainer's log.csv, one value per epoch (empty when the
/// file or the column is missing).
std::vector<double> log_column(const std::string& path, const std::string& name);

/// A decoded window's local rotations as [T, J, 3, 3] and its root path as
/// [T, 3] float tensors.
at::Tensor window_rotations(const DecodedWindow& d);
at::Tensor window_root_positions(const DecodedWindow& d);

}  // namespace mf::test
