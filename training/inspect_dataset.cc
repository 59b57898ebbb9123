// mf_inspect_dataset: loads a dataset through the data pipeline (prior/data/dataset.h)
// and prints what came out: load time, cache use, clip and frame counts per split,
// clip lengths, windows, the skeleton and every skipped clip.
//
//   mf_inspect_dataset [--source PATH] [--cache-dir DIR] [--validation-percent N]
//                      [--threads N] [--no-cache] [--quiet]
//
// Defaults: the shared training archive and the project cache (default_train_archive(),
// default_cache_dir(), overridable by MF_TRAIN_ARCHIVE / MF_CACHE_DIR).
// Exit status: 0 on success, 2 on bad input, 1 on any other error.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "prior/data/dataset.h"
#include "prior/util/command_line.h"

namespace {

struct SplitStats {
  size_t clips = 0;
  long long frames = 0;
  std::vector<int> lengths;
};

SplitStats stats_of(const std::vector<mf::Clip>& clips) {
  SplitStats s;
  s.clips = clips.size();
  for (const mf::Clip& c : clips) {
    s.frames += c.motion.num_frames();
    s.lengths.push_back(c.motion.num_frames());
  }
  std::sort(s.lengths.begin(), s.lengths.end());
  return s;
}

void print_split(const char* label, const std::vector<mf::Clip>& clips) {
  const SplitStats s = stats_of(clips);
  std::printf("%-11s %6zu clips %9lld frames", label, s.clips, s.frames);
  if (!s.lengths.empty()) {
    const double fps = clips.front().motion.fps;
    std::printf(" (%.2f h at %.3g fps); clip length min %d, median %d, max %d; shorter than 128: %zu", s.frames / fps / 3600.0,
                fps, s.lengths.front(), s.lengths[s.lengths.size() / 2], s.lengths.back(),
                static_cast<size_t>(std::lower_bound(s.lengths.begin(), s.lengths.end(), 128) - s.lengths.begin()));
  }
  std::printf("\n");
}

// Loads the dataset and prints the report.
int inspect(const mf::DatasetOptions& o) {
  const auto t0 = std::chrono::steady_clock::now();
  const mf::Dataset ds = mf::load_dataset(o);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  std::printf("source      %s\n", o.source.c_str());
  std::printf("cache dir   %s\n", o.cache_dir.empty() ? "(none)" : o.cache_dir.c_str());
  std::printf("load        %.2f s (%s, %d parsing threads)\n", seconds,
              ds.from_cache ? "from the cache" : (o.use_cache ? "parsed, cache written" : "parsed, no cache"), o.threads);
  std::printf("split       validation when fnv1a64(name) %% 100 < %d\n", o.validation_percent);
  print_split("train", ds.train);
  print_split("validation", ds.validation);
  std::printf("windows     128 frames every 64: train %zu (%zu with short clips kept), validation %zu (%zu)\n",
              mf::make_windows(ds.train, 128, 64, false).size(), mf::make_windows(ds.train, 128, 64, true).size(),
              mf::make_windows(ds.validation, 128, 64, false).size(),
              mf::make_windows(ds.validation, 128, 64, true).size());
  // Clips accepted with offsets off the reference by more than 0.01 mm (but within the
  // 1 mm tolerance); smaller differences are rounding in the files' position channels.
  size_t off_clips = 0;
  double off_max = 0.0;
  for (const auto* split : {&ds.train, &ds.validation}) {
    for (const mf::Clip& c : *split) {
      double d = 0.0;
      for (int j = 1; j < ds.skeleton.num_joints(); ++j)
        d = std::max(d, (c.motion.skeleton.offsets[j] - ds.skeleton.offsets[j]).norm());
      if (d > 1e-5) ++off_clips;
      off_max = std::max(off_max, d);
    }
  }
  std::printf("offsets     %zu clips differ from the reference skeleton by more than 0.01 mm, at most %.3f mm\n", off_clips,
              off_max * 1000.0);
  std::printf("skeleton    %d joints:", ds.skeleton.num_joints());
  for (const std::string& n : ds.skeleton.names) std::printf(" %s", n.c_str());
  std::printf("\nskipped     %zu\n", ds.skipped.size());
  for (const std::string& s : ds.skipped) std::printf("  %s\n", s.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  mf::DatasetOptions o;
  o.source = mf::default_train_archive();
  o.cache_dir = mf::default_cache_dir();
  o.verbose = true;
  CLI::App app{"Loads a dataset through the data pipeline (prior/data/dataset.h) and prints what came out.",
               "mf_inspect_dataset"};
  mf::cli::use_tool_defaults(app);
  app.add_option("--source", o.source, "BVH folder or .tar/.tar.xz/.tar.gz archive (MF_TRAIN_ARCHIVE overrides the "
                                       "default)");
  app.add_option("--cache-dir", o.cache_dir, "extraction and parse cache (MF_CACHE_DIR overrides the default)");
  app.add_option("--validation-percent", o.validation_percent, "clips whose name hashes below N go to validation")
      ->check(CLI::Range(0, 100));
  app.add_option("--threads", o.threads, "parsing threads; <= 0: one per hardware thread");
  app.add_flag_callback("--no-cache", [&] { o.use_cache = false; },
                        "parse again, neither reading nor writing the parse cache");
  app.add_flag_callback("--quiet", [&] { o.verbose = false; }, "no progress lines on stderr");
  return mf::cli::run(app, argc, argv, [&] { return inspect(o); });
}
