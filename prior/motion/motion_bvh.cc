#include "prior/motion/motion_bvh.h"

#include <cmath>

#include "prior/motion/rotations.h"

namespace mf {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegrees = 180.0 / kPi;
// A translation or rotation the layout has no channel for must be this close to
// what the layout implies (metres, radians).
constexpr double kRepresentTolerance = 1e-6;

// Where a joint's channels sit in a frame's row of values.
struct ChannelSlots {
  int position[3] = {-1, -1, -1};  // row index of the X, Y, Z position channel, or -1
  int rotation[3] = {-1, -1, -1};  // row indices of the rotation channels, in file order
  EulerOrder order{};
  bool has_position() const { return position[0] >= 0 || position[1] >= 0 || position[2] >= 0; }
  bool has_rotation() const { return rotation[0] >= 0; }
};

std::vector<ChannelSlots> channel_slots(const BvhDocument& doc) {
  std::vector<ChannelSlots> slots(doc.joints.size());
  int index = 0;
  for (size_t j = 0; j < doc.joints.size(); ++j) {
    int rotations = 0;
    for (BvhChannel c : doc.joints[j].channels) {
      const int code = static_cast<int>(c);  // Xposition..Zposition, then Xrotation..Zrotation
      if (code < 3) {
        slots[j].position[code] = index;
      } else {
        if (rotations < 3) {
          slots[j].rotation[rotations] = index;
          slots[j].order[rotations] = static_cast<Axis>(code - 3);
        }
        ++rotations;
      }
      ++index;
    }
    if (rotations != 0 && rotations != 3)
      throw InputError("BVH joint '" + doc.joints[j].name + "' has " + std::to_string(rotations) +
                       " rotation channels; 0 or 3 distinct axes are supported");
  }
  return slots;
}

// The single child of a container root (see motion_bvh.h), or -1.
int container_child(const BvhDocument& doc, const std::vector<ChannelSlots>& slots) {
  int child = -1, count = 0;
  for (size_t j = 1; j < doc.joints.size(); ++j) {
    if (doc.joints[j].parent == 0) {
      child = static_cast<int>(j);
      ++count;
    }
  }
  return count == 1 && slots[child].has_position() ? child : -1;
}

// Local translation of joint j in frame f, file units: the offset with
// position channels replacing its components.
Eigen::Vector3d local_translation(const BvhDocument& doc, const ChannelSlots& slots, int j, int f) {
  Eigen::Vector3d t = doc.joints[j].offset;
  const double* row = doc.values.data() + static_cast<size_t>(f) * doc.num_channels();
  for (int k = 0; k < 3; ++k)
    if (slots.position[k] >= 0) t[k] = row[slots.position[k]];
  return t;
}

Eigen::Quaterniond local_rotation(const BvhDocument& doc, const ChannelSlots& slots, int f) {
  if (!slots.has_rotation()) return Eigen::Quaterniond::Identity();
  const double* row = doc.values.data() + static_cast<size_t>(f) * doc.num_channels();
  const Eigen::Vector3d degrees(row[slots.rotation[0]], row[slots.rotation[1]], row[slots.rotation[2]]);
  return quat_from_euler(degrees / kDegrees, slots.order);
}

// BVH frame times are usually written with 6 or 7 digits (0.0333333); an fps
// within 1e-5 relative of an integer is taken to be that integer.
double fps_from_frame_time(double frame_time) {
  const double fps = 1.0 / frame_time;
  const double rounded = std::round(fps);
  return rounded > 0 && std::abs(fps - rounded) <= 1e-5 * fps ? rounded : fps;
}

// Flips quaternion signs so that each agrees with the previous frame (frame 0: w >= 0).
void make_signs_continuous(Motion& m) {
  for (int f = 0; f < m.num_frames(); ++f) {
    for (int j = 0; j < m.num_joints(); ++j) {
      Eigen::Quaterniond& q = m.rotation(f, j);
      const double agreement = f == 0 ? q.w() : q.coeffs().dot(m.rotation(f - 1, j).coeffs());
      if (agreement < 0) q.coeffs() = -q.coeffs();
    }
  }
}

Skeleton skeleton_from_bvh(const BvhDocument& doc, const std::vector<ChannelSlots>& slots, int first, double scale) {
  Skeleton s;
  for (int j = first; j < static_cast<int>(doc.joints.size()); ++j) {
    s.names.push_back(doc.joints[j].name);
    s.parents.push_back(j == first ? -1 : doc.joints[j].parent - first);
    // Unused by FK for the root: its rest position (with the container's offset).
    Eigen::Vector3d offset = j == first ? doc.joints[j].offset : local_translation(doc, slots[j], j, 0);
    if (j == first && first > 0) offset += doc.joints[0].offset;
    s.offsets.push_back(offset * scale);
  }
  return s;
}

// ---------------------------------------------------------------------------
// Writing

// For each motion joint, the index of the layout joint with the same name.
// Throws unless names and parents correspond one to one.
std::vector<int> match_layout(const Skeleton& skeleton, const BvhDocument& layout, int first) {
  const int J = skeleton.num_joints();
  const int layout_joints = static_cast<int>(layout.joints.size()) - first;
  if (layout_joints != J)
    throw InputError("skeleton has " + std::to_string(J) + " joints but the BVH layout has " +
                     std::to_string(layout_joints) + (first > 0 ? " (not counting its container root)" : ""));
  std::vector<int> index(J);
  for (int j = 0; j < J; ++j) {
    index[j] = layout.find(skeleton.names[j]);
    if (index[j] < first) throw InputError("joint '" + skeleton.names[j] + "' is not in the BVH layout");
  }
  if (index[0] != first)
    throw InputError("the skeleton's root '" + skeleton.names[0] + "' is not the root of the BVH layout");
  for (int j = 1; j < J; ++j)
    if (layout.joints[index[j]].parent != index[skeleton.parents[j]])
      throw InputError("joint '" + skeleton.names[j] + "' has parent '" + skeleton.names[skeleton.parents[j]] +
                       "' in the skeleton but '" + layout.joints[layout.joints[index[j]].parent].name +
                       "' in the BVH layout");
  return index;
}

void write_translation(double* row, const ChannelSlots& slots, const BvhJoint& joint, const Eigen::Vector3d& t,
                       double scale) {
  for (int k = 0; k < 3; ++k) {
    if (slots.position[k] >= 0) {
      row[slots.position[k]] = t[k];
    } else if (std::abs(t[k] - joint.offset[k]) * scale > kRepresentTolerance) {
      throw InputError("BVH layout joint '" + joint.name + "' has no " + "XYZ"[k] +
                       "position channel, but the motion moves it along that axis");
    }
  }
}

class BvhWriter {
 public:
  BvhWriter(const Motion& motion, const BvhDocument& layout, double scale)
      : motion_(motion), doc_(layout), slots_(channel_slots(layout)), scale_(scale) {
    container_ = container_child(layout, slots_);
    index_ = match_layout(motion.skeleton, layout, container_ >= 0 ? 1 : 0);
    previous_angles_.assign(motion.num_joints(), Eigen::Vector3d::Zero());
  }

