// BVH reading and writing at the level of the file: hierarchy, channels and the
// raw channel values, in the file's own units (usually centimetres) and degrees.
// Conversion to and from mf::Motion (metres, quaternions) is in motion_bvh.h.
//
// Reader guarantees: any channel order per joint, position channels on any
// joint, End Sites, any frame time; numbers parsed independently of the C/C++
// locale. Every malformed input throws mf::BvhError whose message starts with
// "<source>:<line>: " (truncated files, wrong channel counts, bad or non-finite
// numbers, missing MOTION, zero frames, a frame count that disagrees with the
// data, unknown keywords, nesting deeper than kBvhMaxDepth, counts beyond the limits
// below). It never crashes and never allocates more than the input justifies.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "prior/motion/errors.h"

namespace mf {

class BvhError : public InputError {
 public:
  explicit BvhError(const std::string& message) : InputError(message) {}
};

enum class BvhChannel { Xposition, Yposition, Zposition, Xrotation, Yrotation, Zrotation };

const char* to_string(BvhChannel c);

struct BvhJoint {
  std::string name;
  int parent = -1;                    ///< index into BvhDocument::joints, -1 for the root
  Eigen::Vector3d offset{0, 0, 0};    ///< file units
  std::vector<BvhChannel> channels;   ///< 0 to 6 channels in file order
  bool has_end_site = false;
  Eigen::Vector3d end_site{0, 0, 0};  ///< End Site offset, file units
};

struct BvhDocument {
  std::vector<BvhJoint> joints;       ///< depth-first file order; parents before children
  int num_frames = 0;
  double frame_time = 0.0;            ///< seconds
  /// Channel values, frame-major: values[f * num_channels() + c], in the order
  /// the joints and their channels appear in the file; degrees for rotations.
  std::vector<double> values;

  int num_channels() const;
  /// Index of the first channel of joint j in a frame's row.
  int channel_offset(int joint) const;
  /// Index of the joint named `name`, or -1.
  int find(const std::string& name) const;

  /// Throws mf::InputError unless the document is one that format_bvh can write
  /// and parse_bvh reads back: at least one and at most kBvhMaxJoints joints;
  /// joint 0 the only root; joints in depth-first order (each parent is joint
  /// j-1 or one of its ancestors) and nested at most kBvhMaxDepth deep; names
  /// unique, non-empty, without whitespace or braces; at most 6 distinct channels
  /// per joint; finite offsets; num_frames >= 0, frame_time finite and >= 0;
  /// values.size() == num_frames * num_channels(), all finite.
  void validate() const;
};

constexpr int kBvhMaxDepth = 64;
constexpr int kBvhMaxJoints = 1024;
constexpr long long kBvhMaxFrames = 10'000'000;
constexpr long long kBvhMaxValues = 200'000'000;

/// Parses BVH text. `source` names the input in error messages (a path).
/// Accepted syntax: whitespace-separated tokens (spaces, tabs, LF or CRLF line
/// ends, an optional UTF-8 byte order mark); braces may touch other tokens.
/// Inside a joint, OFFSET (required), CHANNELS (optional, 0 to 6 distinct names,
/// case-insensitive), JOINT and one End Site may come in any order. The motion
/// section is "MOTION Frames: N Frame Time: T" followed by exactly N times
/// num_channels() numbers (line breaks between them are not checked). N must be
/// at least 1, T positive, and the hierarchy must have at least one channel.
/// Joint names are single tokens and must be unique; only one ROOT is allowed.
/// Numbers too small for a double read as 0.
BvhDocument parse_bvh(const std::string& text, const std::string& source);
/// Reads (at most kMaxBvhFileBytes, prior/util/binary_io.h) and parses a file;
/// throws FileError ("cannot open BVH file <path>: <reason>") if it cannot be
/// read, BvhError if it does not parse.
BvhDocument read_bvh_file(const std::string& path);

/// Writes BVH text: tabs for indentation, values with 9 significant digits
/// (locale-independent), so a read of the output gives back every channel within
/// 1e-8 relative. Each joint's block lists OFFSET, CHANNELS, child joints, then its
/// End Site. Throws mf::InputError if validate() fails, num_frames < 1 or
/// frame_time <= 0 (the reader would reject the output).
std::string format_bvh(const BvhDocument& doc);
/// Writes to `path` with write_file_atomically (prior/util/file_writer.h: a
/// temporary file and a rename, or in place for devices and FIFOs); throws
/// FileError "cannot write <path>: <reason>" on I/O failure.
void write_bvh_file(const std::string& path, const BvhDocument& doc);

}  // namespace mf
