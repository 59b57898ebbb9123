#include "bench/foreign_data.h"

#include <cstdio>
#include <set>

#include "prior/motion/bvh.h"
#include "prior/motion/errors.h"
#include "prior/motion/interpolation.h"
#include "prior/motion/motion_bvh.h"
#include "prior/rig/units.h"
#include "tasks/methods/jobs.h"

namespace mf::bench {
namespace {

// "cmu-daz/12_01.bvh" -> {"cmu-daz", "12_01"}.
std::pair<std::string, std::string> folder_and_stem(const std::string& relative) {
  const size_t slash = relative.rfind('/');
  const std::string folder = slash == std::string::npos ? "" : relative.substr(0, slash);
  std::string name = slash == std::string::npos ? relative : relative.substr(slash + 1);
  const size_t dot = name.rfind('.');
  if (dot != std::string::npos) name = name.substr(0, dot);
  const size_t parent = folder.rfind('/');
  return {parent == std::string::npos ? folder : folder.substr(parent + 1), name};
}

std::string subject_of(const std::string& stem) { return stem.substr(0, stem.find('_')); }

}  // namespace

bool is_foreign_validation_clip(const std::string& relative) {
  const auto [folder, stem] = folder_and_stem(relative);
  if (folder == "cmu-daz" || folder == "cmu-3dsmax") return true;
  if (folder == "cmu-cgspeed") {
    static const std::set<std::string> held{"60_13", "60_14", "60_15", "10_05", "10_06"};
    return held.count(stem) > 0;
  }
  if (folder == "reactidle") {
    static const std::set<std::string> held{"010_genuine", "011_genuine", "012_genuine",
                                            "013_genuine", "014_genuine", "015_genuine"};
    return held.count(stem) > 0;
  }
  return false;
}

std::string foreign_content(const std::string& relative) {
  const auto [folder, stem] = folder_and_stem(relative);
  const std::string subject = subject_of(stem);
  if (folder == "reactidle") return "standing idle";
  if (folder == "cmu-3dsmax") return "stylised walks and hops";
  if (subject == "10") return "soccer kicks";
  if (subject == "60") return "salsa";
  if (folder == "cmu-daz") return "everyday actions";
  return "other";
}

ForeignData load_foreign_data(const std::string& source, const std::string& cache_dir, double fps, bool verbose) {
  ForeignData data;
  for (const SourceBvhFile& file : list_source_bvh_files(source, cache_dir, verbose)) {
    ForeignClip c;
    c.convention = folder_and_stem(file.relative).first;
    c.content = foreign_content(file.relative);
    try {
      const BvhDocument doc = read_bvh_file(file.path);
      BvhUnits units;
      units.length_scale = detect_bvh_length_unit(doc).metres;
      const Motion motion = motion_from_bvh(doc, units);
      c.source_fps = motion.fps;
      c.clip.name = file.relative;
      c.clip.motion = resample_cubic(motion, fps, resampled_frame_count(motion.num_frames(), motion.fps, fps, nullptr));
    } catch (const InputError& e) {
      throw InputError(file.relative + ": " + e.what());
    }
    if (verbose)
      std::fprintf(stderr, "foreign: %s, %d frames at %g fps (%s)\n", file.relative.c_str(),
                   c.clip.motion.num_frames(), fps, c.content.c_str());
    (is_foreign_validation_clip(file.relative) ? data.validation : data.train).push_back(std::move(c));
  }
  return data;
}

}  // namespace mf::bench
