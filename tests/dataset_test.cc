// Tests of the data pipeline (prior/data/dataset.h) on small generated corpora;
// nothing here reads the shared training archive.
#include "prior/data/dataset.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "prior/motion/errors.h"
#include "prior/motion/motion_bvh.h"
#include "tests/test_util.h"

namespace mf {
namespace {

namespace fs = std::filesystem;

void write_clip(const fs::path& path, const Motion& m) {
  fs::create_directories(path.parent_path());
  write_motion(path.string(), m, default_bvh_layout(m.skeleton));
}

void write_text(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

// A corpus of 7 BVH files (and one ignored JSON file). In path order:
//   a/clip_a.bvh       60 frames  (the reference skeleton)
//   a/clip_b.bvh      200 frames
//   b/sub/clip_d.bvh   40 frames
//   broken.bvh        malformed                      -> skipped
//   clip_c.bvh        130 frames, one offset 0.4 mm off -> kept
//   far_offset.bvh    one offset 5 mm off              -> skipped
//   other_rig.bvh     a joint renamed                  -> skipped
// Usable clips in path order: clip_a, clip_b, clip_d, clip_c.
// FNV-1a-64(name) % 100: clip_a 89, clip_b 12, clip_c 95, clip_d 98.
void write_corpus(const fs::path& root) {
  const Skeleton skel = test::small_skeleton();
  write_clip(root / "a" / "clip_a.bvh", test::random_motion(skel, 60, 30.0, 1));
  write_clip(root / "a" / "clip_b.bvh", test::random_motion(skel, 200, 30.0, 2));
  write_clip(root / "b" / "sub" / "clip_d.bvh", test::random_motion(skel, 40, 30.0, 4));
  write_text(root / "broken.bvh", "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 zero\n");
  Skeleton near = skel;
  near.offsets[4].x() += 0.0004;
  write_clip(root / "clip_c.bvh", test::random_motion(near, 130, 30.0, 3));
  Skeleton far = skel;
  far.offsets[4].x() += 0.005;
  write_clip(root / "far_offset.bvh", test::random_motion(far, 50, 30.0, 5));
  Skeleton other = skel;
  other.names[2] = "Neck";
  write_clip(root / "other_rig.bvh", test::random_motion(other, 50, 30.0, 6));
  write_text(root / "a" / "clip_a.json", "{}");
}

std::vector<std::string> names_of(const std::vector<Clip>& clips) {
  std::vector<std::string> n;
  for (const Clip& c : clips) n.push_back(c.name);
  return n;
}

void expect_same_skeleton(const Skeleton& a, const Skeleton& b) {
  EXPECT_EQ(a.names, b.names);
  EXPECT_EQ(a.parents, b.parents);
  ASSERT_EQ(a.offsets.size(), b.offsets.size());
  for (size_t j = 0; j < a.offsets.size(); ++j) EXPECT_EQ(a.offsets[j], b.offsets[j]) << "joint " << j;
}

// Bit-for-bit equality.
void expect_same_clips(const std::vector<Clip>& a, const std::vector<Clip>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t c = 0; c < a.size(); ++c) {
    SCOPED_TRACE(a[c].name);
    EXPECT_EQ(a[c].name, b[c].name);
    EXPECT_EQ(a[c].motion.fps, b[c].motion.fps);
    expect_same_skeleton(a[c].motion.skeleton, b[c].motion.skeleton);
    ASSERT_EQ(a[c].motion.rotations.size(), b[c].motion.rotations.size());
    ASSERT_EQ(a[c].motion.root_positions.size(), b[c].motion.root_positions.size());
    for (size_t i = 0; i < a[c].motion.rotations.size(); ++i)
      ASSERT_EQ(a[c].motion.rotations[i].coeffs(), b[c].motion.rotations[i].coeffs()) << "rotation " << i;
    for (size_t i = 0; i < a[c].motion.root_positions.size(); ++i)
      ASSERT_EQ(a[c].motion.root_positions[i], b[c].motion.root_positions[i]) << "frame " << i;
  }
}

void expect_same_dataset(const Dataset& a, const Dataset& b) {
  expect_same_skeleton(a.skeleton, b.skeleton);
  expect_same_clips(a.train, b.train);
  expect_same_clips(a.validation, b.validation);
  EXPECT_EQ(a.skipped, b.skipped);
}

std::vector<fs::path> files_matching(const fs::path& dir, const std::string& prefix, const std::string& suffix = "") {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    if (n.rfind(prefix, 0) == 0 && n.size() >= suffix.size() && n.compare(n.size() - suffix.size(), suffix.size(), suffix) == 0)
      out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

bool has_temp_files(const fs::path& dir) {
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().find(".tmp-") != std::string::npos) return true;
  return false;
}

TEST(DatasetSplit, Fnv1a64KnownVectors) {
  EXPECT_EQ(fnv1a64(""), 0xcbf29ce484222325ULL);
  EXPECT_EQ(fnv1a64("a"), 0xaf63dc4c8601ec8cULL);
  EXPECT_EQ(fnv1a64("foobar"), 0x85944171f73967e8ULL);
}

TEST(DatasetSplit, ValidationIsAPureFunctionOfTheName) {
  // fnv1a64("clip_a.bvh") % 100 == 89, fnv1a64("clip_b.bvh") % 100 == 12.
  EXPECT_EQ(fnv1a64("clip_a.bvh") % 100, 89u);
  EXPECT_FALSE(is_validation_clip("clip_a.bvh", 89));
  EXPECT_TRUE(is_validation_clip("clip_a.bvh", 90));
  EXPECT_FALSE(is_validation_clip("clip_b.bvh", 12));
  EXPECT_TRUE(is_validation_clip("clip_b.bvh", 13));
  EXPECT_FALSE(is_validation_clip("clip_b.bvh", 10));
  // fnv1a64("dataset-1_walk_normal_001.bvh") % 100 == 25: training at the default 10 %.
  EXPECT_FALSE(is_validation_clip("dataset-1_walk_normal_001.bvh", 10));
  for (const std::string name : {"", "x.bvh", "clip_a.bvh", "dataset-2_run_normal_003.bvh"}) {
    EXPECT_FALSE(is_validation_clip(name, 0)) << name;
    EXPECT_TRUE(is_validation_clip(name, 100)) << name;
    for (int p = 0; p <= 100; p += 7) EXPECT_EQ(is_validation_clip(name, p), is_validation_clip(name, p)) << name;
  }
}

TEST(DatasetLoad, FolderRecursiveInPathOrderWithSkippedClips) {
  const fs::path root = test::scratch_dir("dataset_folder");
  write_corpus(root / "src");
  DatasetOptions o;
  o.source = (root / "src").string();
  o.validation_percent = 0;
  const Dataset ds = load_dataset(o);
  EXPECT_FALSE(ds.from_cache);
  EXPECT_EQ(names_of(ds.train), (std::vector<std::string>{"clip_a.bvh", "clip_b.bvh", "clip_d.bvh", "clip_c.bvh"}));
  EXPECT_TRUE(ds.validation.empty());
  std::vector<int> frames;
  for (const Clip& c : ds.train) frames.push_back(c.motion.num_frames());
  EXPECT_EQ(frames, (std::vector<int>{60, 200, 40, 130}));

  ASSERT_EQ(ds.skipped.size(), 3u);
  EXPECT_EQ(ds.skipped[0].rfind("broken.bvh: ", 0), 0u) << ds.skipped[0];
  EXPECT_EQ(ds.skipped[1].rfind("far_offset.bvh: ", 0), 0u) << ds.skipped[1];
  EXPECT_NE(ds.skipped[1].find("Foot_L"), std::string::npos) << ds.skipped[1];  // joint 4
  EXPECT_EQ(ds.skipped[2].rfind("other_rig.bvh: ", 0), 0u) << ds.skipped[2];
  EXPECT_NE(ds.skipped[2].find("Neck"), std::string::npos) << ds.skipped[2];

  // The reference skeleton is clip_a's; clip_c keeps its own (0.4 mm longer) offset.
  const Skeleton ref = test::small_skeleton();
  EXPECT_EQ(ds.skeleton.names, ref.names);
  EXPECT_EQ(ds.skeleton.parents, ref.parents);
  for (int j = 1; j < ref.num_joints(); ++j) EXPECT_LT((ds.skeleton.offsets[j] - ref.offsets[j]).norm(), 1e-7) << j;
  EXPECT_NEAR(ds.train[3].motion.skeleton.offsets[4].x() - ds.skeleton.offsets[4].x(), 0.0004, 1e-7);

  // The clips are the files' motions (not mixed up): compare clip_b with what was written.
  const Motion b = test::random_motion(ref, 200, 30.0, 2);
  const Motion& got = ds.train[1].motion;
  EXPECT_NEAR(got.fps, 30.0, 1e-4);
  for (int f = 0; f < 200; f += 17) {
    EXPECT_LT((got.root_positions[f] - b.root_positions[f]).norm(), 1e-5) << f;
    for (int j = 0; j < ref.num_joints(); ++j)
      EXPECT_GT(std::abs(got.rotation(f, j).dot(b.rotation(f, j))), 1.0 - 1e-9) << f << " " << j;
  }
}

TEST(DatasetLoad, SplitDependsOnlyOnNames) {
  const fs::path root = test::scratch_dir("dataset_split");
  write_corpus(root / "src");
  DatasetOptions o;
  o.source = (root / "src").string();
  o.validation_percent = 90;  // clip_a (89) and clip_b (12) go to validation; clip_c (95) and clip_d (98) stay
  o.threads = 1;
  const Dataset one = load_dataset(o);
  EXPECT_EQ(names_of(one.validation), (std::vector<std::string>{"clip_a.bvh", "clip_b.bvh"}));
  EXPECT_EQ(names_of(one.train), (std::vector<std::string>{"clip_d.bvh", "clip_c.bvh"}));

  o.threads = 3;  // more threads than needed: same result, bit for bit
  expect_same_dataset(one, load_dataset(o));

  // A subset of the files, in another layout: the same clips go to the same side.
  fs::create_directories(root / "subset" / "z");
  fs::copy_file(root / "src" / "clip_c.bvh", root / "subset" / "clip_c.bvh");
  fs::copy_file(root / "src" / "a" / "clip_b.bvh", root / "subset" / "z" / "clip_b.bvh");
  o.source = (root / "subset").string();
  const Dataset sub = load_dataset(o);
  EXPECT_EQ(names_of(sub.validation), (std::vector<std::string>{"clip_b.bvh"}));
  EXPECT_EQ(names_of(sub.train), (std::vector<std::string>{"clip_c.bvh"}));
  EXPECT_TRUE(sub.skipped.empty());
}

TEST(DatasetLoad, RejectsBadSources) {
  const fs::path root = test::scratch_dir("dataset_bad_sources");
  DatasetOptions o;
  o.source = (root / "missing").string();
  EXPECT_THROW(load_dataset(o), InputError);

  fs::create_directories(root / "empty");
  write_text(root / "empty" / "notes.txt", "no clips here");
  o.source = (root / "empty").string();
  EXPECT_THROW(load_dataset(o), InputError);

  write_text(root / "only_broken" / "broken.bvh", "HIERARCHY\nROOT");
  o.source = (root / "only_broken").string();
  try {
    load_dataset(o);
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("broken.bvh"), std::string::npos) << e.what();
  }

