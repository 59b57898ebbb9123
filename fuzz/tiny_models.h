// The smallest models the loaders accept, for the fuzz targets' seeds and the
// C API targets' model (made in memory at start-up): the 7-joint test rig
// (tests/test_util.h), the smallest sizes each kind's hyperparameter checks
// allow, random weights. Cheap to run: a solve or a pass costs well under a
// millisecond per frame.
#pragma once

#include <memory>
#include <string>

#include "prior/inbetween/inbetweener.h"
#include "prior/model/nemf.h"

namespace mf::fuzz {

/// A NeMF prior with window 16, decoder 1x8, z_l 2, z_g 1, frozen.
NemfModel micro_prior();
/// An in-betweener of `kind` (any of inbetweener_kinds()) on `rig`, width 8,
/// one layer, one head, window 16.
std::unique_ptr<InbetweenModel> micro_inbetweener(const std::string& kind, const RigInfo& rig);

}  // namespace mf::fuzz
