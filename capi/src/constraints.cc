// Constraints beyond whole-pose keys (tasks/constraints/constraint_spec.h) and mf_solve
// with its alternatives and reports (tasks/methods/jobs.h run_constrained); the
// solution handle mf_transition shares.
#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "capi/src/capi_internal.h"
#include "prior/util/binary_io.h"
#include "tasks/constraints/constraint_spec.h"
#include "tasks/constraints/trajectory_csv.h"
#include "tasks/methods/jobs.h"

namespace mf::capi {
namespace {

int32_t frame_arg(int32_t frame, const char* what) {
  if (frame < 0) throw ApiError(MF_ERROR_INVALID_ARGUMENT, std::string(what) + " " + std::to_string(frame) + " is negative");
  return frame;
}

const mf_solution& checked(const mf_solution* s, int32_t index) {
  require(s, "solution");
  if (index < 0 || index >= static_cast<int32_t>(s->motions.size()))
    throw ApiError(MF_ERROR_INVALID_ARGUMENT, "solution index " + std::to_string(index) + " is out of range (the solution has " +
                                                  std::to_string(s->motions.size()) + ")");
  return *s;
}

nlohmann::json report_json(const ConstraintReport& r, double cm_to_unit, int index) {
  return {{"index", index},
          {"keys",
           {{"rotations", r.keys.rotations},
            {"rotation_max_deg", r.keys.rotation_max_deg},
            {"rotation_mean_deg", r.keys.rotation_mean_deg},
            {"roots", r.keys.roots},
            {"root_max", r.keys.root_max_cm * cm_to_unit},
            {"root_mean", r.keys.root_mean_cm * cm_to_unit}}},
          {"targets", {{"count", r.targets.count}, {"max", r.targets.max_cm * cm_to_unit}, {"mean", r.targets.mean_cm * cm_to_unit}}},
          {"contacts",
           {{"frames", r.contacts.frames}, {"max", r.contacts.max_cm * cm_to_unit}, {"mean", r.contacts.mean_cm * cm_to_unit}}}};
}

// The report JSON of one solution: report_json() plus the trajectory's when
// the constraints have one (so reports without one keep their old bytes).
nlohmann::json solution_report_json(const ConstraintReport& r, double cm_to_unit, int index, bool trajectory) {
  nlohmann::json j = report_json(r, cm_to_unit, index);
  if (trajectory)
    j["trajectory"] = {{"rows", r.trajectory.rows},
                       {"max", r.trajectory.max_cm * cm_to_unit},
                       {"mean", r.trajectory.mean_cm * cm_to_unit},
                       {"facing_max_deg", r.trajectory.facing_max_deg},
                       {"facing_mean_deg", r.trajectory.facing_mean_deg}};
  return j;
}

}  // namespace

std::unique_ptr<mf_solution> new_solution(ConstrainedResult&& r, const mf_motion& like, bool trajectory) {
  auto s = std::make_unique<mf_solution>();
  for (Motion& m : r.motions) {
    std::unique_ptr<mf_motion> h(derived_motion(std::move(m), like));
    for (const std::string& w : r.warnings) h->warnings += (h->warnings.empty() ? "" : "\n") + w;
    s->motions.push_back(std::move(h));
  }
  s->reports = std::move(r.reports);
  s->warnings = std::move(r.warnings);
  s->length_scale = like.length_scale;
  s->unit = like.unit;
  s->trajectory = trajectory;
  for (const Method& m : registered_methods())
    if (m.name == r.method) s->method = m.name.c_str();
  return s;
}

}  // namespace mf::capi

using mf::capi::ApiError;
using mf::capi::guard;
using mf::capi::require;

extern "C" {

int mf_constraints_create(mf_constraints** out) {
  return guard([&] {
    require(out, "out");
    *out = new mf_constraints();
  });
}

int mf_constraints_parse_json(const char* json, size_t length, mf_constraints** out) {
  return guard([&] {
    require(out, "out");
    if (!json && length != 0) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "json is NULL");
    auto c = std::make_unique<mf_constraints>();
    c->spec = mf::ConstraintSpec::parse_json(std::string(json ? json : "", length));
    *out = c.release();
  });
}

int mf_constraints_load_json(const char* path, mf_constraints** out) {
  return guard([&] {
    require(path, "path");
    require(out, "out");
    const std::string text = mf::read_file_limited(path, "constraints file", mf::kMaxConstraintsFileBytes);
    auto c = std::make_unique<mf_constraints>();
    c->spec = mf::ConstraintSpec::parse_json(text, path);
    *out = c.release();
  });
}

void mf_constraints_destroy(mf_constraints* constraints) { delete constraints; }

