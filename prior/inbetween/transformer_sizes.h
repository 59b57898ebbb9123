// The sizes and constants of the transformer blocks (transformer_blocks.h),
// torch-free: the Eigen runtime's blocks (prior/runtime/transformer_blocks.h)
// are built from the same numbers.
#pragma once

namespace mf::blocks {

/// Additive attention mask: large but finite, so a row with every key masked
/// gives a uniform softmax instead of NaN.
constexpr double kMasked = -1e9;
/// Hidden units of the per-layer relative position MLP.
constexpr int kRelativeHidden = 32;
/// Frame distances enter the position MLPs as sinusoids of kFrequencies
/// frequencies (periods geometric from 4 frames to twice the window) plus the
/// distance divided by the window: plain scalars make positions hard to tell
/// apart at initialisation and slow training down.
constexpr int kFrequencies = 8;
constexpr int kDistanceFeatures = 2 * kFrequencies + 1;
/// Keyframe encoding inputs (key_features()): the distance to the previous
/// key, to the next key and the fraction of the way between them.
constexpr int kKeyFeatures = 2 * kDistanceFeatures + 1;

/// Sizes of one transformer trunk.
struct TrunkSize {
  int width = 64;    ///< d_model
  int layers = 2;    ///< transformer layers
  int heads = 4;     ///< attention heads (divide width)
  int ffn = 128;     ///< feed-forward units
  int window = 128;  ///< maximum frames (relative offsets are clamped to it)
};

}  // namespace mf::blocks
