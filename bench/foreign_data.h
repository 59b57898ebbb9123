// The real capture on other rigs of the shared data (`foreign/foreign.tar.xz`,
// its README): other people on five other rig conventions, units and frame
// rates, for `motionfield-bench --dataset foreign` and for training on more
// bodies. Each clip is read as a user's file is read (its unit detected from
// the leg length, prior/rig/units.h), kept on its own rig and resampled to
// the model's frame rate.
//
// Split (the README's suggestion, fixed): validation = every clip of
// `cmu-daz/` and `cmu-3dsmax/`, `cmu-cgspeed/` 60_13, 60_14, 60_15, 10_05 and
// 10_06, and `reactidle/` 010..015_genuine; every other clip is training.
// No model may be trained on the validation clips.
#pragma once

#include <string>
#include <vector>

#include "prior/data/dataset.h"

namespace mf::bench {

struct ForeignClip {
  std::string convention;  ///< the rig convention: its folder ("cmu-cgspeed", "cmu-daz", ...)
  std::string content;     ///< what is performed, from the data's README ("salsa", "standing idle", ...)
  double source_fps = 0;   ///< the file's own frame rate
  Clip clip;               ///< on the file's own rig, metres, at the loader's frame rate
};

struct ForeignData {
  std::vector<ForeignClip> train;
  std::vector<ForeignClip> validation;
};

/// True when the clip at `relative` (path in the archive, e.g.
/// "cmu-daz/12_01.bvh") belongs to the validation split above.
bool is_foreign_validation_clip(const std::string& relative);

/// The content label of a clip by its path (the README's description of each
/// subject); "other" for a file it does not describe.
std::string foreign_content(const std::string& relative);

/// Every BVH file of `source` (folder or archive, extracted into `cache_dir`),
/// read with its detected unit and resampled to `fps` (Catmull-Rom; the time
/// span kept), split as above. Throws InputError naming the file when one
/// cannot be read.
ForeignData load_foreign_data(const std::string& source, const std::string& cache_dir, double fps, bool verbose);

}  // namespace mf::bench