int mf_constraints_add_pose_keys(mf_constraints* constraints, const int32_t* frames, size_t count) {
  return guard([&] {
    require(constraints, "constraints");
    if (!frames && count != 0) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "frames is NULL");
    std::vector<int> f;
    for (size_t i = 0; i < count; ++i) f.push_back(mf::capi::frame_arg(frames[i], "key frame"));
    constraints->spec.add_whole_pose_keys(f);
  });
}

int mf_constraints_add_partial_key(mf_constraints* constraints, int32_t frame, const char* const* joints,
                                   size_t joint_count, uint32_t root) {
  return guard([&] {
    require(constraints, "constraints");
    if (!joints && joint_count != 0) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "joints is NULL");
    if (root & ~(MF_ROOT_POSITION | MF_ROOT_ROTATION))
      throw ApiError(MF_ERROR_INVALID_ARGUMENT, "root holds unknown flags (MF_ROOT_POSITION, MF_ROOT_ROTATION)");
    mf::KeySpec k;
    k.frame = mf::capi::frame_arg(frame, "key frame");
    k.whole = false;
    for (size_t i = 0; i < joint_count; ++i) {
      require(joints[i], "a joint name");
      k.joints.push_back(joints[i]);
    }
    k.root_position = (root & MF_ROOT_POSITION) != 0;
    k.root_rotation = (root & MF_ROOT_ROTATION) != 0;
    if (k.joints.empty() && root == 0)
      throw ApiError(MF_ERROR_INVALID_ARGUMENT, "the key at frame " + std::to_string(frame) + " constrains nothing");
    constraints->spec.keys.push_back(k);
  });
}

int mf_constraints_add_target(mf_constraints* constraints, int32_t frame, const char* joint, const float position[3],
                              float weight) {
  return guard([&] {
    require(constraints, "constraints");
    require(joint, "joint");
    require(position, "position");
    mf::TargetSpec t;
    t.frame = mf::capi::frame_arg(frame, "target frame");
    t.joint = joint;
    t.position = Eigen::Vector3d(position[0], position[1], position[2]);
    if (!t.position.allFinite()) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "the target position is not finite");
    if (!(std::isfinite(weight) && weight >= 0))
      throw ApiError(MF_ERROR_INVALID_ARGUMENT, "the target weight must be finite and non-negative");
    t.weight = weight;
    constraints->spec.targets.push_back(t);
  });
}

int mf_constraints_add_contact(mf_constraints* constraints, const char* joint, int32_t first, int32_t last) {
  return guard([&] {
    require(constraints, "constraints");
    require(joint, "joint");
    mf::ContactSpec c;
    c.joint = joint;
    c.first = mf::capi::frame_arg(first, "contact first frame");
    c.last = mf::capi::frame_arg(last, "contact last frame");
    if (c.first >= c.last)
      throw ApiError(MF_ERROR_INVALID_ARGUMENT, "a contact must span at least two frames (first < last)");
    constraints->spec.contacts.push_back(c);
  });
}

int mf_constraints_to_json(const mf_constraints* constraints, char* out, size_t capacity, size_t* needed) {
  return guard([&] {
    require(constraints, "constraints");
    mf::capi::write_string(constraints->spec.to_json(), out, capacity, needed);
  });
}

int mf_solve(const mf_model* model, const mf_motion* input, const mf_constraints* constraints, int32_t alternatives,
             const mf_task_options* options, mf_solution** out) {
  return guard([&] {
    require(input, "input");
    require(constraints, "constraints");
    require(out, "out");
    const mf_task_options o = mf::capi::read_options(options, "mf_task_options");
    const mf::TaskContext ctx = mf::capi::task_context(model, o);
    const mf::capi::TaskThreads threads;
    const mf::MotionConstraints c = constraints->spec.resolve(input->motion.skeleton, input->length_scale);
    mf::ConstrainedResult r =
        mf::run_constrained(input->motion, c, o.method ? std::string(o.method) : std::string(), alternatives, ctx);
    *out = mf::capi::new_solution(std::move(r), *input, !c.trajectory.empty()).release();
  });
}

void mf_solution_destroy(mf_solution* solution) { delete solution; }

int mf_solution_get_count(const mf_solution* solution, int32_t* out) {
  return guard([&] {
    require(solution, "solution");
    require(out, "out");
    *out = static_cast<int32_t>(solution->motions.size());
  });
}

int mf_solution_get_motion(const mf_solution* solution, int32_t index, mf_motion** out) {
  return guard([&] {
    const mf_solution& s = mf::capi::checked(solution, index);
    require(out, "out");
    *out = new mf_motion(*s.motions[static_cast<size_t>(index)]);
  });
}

int mf_constraint_report_init(mf_constraint_report* report) {
  return guard([&] {
    require(report, "report");
    std::memset(report, 0, sizeof *report);
    report->struct_size = sizeof *report;
  });
}

