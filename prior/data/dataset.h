// The data pipeline: BVH clips from a folder or a .tar/.tar.xz/.tar.gz archive,
// parsed into mf::Motion, split deterministically into training and validation
// by file, cut into windows, with a binary cache so that a second load is fast.
//
// Sources. A folder is searched recursively for files ending in ".bvh" (any
// case); an archive is a file ending in .tar, .tar.xz, .txz, .tar.gz or .tgz,
// extracted with libarchive (prior/data/tar_archive.h: regular files only; an
// entry with an absolute path or a ".." component fails the load). Clips are
// always processed in the order of their path (relative to the folder or
// archive root, compared bytewise), so every result below is independent of
// the file system's listing order and of the number of parsing threads.
//
// Split: a clip goes to validation when FNV-1a-64(file base name) % 100 <
// validation_percent (default 10). It depends only on the file name, so it is
// the same on every machine, for every subset of files and in every order.
//
// Skeleton check: the reference is the skeleton of the first clip (by path)
// that parses. A clip is skipped when its joint names or parents differ from the
// reference, or when a non-root offset differs by more than 1 mm (the root's
// offset is not compared: the root's per-frame translation replaces it). Clips
// within the tolerance keep their own offsets.
//
// Nothing extracted or cached is ever written inside the source tree: archives
// are extracted into `<cache_dir>/extract-<key>/` (through a temporary folder
// renamed once the whole archive was read, so an interrupted extraction is
// never taken for a complete one) and the parsed clips are stored in
// `<cache_dir>/clips-<key>.bin` (written to a temporary file and renamed).
// For an archive, key = hex FNV-1a-64 of (absolute path, size, modification
// time, cache format version); for a folder it covers the folder's absolute path
// and the relative path, size and modification time of every clip. The clips
// key also covers the length units. Touching or replacing the source therefore
// misses the old cache; old extractions and clips files are never deleted
// automatically (temporaries left by a killed process are, once they are more
// than an hour old). Several processes may load the same source at once.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "prior/motion/motion.h"
#include "prior/motion/motion_bvh.h"
#include "prior/util/binary_io.h"  // fnv1a64, the split's hash

namespace mf {

struct Clip {
  std::string name;    ///< file base name, e.g. "dataset-1_walk_normal_001.bvh"
  Motion motion;       ///< metres, as read by motion_from_bvh
};

struct DatasetOptions {
  std::string source;              ///< a folder (searched recursively for *.bvh) or an archive
  /// Where to extract and cache. Required for archives (extraction needs it even
  /// when use_cache is false); for folders, empty means no cache.
  std::string cache_dir;
  int validation_percent = 10;     ///< 0..100
  BvhUnits units;
  /// Read and write `<cache_dir>/clips-<key>.bin`. A cache file that is
  /// truncated or corrupted is ignored, the clips are parsed again and the file
  /// is rewritten. Failing to write the cache is not an error (a warning on stderr).
  bool use_cache = true;
  int threads = 2;                 ///< parsing threads; <= 0 means one per hardware thread
  bool verbose = false;            ///< progress lines on stderr
};

struct Dataset {
  Skeleton skeleton;               ///< the skeleton every clip shares (the reference clip's)
  std::vector<Clip> train;         ///< in path order
  std::vector<Clip> validation;    ///< in path order
  std::vector<std::string> skipped;  ///< "name: reason" for clips that failed to parse or did not match
  bool from_cache = false;         ///< true when the clips came from the binary cache
};

/// True when `name` (a base name) belongs to the validation split.
bool is_validation_clip(const std::string& name, int validation_percent);

/// Loads every clip (see the top of this file). Throws mf::InputError if the
/// source does not exist or is neither a folder nor a supported archive, if the
/// archive cannot be extracted, if an archive is given without cache_dir, if
/// validation_percent is outside 0..100, or if no clip is usable (the message
/// then quotes the first reasons).
Dataset load_dataset(const DatasetOptions& options);

/// A BVH file of a source: its path relative to the source's root
/// ('/'-separated) and where it can be read.
struct SourceBvhFile {
  std::string relative;
  std::string path;
};

/// The BVH files of `source` (a folder searched recursively, or an archive
/// extracted into `cache_dir` as load_dataset() does), sorted by relative
/// path. For readers of clips that are not on one rig (the foreign capture of
/// the benchmark); the errors are load_dataset()'s.
std::vector<SourceBvhFile> list_source_bvh_files(const std::string& source, const std::string& cache_dir,
                                                 bool verbose);

/// The default location of the shared training archive relative to the project
/// root, and the default cache directory (`<project>/.cache`), as configured at
/// build time; both can be overridden by the environment variables
/// MF_TRAIN_ARCHIVE and MF_CACHE_DIR (when set and non-empty).
std::string default_train_archive();
std::string default_cache_dir();
/// The shared archive of real capture on other rigs (`foreign/foreign.tar.xz`
/// of the shared data; MF_FOREIGN_ARCHIVE overrides it).
std::string default_foreign_archive();

/// A window of a clip: frames [start, start + length) of clips[clip]. When the
/// clip is shorter than the requested window length, the window is the whole
/// clip and `length` is the clip's length (callers pad and mask).
struct Window {
  int clip = 0;
  int start = 0;
  int length = 0;
};

/// Windows of `length` frames every `stride` frames over each clip: starts 0,
/// stride, 2 stride, ... as long as the window fits (a trailing remainder
/// shorter than `length` is dropped). Clips shorter than `length` give one
/// window of their full length when `keep_short` is true and none otherwise.
/// Ordered by clip, then start. Throws mf::InputError unless length >= 1 and
/// stride >= 1.
std::vector<Window> make_windows(const std::vector<Clip>& clips, int length, int stride, bool keep_short);

/// Binary serialisation of clips (used by the cache; exposed for tests). The
/// file holds a magic, a format version, the payload size and a checksum, then
/// per clip its name, fps, skeleton, rotations and root positions as doubles in
/// the machine's byte order (a cache is not meant to move between machines).
/// save_clips writes through a temporary file and a rename; throws
/// mf::InputError if the file cannot be written.
void save_clips(const std::string& path, const std::vector<Clip>& clips);
/// Throws mf::InputError if the file cannot be read, is not a clips file, has
/// another format version, is truncated or fails its checksum, or holds an
/// invalid skeleton or motion.
std::vector<Clip> load_clips(const std::string& path);

}  // namespace mf