  write_text(root / "clips.zip", "PK");
  o.source = (root / "clips.zip").string();
  EXPECT_THROW(load_dataset(o), InputError);

  write_text(root / "clips.tar", "");
  o.source = (root / "clips.tar").string();  // an archive needs a cache_dir
  EXPECT_THROW(load_dataset(o), InputError);

  write_clip(root / "ok" / "x.bvh", test::random_motion(test::small_skeleton(), 10, 30.0, 9));
  o.source = (root / "ok").string();
  o.validation_percent = 101;
  EXPECT_THROW(load_dataset(o), InputError);
  o.validation_percent = -1;
  EXPECT_THROW(load_dataset(o), InputError);
  o.validation_percent = 10;
  EXPECT_NO_THROW(load_dataset(o));
}

TEST(DatasetLoad, ArchivesGiveTheSameClipsAsTheFolder) {
  const fs::path root = test::scratch_dir("dataset_archives");
  write_corpus(root / "src");
  DatasetOptions o;
  o.source = (root / "src").string();
  o.validation_percent = 50;
  const Dataset from_folder = load_dataset(o);

  const std::vector<std::pair<std::string, std::string>> formats = {
      {"clips.tar.xz", "-cJf"}, {"clips.tgz", "-czf"}, {"clips.tar", "-cf"}};
  for (const auto& [file, flags] : formats) {
    SCOPED_TRACE(file);
    const fs::path archive = root / file;
    const std::string cmd = "tar " + flags + " '" + archive.string() + "' -C '" + (root / "src").string() + "' .";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    const fs::path cache = root / ("cache-" + file);
    o.source = archive.string();
    o.cache_dir = cache.string();
    o.use_cache = false;
    const Dataset ds = load_dataset(o);
    EXPECT_FALSE(ds.from_cache);
    expect_same_dataset(from_folder, ds);
    // One complete extraction folder, no temporary left behind, no clips cache (use_cache is false).
    const auto extracted = files_matching(cache, "extract-");
    ASSERT_EQ(extracted.size(), 1u);
    EXPECT_TRUE(fs::is_regular_file(extracted[0] / "a" / "clip_a.bvh"));
    EXPECT_FALSE(has_temp_files(cache));
    EXPECT_TRUE(files_matching(cache, "clips-").empty());
    // A second load reuses the extraction.
    expect_same_dataset(from_folder, load_dataset(o));
    EXPECT_EQ(files_matching(cache, "extract-").size(), 1u);
  }

  // A truncated archive fails with InputError and leaves no partial extraction.
  {
    const fs::path full = root / "clips.tar.xz";
    const fs::path cut = root / "cut.tar.xz";
    std::string bytes;
    {
      std::ifstream in(full, std::ios::binary);
      bytes.assign(std::istreambuf_iterator<char>(in), {});
    }
    write_text(cut, bytes.substr(0, bytes.size() / 2));
    const fs::path cache = root / "cache-cut";
    o.source = cut.string();
    o.cache_dir = cache.string();
    EXPECT_THROW(load_dataset(o), InputError);
    EXPECT_TRUE(files_matching(cache, "extract-").empty());
  }
}

// Archives are read with libarchive (prior/data/tar_archive.h): only regular
// files are extracted, and an entry that would land outside the extraction
// folder (a ".." component, an absolute path) fails the load before anything of
// it is written, leaving no extraction behind.
TEST(DatasetLoad, ArchivesExtractRegularFilesAndRefuseUnsafePaths) {
  const fs::path root = test::scratch_dir("dataset_archive_entries");
  const Skeleton skel = test::small_skeleton();
  write_clip(root / "src" / "clips" / "ok.bvh", test::random_motion(skel, 20, 30.0, 1));
  write_clip(root / "src" / "evil.bvh", test::random_motion(skel, 20, 30.0, 2));
  fs::create_symlink("ok.bvh", root / "src" / "clips" / "link.bvh");
  auto make_tar = [&](const std::string& name, const std::string& members) {
    // -P keeps "../" and "/" in member names, as a hostile archive would hold them.
    const std::string cmd = "tar -cPf '" + (root / name).string() + "' -C '" + (root / "src" / "clips").string() +
                            "' " + members + " 2>/dev/null";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
    return (root / name).string();
  };
  DatasetOptions o;
  o.cache_dir = (root / "cache").string();
  o.use_cache = false;

  o.source = make_tar("good.tar", ".");
  const Dataset good = load_dataset(o);
  EXPECT_EQ(names_of(good.train).size() + names_of(good.validation).size(), 1u);
  const auto extracted = files_matching(root / "cache", "extract-");
  ASSERT_EQ(extracted.size(), 1u);
  EXPECT_TRUE(fs::is_regular_file(extracted[0] / "ok.bvh"));
  EXPECT_FALSE(fs::exists(fs::symlink_status(extracted[0] / "link.bvh")));

  const std::vector<std::pair<std::string, std::string>> unsafe = {
      {"dotdot.tar", "ok.bvh ../evil.bvh"}, {"absolute.tar", "ok.bvh '" + (root / "src" / "evil.bvh").string() + "'"}};
  for (const auto& [name, members] : unsafe) {
    SCOPED_TRACE(name);
    o.source = make_tar(name, members);
    o.cache_dir = (root / ("cache-" + name)).string();
    try {
      load_dataset(o);
      ADD_FAILURE() << "expected InputError";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("evil.bvh"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("cannot extract"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(files_matching(o.cache_dir, "extract-").empty());
    EXPECT_FALSE(has_temp_files(o.cache_dir));
    EXPECT_FALSE(fs::exists(fs::path(o.cache_dir) / "evil.bvh"));
  }
}

TEST(DatasetLoad, StaleTemporariesOfDeadProcessesAreRemoved) {
  const fs::path root = test::scratch_dir("dataset_stale_temps");
  write_corpus(root / "src");
  const fs::path archive = root / "clips.tar";
  const std::string cmd = "tar -cf '" + archive.string() + "' -C '" + (root / "src").string() + "' .";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  DatasetOptions o;
  o.source = archive.string();
  o.cache_dir = (root / "cache").string();
  o.use_cache = false;
  load_dataset(o);
  const auto extracted = files_matching(root / "cache", "extract-");
  ASSERT_EQ(extracted.size(), 1u);
  const std::string base = extracted[0].string();
  fs::remove_all(extracted[0]);

  // Process 999999999 cannot exist (beyond any pid_max); this test process does.
  const auto two_hours_ago = fs::file_time_type::clock::now() - std::chrono::hours(2);
  const fs::path dead_old = base + ".tmp-999999999-0";
  const fs::path dead_recent = base + ".tmp-999999999-1";
  const fs::path alive_old = base + ".tmp-" + std::to_string(::getpid()) + "-12345";
  for (const fs::path& p : {dead_old, dead_recent, alive_old}) write_text(p / "partial.bvh", "HIERARCHY");
  fs::last_write_time(dead_old, two_hours_ago);
  fs::last_write_time(alive_old, two_hours_ago);

  load_dataset(o);
  EXPECT_TRUE(fs::is_directory(extracted[0]));
  EXPECT_FALSE(fs::exists(dead_old));
  EXPECT_TRUE(fs::exists(dead_recent));
  EXPECT_TRUE(fs::exists(alive_old));
}

TEST(DatasetCache, HitEqualsFreshParse) {
  const fs::path root = test::scratch_dir("dataset_cache_hit");
  write_corpus(root / "src");
  const fs::path archive = root / "clips.tar.xz";
  const std::string cmd = "tar -cJf '" + archive.string() + "' -C '" + (root / "src").string() + "' .";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;

  DatasetOptions o;
  o.source = archive.string();
  o.cache_dir = (root / "cache").string();
  o.validation_percent = 50;
  const Dataset fresh = load_dataset(o);
  EXPECT_FALSE(fresh.from_cache);
  ASSERT_EQ(files_matching(root / "cache", "clips-", ".bin").size(), 1u);
  EXPECT_FALSE(has_temp_files(root / "cache"));

  // Remove the extraction: the second load must come from the cache alone.
  for (const fs::path& p : files_matching(root / "cache", "extract-")) fs::remove_all(p);
  const Dataset cached = load_dataset(o);
  EXPECT_TRUE(cached.from_cache);
  expect_same_dataset(fresh, cached);
  EXPECT_EQ(cached.skipped.size(), 3u);

  // The split is applied after the cache: another percentage, same cache file.
  o.validation_percent = 0;
  const Dataset all = load_dataset(o);
  EXPECT_TRUE(all.from_cache);
  EXPECT_EQ(all.train.size(), 4u);
  EXPECT_TRUE(all.validation.empty());

  // Other length units are another cache entry.
  o.units.length_scale = 0.02;
  const Dataset doubled = load_dataset(o);
  EXPECT_FALSE(doubled.from_cache);
  EXPECT_NEAR(doubled.train[0].motion.skeleton.offsets[1].y(), 2 * all.train[0].motion.skeleton.offsets[1].y(), 1e-9);
  EXPECT_EQ(files_matching(root / "cache", "clips-", ".bin").size(), 2u);
}

TEST(DatasetCache, FolderCacheMissesWhenAFileChanges) {
  const fs::path root = test::scratch_dir("dataset_cache_folder");
  write_corpus(root / "src");
  DatasetOptions o;
  o.source = (root / "src").string();
  o.cache_dir = (root / "cache").string();
  const Dataset first = load_dataset(o);
  EXPECT_FALSE(first.from_cache);
  const Dataset second = load_dataset(o);
  EXPECT_TRUE(second.from_cache);
  expect_same_dataset(first, second);

  // Replace clip_d with a longer motion: the key changes, the new data is parsed.
  write_clip(root / "src" / "b" / "sub" / "clip_d.bvh", test::random_motion(test::small_skeleton(), 77, 30.0, 4));
  fs::last_write_time(root / "src" / "b" / "sub" / "clip_d.bvh",
                      fs::last_write_time(root / "src" / "a" / "clip_a.bvh") + std::chrono::hours(1));
  const Dataset third = load_dataset(o);
  EXPECT_FALSE(third.from_cache);
  int frames_d = -1;
  for (const auto* split : {&third.train, &third.validation})
    for (const Clip& c : *split)
      if (c.name == "clip_d.bvh") frames_d = c.motion.num_frames();
  EXPECT_EQ(frames_d, 77);
}

TEST(DatasetCache, CorruptedOrTruncatedCacheIsDetectedAndReplaced) {
  const fs::path root = test::scratch_dir("dataset_cache_corrupt");
  write_corpus(root / "src");
  DatasetOptions o;
  o.source = (root / "src").string();
  o.cache_dir = (root / "cache").string();
  const Dataset fresh = load_dataset(o);
  const auto bins = files_matching(root / "cache", "clips-", ".bin");
  ASSERT_EQ(bins.size(), 1u);
  const fs::path bin = bins[0];
  std::string good;
  {
    std::ifstream in(bin, std::ios::binary);
    good.assign(std::istreambuf_iterator<char>(in), {});
  }
  ASSERT_GT(good.size(), 1000u);
  EXPECT_NO_THROW(load_clips(bin.string()));

  struct Damage {
    const char* what;
    std::string bytes;
  };
  std::vector<Damage> damages;
  damages.push_back({"truncated", good.substr(0, good.size() / 2)});
  damages.push_back({"truncated by one byte", good.substr(0, good.size() - 1)});
  damages.push_back({"empty", ""});
  damages.push_back({"header only", good.substr(0, 20)});
  std::string flipped = good;
  flipped[good.size() / 2] ^= 0x10;
  damages.push_back({"one bit flipped", flipped});
  std::string version = good;
  version[8] ^= 0x7f;
  damages.push_back({"other version", version});
  std::string magic = good;
  magic[0] = 'X';
  damages.push_back({"bad magic", magic});
  damages.push_back({"extra bytes", good + "junk"});

  for (const Damage& d : damages) {
    SCOPED_TRACE(d.what);
    write_text(bin, d.bytes);
    EXPECT_THROW(load_clips(bin.string()), InputError);
    const Dataset again = load_dataset(o);
    EXPECT_FALSE(again.from_cache);
    expect_same_dataset(fresh, again);
    // The cache was rewritten and is valid again.
    EXPECT_EQ(fs::file_size(bin), good.size());
    EXPECT_NO_THROW(load_clips(bin.string()));
    EXPECT_TRUE(load_dataset(o).from_cache);
  }
  EXPECT_FALSE(has_temp_files(root / "cache"));
}

TEST(DatasetCache, SaveLoadClipsRoundTrip) {
  const fs::path root = test::scratch_dir("dataset_save_load");
  const Skeleton skel = test::small_skeleton();
  std::vector<Clip> clips = {{"one.bvh", test::random_motion(skel, 33, 30.0, 11)},
                             {"two.bvh", test::random_motion(skel, 5, 24.0, 12)}};
  clips[1].motion.skeleton.offsets[0] = Eigen::Vector3d(1.5, -2.0, 0.25);
  const std::string path = (root / "clips.bin").string();
  save_clips(path, clips);
  expect_same_clips(clips, load_clips(path));

  save_clips(path, {});
  EXPECT_TRUE(load_clips(path).empty());

  EXPECT_THROW(save_clips((root / "no" / "such" / "dir" / "clips.bin").string(), clips), InputError);
  EXPECT_THROW(load_clips((root / "missing.bin").string()), InputError);
  EXPECT_FALSE(has_temp_files(root));
}

std::vector<Clip> clips_of_lengths(const std::vector<int>& lengths) {
  std::vector<Clip> clips;
  for (int n : lengths) clips.push_back({"c" + std::to_string(n), Motion::identity(test::small_skeleton(), n, 30.0)});
  return clips;
}

std::vector<std::vector<int>> as_rows(const std::vector<Window>& w) {
  std::vector<std::vector<int>> rows;
  for (const Window& x : w) rows.push_back({x.clip, x.start, x.length});
  return rows;
}

TEST(DatasetWindows, LongAndShortClips) {
  const auto clips = clips_of_lengths({300, 100, 128});
  // 300 frames, 128 every 64: starts 0, 64, 128 (192 + 128 > 300).
  EXPECT_EQ(as_rows(make_windows(clips, 128, 64, true)),
            (std::vector<std::vector<int>>{{0, 0, 128}, {0, 64, 128}, {0, 128, 128}, {1, 0, 100}, {2, 0, 128}}));
  EXPECT_EQ(as_rows(make_windows(clips, 128, 64, false)),
            (std::vector<std::vector<int>>{{0, 0, 128}, {0, 64, 128}, {0, 128, 128}, {2, 0, 128}}));
  // Non-overlapping windows drop the trailing remainder.
  EXPECT_EQ(as_rows(make_windows(clips, 128, 128, false)),
            (std::vector<std::vector<int>>{{0, 0, 128}, {0, 128, 128}, {2, 0, 128}}));
  EXPECT_EQ(make_windows(clips, 1, 1, false).size(), 528u);
  EXPECT_TRUE(make_windows({}, 128, 64, true).empty());
  EXPECT_THROW(make_windows(clips, 0, 64, true), InputError);
  EXPECT_THROW(make_windows(clips, 128, 0, true), InputError);
}

class EnvVar {
 public:
  EnvVar(const char* name, const char* value) : name_(name) {
    const char* old = std::getenv(name);
    if (old) old_ = old, had_ = true;
    if (value)
      setenv(name, value, 1);
    else
      unsetenv(name);
  }
  ~EnvVar() {
    if (had_)
      setenv(name_.c_str(), old_.c_str(), 1);
    else
      unsetenv(name_.c_str());
  }

 private:
  std::string name_, old_;
  bool had_ = false;
};

TEST(DatasetDefaults, BuildTimePathsAndEnvironmentOverrides) {
  {
    EnvVar a("MF_TRAIN_ARCHIVE", nullptr), c("MF_CACHE_DIR", nullptr);
    const std::string archive = default_train_archive();
    EXPECT_EQ(fs::path(archive).filename(), "train.tar.xz");
    EXPECT_EQ(fs::path(archive).parent_path().filename(), "bandai-namco");
    EXPECT_EQ(archive.find(".."), std::string::npos) << archive;  // normalised
    EXPECT_EQ(fs::path(default_cache_dir()), fs::path(MF_SOURCE_DIR).lexically_normal() / ".cache");
  }
  {
    EnvVar a("MF_TRAIN_ARCHIVE", "/data/x.tar.gz"), c("MF_CACHE_DIR", "/tmp/mfcache");
    EXPECT_EQ(default_train_archive(), "/data/x.tar.gz");
    EXPECT_EQ(default_cache_dir(), "/tmp/mfcache");
  }
  {
    EnvVar a("MF_TRAIN_ARCHIVE", ""), c("MF_CACHE_DIR", "");  // empty means unset
    EXPECT_EQ(fs::path(default_train_archive()).filename(), "train.tar.xz");
    EXPECT_EQ(fs::path(default_cache_dir()).filename(), ".cache");
  }
}

}  // namespace
}  // namespace mf