  BvhDocument write() {
    for (int j = 1; j < motion_.num_joints(); ++j) doc_.joints[index_[j]].offset = motion_.skeleton.offsets[j] / scale_;
    doc_.num_frames = motion_.num_frames();
    doc_.frame_time = 1.0 / motion_.fps;
    doc_.values.assign(static_cast<size_t>(doc_.num_frames) * doc_.num_channels(), 0.0);
    for (int f = 0; f < motion_.num_frames(); ++f) write_frame(f);
    return std::move(doc_);
  }

 private:
  void write_frame(int f) {
    double* row = doc_.values.data() + static_cast<size_t>(f) * doc_.num_channels();
    Eigen::Vector3d root = motion_.root_positions[f] / scale_;
    if (container_ >= 0) {
      // The container stays at its offset with no rotation; its child carries the rest.
      write_translation(row, slots_[0], doc_.joints[0], doc_.joints[0].offset, scale_);
      root -= doc_.joints[0].offset;
    }
    write_translation(row, slots_[index_[0]], doc_.joints[index_[0]], root, scale_);
    for (int j = 0; j < motion_.num_joints(); ++j) {
      const int b = index_[j];
      if (j > 0) write_translation(row, slots_[b], doc_.joints[b], doc_.joints[b].offset, scale_);
      write_rotation(row, j, f);
    }
  }