int mf_solution_get_report(const mf_solution* solution, int32_t index, mf_constraint_report* report) {
  return guard([&] {
    const mf_solution& s = mf::capi::checked(solution, index);
    require(report, "report");
    const uint32_t size = report->struct_size;
    if (size < sizeof(uint32_t) || size > 65536)
      throw ApiError(MF_ERROR_INVALID_ARGUMENT, "mf_constraint_report.struct_size is " + std::to_string(size) +
                                                    ": call mf_constraint_report_init() first");
    const mf::ConstraintReport& r = s.reports[static_cast<size_t>(index)];
    const double u = 0.01 / s.length_scale;  // cm -> input units
    mf_constraint_report full;
    std::memset(&full, 0, sizeof full);
    full.struct_size = size < sizeof full ? size : static_cast<uint32_t>(sizeof full);
    full.key_rotations = static_cast<int32_t>(r.keys.rotations);
    full.key_rotation_max_deg = r.keys.rotation_max_deg;
    full.key_rotation_mean_deg = r.keys.rotation_mean_deg;
    full.key_roots = static_cast<int32_t>(r.keys.roots);
    full.key_root_max = r.keys.root_max_cm * u;
    full.key_root_mean = r.keys.root_mean_cm * u;
    full.targets = static_cast<int32_t>(r.targets.count);
    full.target_max = r.targets.max_cm * u;
    full.target_mean = r.targets.mean_cm * u;
    full.contact_frames = static_cast<int32_t>(r.contacts.frames);
    full.contact_slide_max = r.contacts.max_cm * u;
    full.contact_slide_mean = r.contacts.mean_cm * u;
    full.trajectory_rows = static_cast<int32_t>(r.trajectory.rows);
    full.trajectory_max = r.trajectory.max_cm * u;
    full.trajectory_mean = r.trajectory.mean_cm * u;
    full.facing_max_deg = r.trajectory.facing_max_deg;
    full.facing_mean_deg = r.trajectory.facing_mean_deg;
    std::memcpy(report, &full, size < sizeof full ? size : sizeof full);
  });
}

int mf_solution_get_report_json(const mf_solution* solution, char* out, size_t capacity, size_t* needed) {
  return guard([&] {
    require(solution, "solution");
    nlohmann::json doc = {{"unit", solution->unit}, {"solutions", nlohmann::json::array()},
                          {"warnings", solution->warnings}};
    const double u = 0.01 / solution->length_scale;
    for (size_t i = 0; i < solution->reports.size(); ++i)
      doc["solutions"].push_back(
          mf::capi::solution_report_json(solution->reports[i], u, static_cast<int>(i), solution->trajectory));
    mf::capi::write_string(doc.dump(2, ' ', false, nlohmann::json::error_handler_t::replace), out, capacity, needed);
  });
}

int mf_constraints_add_trajectory(mf_constraints* constraints, const int32_t* frames, const float* rows, size_t count) {
  return guard([&] {
    require(constraints, "constraints");
    if ((!frames || !rows) && count != 0) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "frames or rows is NULL");
    std::vector<mf::TrajectoryPoint> add;
    for (size_t i = 0; i < count; ++i) {
      mf::TrajectoryPoint p;
      p.frame = mf::capi::frame_arg(frames[i], "trajectory frame");
      p.x = rows[4 * i];
      p.z = rows[4 * i + 1];
      p.forward_x = rows[4 * i + 2];
      p.forward_z = rows[4 * i + 3];
      const std::string what = "trajectory row " + std::to_string(i) + " (frame " + std::to_string(p.frame) + ")";
      if (!std::isfinite(p.x) || !std::isfinite(p.z) || !std::isfinite(p.forward_x) || !std::isfinite(p.forward_z))
        throw ApiError(MF_ERROR_INVALID_ARGUMENT, what + ": values must be finite");
      if (std::hypot(p.forward_x, p.forward_z) < 1e-6)
        throw ApiError(MF_ERROR_INVALID_ARGUMENT, what + ": the facing direction (forward_x, forward_z) has zero length");
      add.push_back(p);
    }
    constraints->spec.trajectory.insert(constraints->spec.trajectory.end(), add.begin(), add.end());
  });
}

int mf_constraints_load_trajectory_csv(mf_constraints* constraints, const char* path) {
  return guard([&] {
    require(constraints, "constraints");
    require(path, "path");
    const std::vector<mf::TrajectoryPoint> rows = mf::read_trajectory_csv(path);
    constraints->spec.trajectory.insert(constraints->spec.trajectory.end(), rows.begin(), rows.end());
  });
}

int mf_solution_get_method(const mf_solution* solution, const char** name) {
  return guard([&] {
    require(solution, "solution");
    require(name, "name");
    *name = solution->method;
  });
}

}  // extern "C"