  void write_rotation(double* row, int j, int f) {
    const ChannelSlots& slots = slots_[index_[j]];
    const Eigen::Quaterniond& q = motion_.rotation(f, j);
    if (!slots.has_rotation()) {
      if (geodesic_angle(q, Eigen::Quaterniond::Identity()) > kRepresentTolerance)
        throw InputError("BVH layout joint '" + motion_.skeleton.names[j] +
                         "' has no rotation channels, but the motion rotates it");
      return;
    }
    const Eigen::Vector3d angles =
        f == 0 ? euler_from_quat(q, slots.order) : euler_from_quat_near(q, slots.order, previous_angles_[j]);
    previous_angles_[j] = angles;
    for (int k = 0; k < 3; ++k) row[slots.rotation[k]] = angles[k] * kDegrees;
  }

  const Motion& motion_;
  BvhDocument doc_;
  std::vector<ChannelSlots> slots_;
  double scale_;
  int container_ = -1;
  std::vector<int> index_;
  std::vector<Eigen::Vector3d> previous_angles_;
};

void check_units(const BvhUnits& units) {
  if (!(std::isfinite(units.length_scale) && units.length_scale > 0))
    throw InputError("BVH length scale must be positive and finite");
}

void add_layout_joint(const Skeleton& s, const std::vector<std::vector<int>>& children, int j, int parent, double scale,
                      BvhDocument& doc) {
  BvhJoint joint;
  joint.name = s.names[j];
  joint.parent = parent;
  joint.offset = s.offsets[j] / scale;
  using C = BvhChannel;
  if (parent < 0) joint.channels = {C::Xposition, C::Yposition, C::Zposition};
  for (C c : {C::Zrotation, C::Xrotation, C::Yrotation}) joint.channels.push_back(c);
  if (children[j].empty()) {
    joint.has_end_site = true;
    const Eigen::Vector3d own = s.offsets[j];
    joint.end_site = (own.norm() > 1e-9 ? Eigen::Vector3d(0.25 * own) : Eigen::Vector3d(0, 0.05, 0)) / scale;
  }
  const int index = static_cast<int>(doc.joints.size());
  doc.joints.push_back(std::move(joint));
  for (int child : children[j]) add_layout_joint(s, children, child, index, scale, doc);
}

}  // namespace

Motion motion_from_bvh(const BvhDocument& doc, const BvhUnits& units) {
  check_units(units);
  doc.validate();
  if (doc.num_frames < 1) throw InputError("BVH document has no frames");
  if (!(doc.frame_time > 0)) throw InputError("BVH frame time must be positive");
  const std::vector<ChannelSlots> slots = channel_slots(doc);
  const int container = container_child(doc, slots);
  const int first = container >= 0 ? 1 : 0;
  const double scale = units.length_scale;

  Motion m = Motion::identity(skeleton_from_bvh(doc, slots, first, scale), doc.num_frames,
                              fps_from_frame_time(doc.frame_time));
  for (int f = 0; f < doc.num_frames; ++f) {
    for (int j = first; j < static_cast<int>(doc.joints.size()); ++j)
      m.rotation(f, j - first) = local_rotation(doc, slots[j], f);
    const Eigen::Vector3d root = local_translation(doc, slots[first], first, f) * scale;
    if (first == 0) {
      m.root_positions[f] = root;
    } else {
      const Eigen::Quaterniond container_rotation = local_rotation(doc, slots[0], f);
      m.root_positions[f] = local_translation(doc, slots[0], 0, f) * scale + container_rotation * root;
      m.rotation(f, 0) = (container_rotation * m.rotation(f, 0)).normalized();
    }
  }
  make_signs_continuous(m);
  return m;
}

BvhDocument motion_to_bvh(const Motion& motion, const BvhDocument& layout, const BvhUnits& units) {
  check_units(units);
  motion.validate();
  layout.validate();
  return BvhWriter(motion, layout, units.length_scale).write();
}

BvhDocument default_bvh_layout(const Skeleton& skeleton, const BvhUnits& units) {
  check_units(units);
  skeleton.validate();
  BvhDocument doc;
  add_layout_joint(skeleton, skeleton.children(), 0, -1, units.length_scale, doc);
  return doc;
}

Motion read_motion(const std::string& path, BvhDocument* layout_out, const BvhUnits& units) {
  BvhDocument doc = read_bvh_file(path);
  Motion motion;
  try {
    motion = motion_from_bvh(doc, units);
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
  if (layout_out) *layout_out = std::move(doc);
  return motion;
}

void write_motion(const std::string& path, const Motion& motion, const BvhDocument& layout, const BvhUnits& units) {
  write_bvh_file(path, motion_to_bvh(motion, layout, units));
}

}  // namespace mf
