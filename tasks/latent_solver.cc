#include "tasks/latent_solver.h"

#include <ATen/ATen.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <sstream>

#include "prior/model/nemf.h"
#include "prior/motion/errors.h"
#include "prior/motion/rotations.h"
#include "tasks/latent_optimizer.h"
#include "tasks/residuals.h"
#include "tasks/windows.h"

namespace mf {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

int default_iterations(SolverMethod m) { return m == SolverMethod::Adam ? 600 : 40; }

// L-BFGS cap for one window when the options leave it open: 40, or 60 when
// the window has end-effector targets or 40+ frames in a row without a key
// (every task keeps improving up to 40 iterations, long gaps and effectors up to
// 60; docs/BENCHMARKS.md, "Iteration caps").
int window_iterations(const LatentSolverOptions& o, const MotionConstraints& wc, int T) {
  if (o.max_iterations > 0) return o.max_iterations;
  if (o.method == SolverMethod::Adam) return default_iterations(o.method);
  int longest = 0, previous = -1;
  for (const PoseKey& k : wc.keys) {
    longest = std::max(longest, k.frame - previous - 1);
    previous = k.frame;
  }
  longest = std::max(longest, T - previous - 1);
  return (!wc.effectors.empty() || longest >= 40) ? 60 : default_iterations(o.method);
}

// The energy of a window's problem as a function of the codes.
CodeEnergy window_energy(const NemfModel& model, const WindowProblem& problem, const EnergyWeights& weights) {
  return [&model, &problem, &weights](const at::Tensor& z_l, const at::Tensor& z_g) {
    return evaluate_energy(model, problem, weights, z_l, z_g);
  };
}

void measure_effectors(const Motion& motion, const MotionConstraints& c, EffectorError* e) {
  *e = EffectorError{};
  if (c.effectors.empty()) return;
  GlobalPose pose = forward_kinematics(motion);
  double sum = 0.0;
  for (const EffectorTarget& t : c.effectors) {
    const double d = (pose.position(t.frame, t.joint) - t.position).norm() * 100.0;
    e->max_cm = std::max(e->max_cm, d);
    sum += d;
    ++e->count;
  }
  e->mean_cm = sum / e->count;
}

// The error of the raw solution at the constrained values.
ConstraintError known_value_error(const Motion& input, const MotionConstraints& c, const Motion& raw) {
  ConstraintError err;
  double rot_sum = 0.0, root_sum = 0.0;
  for (int j = 0; j < input.num_joints(); ++j) {
    for (size_t k = 0; k < c.keys.size(); ++k) {
      if (!c.key_has_joint(k, j)) continue;
      const int f = c.keys[k].frame;
      const double deg = geodesic_angle(input.rotation(f, j).normalized(), raw.rotation(f, j)) * 180.0 / M_PI;
      err.rotation_max_deg = std::max(err.rotation_max_deg, deg);
      rot_sum += deg;
      ++err.rotations;
    }
  }
  for (const PoseKey& k : c.keys) {
    if (!k.root_position) continue;
    const double cm = (input.root_positions[k.frame] - raw.root_positions[k.frame]).norm() * 100.0;
    err.root_max_cm = std::max(err.root_max_cm, cm);
    root_sum += cm;
    ++err.roots;
  }
  if (err.rotations) err.rotation_mean_deg = rot_sum / err.rotations;
  if (err.roots) err.root_mean_cm = root_sum / err.roots;
  return err;
}

// Makes the constrained values of `out` exactly the input's, spreading the
// residuals with smoothstep ramps (see the header). Records the raw error first.
void overwrite_known(const Motion& input, const MotionConstraints& c, Motion* out, ConstraintError* err) {
  const Motion raw = *out;
  *err = known_value_error(input, c, raw);
  for (int j = 0; j < input.num_joints(); ++j) {
    std::vector<int> frames;
    for (size_t k = 0; k < c.keys.size(); ++k) {
      if (c.key_has_joint(k, j)) frames.push_back(c.keys[k].frame);
    }
    spread_rotation_residual(input, raw, j, frames, ResidualRamp::Smoothstep, out);
  }
  std::vector<int> frames;
  for (const PoseKey& k : c.keys) {
    if (k.root_position) frames.push_back(k.frame);
  }
  spread_root_residual(input, raw, frames, ResidualRamp::Smoothstep, out);
}

// Moves the ankle at `frame` to `target` (world) by turning the hip and the
// knee (two-bone IK), keeping the ankle's global rotation. `pose` holds the
// global transforms of the motion's current state and is updated for the
// three joints.
void two_bone_ik(Motion* m, GlobalPose* pose, int frame, int hip, int knee, int ankle, const Eigen::Vector3d& target) {
  const int J = m->num_joints();
  auto gpos = [&](int j) -> Eigen::Vector3d& { return pose->positions[static_cast<size_t>(frame) * J + j]; };
  auto grot = [&](int j) -> Eigen::Quaterniond& { return pose->rotations[static_cast<size_t>(frame) * J + j]; };
  const Eigen::Vector3d H = gpos(hip), K = gpos(knee), A = gpos(ankle);
  const double a = (K - H).norm(), b = (A - K).norm();
  if (a < 1e-6 || b < 1e-6) return;
  const double d = std::clamp((target - H).norm(), std::abs(a - b) + 1e-4, a + b - 1e-4);
  const Eigen::Vector3d u = H - K, v = A - K;
  Eigen::Vector3d n = u.cross(v);
  Eigen::Quaterniond knee_delta = Eigen::Quaterniond::Identity();
  if (n.norm() > 1e-8 * a * b) {
    n.normalize();
    const double now = std::acos(std::clamp(u.dot(v) / (a * b), -1.0, 1.0));
    const double want = std::acos(std::clamp((a * a + b * b - d * d) / (2 * a * b), -1.0, 1.0));
    knee_delta = Eigen::Quaterniond(Eigen::AngleAxisd(want - now, n));
  }
  const Eigen::Vector3d A1 = K + knee_delta * v;
  const Eigen::Quaterniond hip_delta = Eigen::Quaterniond::FromTwoVectors(A1 - H, target - H);
  const Eigen::Quaterniond ankle_global = grot(ankle);
  const Eigen::Quaterniond hip_global = (hip_delta * grot(hip)).normalized();
  const Eigen::Quaterniond knee_global = (hip_delta * knee_delta * grot(knee)).normalized();
  const int hip_parent = m->skeleton.parents[hip];
  const Eigen::Quaterniond parent_global = hip_parent >= 0 ? grot(hip_parent) : Eigen::Quaterniond::Identity();
  m->rotation(frame, hip) = (parent_global.conjugate() * hip_global).normalized();
  m->rotation(frame, knee) = (hip_global.conjugate() * knee_global).normalized();
  m->rotation(frame, ankle) = (knee_global.conjugate() * ankle_global).normalized();
  grot(hip) = hip_global;
  grot(knee) = knee_global;
  gpos(knee) = H + hip_delta * (K - H);
  gpos(ankle) = H + hip_delta * (A1 - H);
}

// Foot locking: while the global motion predictor says an ankle is in contact
// (probability > 0.5 for at least two frames) and the ankle is within its
// contact threshold of its standing height, its ground position is held (at
// the known frames' positions when the contact holds known frames,
// interpolated between them, else at the contact's mean position) by
// two-bone IK on hip and knee, with a linear ramp of `ramp` frames on each
// side. Frames whose leg joints are constrained, or that carry an end-effector
// target on the leg or above it, are not touched.
void lock_feet(const RigInfo& rig, const MotionConstraints& c, const std::vector<float>& contacts, int ramp,
               Motion* out) {
  const int N = out->num_frames(), F = rig.num_feet();
  const Skeleton& skel = out->skeleton;
  for (int k = 0; k < F; ++k) {
    const int ankle = rig.foot_joints[k];
    std::string name = skel.names[ankle];
    std::transform(name.begin(), name.end(), name.begin(), [](unsigned char ch) { return std::tolower(ch); });
    if (name.find("toe") != std::string::npos) continue;
    const int knee = skel.parents[ankle];
    const int hip = knee > 0 ? skel.parents[knee] : -1;
    if (hip <= 0) continue;  // needs a thigh and a shin below the root
    // Frames the IK may not change.
    std::vector<char> fixed(N, 0), known(N, 0);
    for (size_t i = 0; i < c.keys.size(); ++i) {
      const int f = c.keys[i].frame;
      if (c.key_has_joint(i, hip) || c.key_has_joint(i, knee) || c.key_has_joint(i, ankle)) fixed[f] = 1;
      if (c.key_has_joint(i, hip) && c.key_has_joint(i, knee) && c.key_has_joint(i, ankle) && c.key_fixes_root(i))
        known[f] = 1;
    }
    for (const EffectorTarget& e : c.effectors) {
      for (int j = e.joint; j >= 0; j = skel.parents[j]) {
        if (j == ankle || j == knee || j == hip) fixed[e.frame] = 1;
      }
      for (int j = ankle; j >= 0; j = skel.parents[j]) {
        if (j == e.joint) fixed[e.frame] = 1;  // an effector on the root or the spine above the hip
      }
    }
    GlobalPose pose = forward_kinematics(*out);
    // In contact: the predictor says so and the output's ankle is low enough.
    const double low = rig.foot_heights[k] + rig.foot_thresholds[k];
    std::vector<char> on(N);
    for (int f = 0; f < N; ++f) on[f] = contacts[static_cast<size_t>(f) * F + k] > 0.5f && pose.position(f, ankle).y() < low;
    std::vector<Eigen::Vector3d> goal(N);
    std::vector<double> weight(N, 0.0);
    for (int s = 0; s < N;) {
      if (!on[s]) {
        ++s;
        continue;
      }
      int e = s;
      while (e + 1 < N && on[e + 1]) ++e;
      if (e > s) {
        // The lock point: the known ankle positions inside the contact,
        // interpolated between them (so that nothing jumps at a known frame),
        // else the contact's mean position.
        std::vector<int> inside;
        for (int f = s; f <= e; ++f) {
          if (known[f]) inside.push_back(f);
        }
        Eigen::Vector3d mean = Eigen::Vector3d::Zero();
        for (int f = s; f <= e; ++f) mean += pose.position(f, ankle);
        mean /= (e - s + 1);
        auto lock_at = [&](int f) -> Eigen::Vector3d {
          if (inside.empty()) return mean;
          if (f <= inside.front()) return pose.position(inside.front(), ankle);
          if (f >= inside.back()) return pose.position(inside.back(), ankle);
          const auto it = std::lower_bound(inside.begin(), inside.end(), f);
          const int b = *it, a = *(it - 1);
          const double t = static_cast<double>(f - a) / (b - a);
          return pose.position(a, ankle) * (1.0 - t) + pose.position(b, ankle) * t;
        };
        for (int f = std::max(0, s - ramp); f <= std::min(N - 1, e + ramp); ++f) {
          const double w = f < s ? 1.0 - static_cast<double>(s - f) / (ramp + 1)
                                 : f > e ? 1.0 - static_cast<double>(f - e) / (ramp + 1) : 1.0;
          if (w > weight[f]) {
            weight[f] = w;
            goal[f] = lock_at(std::clamp(f, s, e));
          }
        }
      }
      s = e + 1;
    }
    for (int f = 0; f < N; ++f) {
      if (weight[f] <= 0.0 || fixed[f]) continue;
      const Eigen::Vector3d now = pose.position(f, ankle);
      Eigen::Vector3d target = now;
      target.x() += weight[f] * (goal[f].x() - now.x());
      target.z() += weight[f] * (goal[f].z() - now.z());
      two_bone_ik(out, &pose, f, hip, knee, ankle, target);
    }
  }
}

// Out of the reach of a two-bone chain (top, mid, joint) at `frame`: the
// change that brings the target within reach, applied at `frame` and, with the
// weights w, at its neighbours. With `swing` and a chain that does not hang
// from the root, the chain's parent (a shoulder) swings the joint toward the
// target; otherwise (a leg, or a target still beyond the swung arm) the root
// moves by the shortfall along the top-to-target direction (the hips dip or
// lean). A tenth of a millimetre inside the reach is kept as margin. Returns
// false when the target is already within reach.
bool extend_reach(const Motion& m, const GlobalPose& pose, int frame, int top, int mid, int joint,
                  const Eigen::Vector3d& target, bool swing, Eigen::Vector3d* root_shift,
                  Eigen::Quaterniond* parent_swing) {
  const double reach = (pose.position(frame, mid) - pose.position(frame, top)).norm() +
                       (pose.position(frame, joint) - pose.position(frame, mid)).norm() - 2e-4;
  const Eigen::Vector3d to_target = target - pose.position(frame, top);
  const double distance = to_target.norm();
  *root_shift = Eigen::Vector3d::Zero();
  *parent_swing = Eigen::Quaterniond::Identity();
  if (distance <= reach || distance < 1e-9) return false;
  const int parent = m.skeleton.parents[top];
  if (parent <= 0 || !swing) {
    *root_shift = to_target * ((distance - reach) / distance);
  } else {
    const Eigen::Vector3d P = pose.position(frame, parent);
    *parent_swing = Eigen::Quaterniond::FromTwoVectors(pose.position(frame, joint) - P, target - P);
  }
  return true;
}

// End-effector IK: each target is reached exactly by two-bone IK on the
// joint, its parent and grandparent (the grandparent not the root), and the
// same displacement is applied with a raised-cosine falloff over `falloff`
// frames on each side, stopping at frames whose chain is constrained by a key.
// A target beyond the chain's reach is first brought within it by
// extend_reach() (root or the chain's parent), with the same falloff.
void reach_effector(const MotionConstraints& c, const EffectorTarget& e, int falloff, Motion* out) {
  const Skeleton& skel = out->skeleton;
  const int N = out->num_frames();
  if (e.weight <= 0) return;
  const int j = e.joint, mid = skel.parents[j];
  const int top = mid > 0 ? skel.parents[mid] : -1;
  if (top <= 0) return;
  std::vector<char> fixed(N, 0);
  for (size_t i = 0; i < c.keys.size(); ++i) {
    if (c.key_has_joint(i, top) || c.key_has_joint(i, mid) || c.key_has_joint(i, j)) fixed[c.keys[i].frame] = 1;
  }
  if (fixed[e.frame]) return;  // the pose there is given
  auto falloff_weight = [&](int d) { return 0.5 * (1.0 + std::cos(M_PI * d / (falloff + 1.0))); };
  GlobalPose pose = forward_kinematics(*out);
  for (int attempt = 0; attempt < 3; ++attempt) {
    Eigen::Vector3d shift;
    Eigen::Quaterniond swing;
    if (!extend_reach(*out, pose, e.frame, top, mid, j, e.position, attempt == 0, &shift, &swing)) break;
    const bool swung = shift.isZero();
    const int parent = skel.parents[top], grand = parent > 0 ? skel.parents[parent] : -1;
    // Frames whose keys fix what the extension changes: the chain, and the
    // root position (a shift) or the chain's parent (a swing).
    std::vector<char> kept = fixed;
    for (size_t i = 0; i < c.keys.size(); ++i) {
      if (swung ? c.key_has_joint(i, parent) : c.keys[i].root_position) kept[c.keys[i].frame] = 1;
    }
    if (kept[e.frame]) break;
    for (int f = std::max(0, e.frame - falloff); f <= std::min(N - 1, e.frame + falloff); ++f) {
      const int d = std::abs(f - e.frame);
      bool blocked = false;  // stop at a kept frame, as the chain's falloff does
      for (int g = std::min(f, e.frame); g <= std::max(f, e.frame); ++g) blocked = blocked || kept[g];
      if (blocked) continue;
      const double w = falloff_weight(d);
      if (!swung) {
        out->root_positions[f] += w * shift;
      } else {
        const Eigen::Quaterniond global = pose.rotation(f, parent);
        const Eigen::Quaterniond up = grand >= 0 ? pose.rotation(f, grand) : Eigen::Quaterniond::Identity();
        const Eigen::Quaterniond turned = Eigen::Quaterniond::Identity().slerp(w, swing) * global;
        out->rotation(f, parent) = (up.conjugate() * turned).normalized();
      }
    }
    pose = forward_kinematics(*out);
  }
  const Eigen::Vector3d delta = e.position - pose.position(e.frame, j);
  for (int dir : {-1, 1}) {
    for (int d = dir < 0 ? 0 : 1; d <= falloff; ++d) {
      const int f = e.frame + dir * d;
      if (f < 0 || f >= N || fixed[f]) break;
      two_bone_ik(out, &pose, f, top, mid, j, pose.position(f, j) + falloff_weight(d) * delta);
    }
  }
}

void reach_effectors(const MotionConstraints& c, int falloff, Motion* out) {
  // A second pass puts back what a later target's root shift moved of an
  // earlier target's joint.
  for (int pass = 0; pass < 2; ++pass) {
    for (const EffectorTarget& e : c.effectors) reach_effector(c, e, falloff, out);
  }
}

}  // namespace

std::string LatentSolverOptions::validate() const {
  std::ostringstream e;
  e << LatentOptimizerSettings::validate();
  if (overlap < 1) e << "overlap must be >= 1; ";
  if (keyed_iterations < 0) e << "keyed_iterations must be >= 0; ";
  const EnergyWeights& w = weights;
  for (double v : {w.rotation, w.position, w.root_orientation, w.root_translation, w.effector, w.latent_prior,
                   w.foot_skating, w.smoothness}) {
    if (!(v >= 0) || !std::isfinite(v)) {
      e << "energy weights must be finite and non-negative; ";
      break;
    }
  }
  return e.str();
}

LatentSolverOptions default_solver_options(SolverMethod method) {
  LatentSolverOptions o;
  o.method = method;
  return o;
}

LatentSolution solve_latents(const NemfModel& model, const WindowProblem& problem, const InitialGuess& start,
                             const LatentSolverOptions& options, const TaskContext& ctx, int iteration_offset,
                             int iteration_total) {
  const std::string bad = options.validate();
  if (!bad.empty()) throw InputError("invalid solver options: " + bad);
  const int zl = model.config().zl, zg = model.config().zg;
  if (!start.z_l.defined() || !start.z_g.defined() || start.z_l.numel() != zl || start.z_g.numel() != zg)
    throw InputError("initial codes must have " + std::to_string(zl) + " + " + std::to_string(zg) + " values");
  const auto t0 = Clock::now();
  const FlatLatentEnergy energy(window_energy(model, problem, options.weights), zl, zg);
  const at::Tensor x0 = energy.join(start.z_l, start.z_g);
  const int cap = options.max_iterations > 0 ? options.max_iterations : default_iterations(options.method);
  const int total = iteration_total > 0 ? iteration_total : cap;

  LatentSolution out;
  SolveSummary& s = out.summary;
  s.initial_terms = energy.terms(x0, &s.initial_energy);
  at::Tensor x = x0;
  const EnergyWeights& w = options.weights;
  const bool dense = w.root_translation > 0 || w.effector > 0 || w.foot_skating > 0 || w.smoothness > 0;
  if (options.method == SolverMethod::Lbfgs && options.keyed_iterations > 0 && dense) {
    EnergyWeights keyed = w;
    keyed.root_translation = keyed.effector = keyed.foot_skating = keyed.smoothness = 0.0;
    const FlatLatentEnergy cheap(window_energy(model, problem, keyed), zl, zg);
    LatentOptimizerStats first;
    x = minimize_latent(cheap.total(), x, options.method, options.capped(options.keyed_iterations), ctx, &first,
                        iteration_offset, total);
    s.keyed_iterations = first.iterations;
    s.evaluations += first.evaluations;
  }
  LatentOptimizerStats main;
  x = minimize_latent(energy.total(), x, options.method, options.capped(cap), ctx, &main,
                      iteration_offset + s.keyed_iterations, total);
  s.iterations = s.keyed_iterations + main.iterations;
  s.evaluations += main.evaluations;
  s.converged = main.converged;
  s.message = main.message;
  s.final_terms = energy.terms(x, &s.final_energy);
  out.z_l = energy.z_l(x);
  out.z_g = energy.z_g(x);
  s.wall_ms = ms_since(t0);
  return out;
}

Motion complete_motion(const NemfModel& model, const Motion& input, const MotionConstraints& constraints,
                       const LatentSolverOptions& options, const TaskContext& ctx, CompletionReport* report) {
  const auto t0 = Clock::now();
  const std::string bad = options.validate();
  if (!bad.empty()) throw InputError("invalid solver options: " + bad);
  const RigInfo& rig = model.rig();
  const int N = input.num_frames(), J = input.num_joints();
  if (J != rig.num_joints() || input.skeleton.names != rig.skeleton.names ||
      input.skeleton.parents != rig.skeleton.parents) {
    throw InputError("the motion's skeleton does not match the model's: " + std::to_string(J) + " joints given, the model has " +
                     std::to_string(rig.num_joints()) + " (joint names and parents must agree)");
  }
  if (N < 2) throw InputError("the motion needs at least two frames");
  if (input.rotations.size() != static_cast<size_t>(N) * J)
    throw InputError("the motion's rotation count does not match its frames and joints");
  constraints.validate(N, J);
  for (size_t k = 0; k < constraints.keys.size(); ++k) {
    const int f = constraints.keys[k].frame;
    for (int j = 0; j < J; ++j) {
      if (!constraints.key_has_joint(k, j)) continue;
      const Eigen::Quaterniond& q = input.rotation(f, j);
      if (!q.coeffs().allFinite() || q.norm() < 1e-6)
        throw InputError("the rotation of joint " + input.skeleton.names[j] + " at known frame " + std::to_string(f) +
                         " is not a finite, non-zero quaternion");
    }
    if (constraints.keys[k].root_position && !input.root_positions[f].allFinite())
      throw InputError("the root position at known frame " + std::to_string(f) + " is not finite");
  }

  const int W = model.config().window;
  const std::vector<int> starts = window_starts(N, W, W - std::min(options.overlap, W / 2));
  const int windows = static_cast<int>(starts.size());
  auto length_of = [&](int k) { return std::min(W, N - starts[k]); };

  // First window holding a key that fixes the root.
  int first = -1;
  for (size_t k = 0; k < constraints.keys.size() && first < 0; ++k) {
    if (!constraints.key_fixes_root(k)) continue;
    for (int w = 0; w < windows; ++w) {
      if (constraints.keys[k].frame >= starts[w] && constraints.keys[k].frame < starts[w] + length_of(w)) {
        first = w;
        break;
      }
    }
  }
  std::vector<int> order;
  for (int w = first; w < windows; ++w) order.push_back(w);
  for (int w = first - 1; w >= 0; --w) order.push_back(w);

  std::shared_ptr<const LatentInitializer> init = options.initializer;
  if (!init) init = std::make_shared<InterpolationEncoderInitializer>();
  const int cap = options.max_iterations > 0 ? options.max_iterations
                 : options.method == SolverMethod::Adam ? default_iterations(options.method) : 60;

  CompletionReport rep;
  Motion out = Motion::identity(input.skeleton, N, input.fps);
  std::vector<char> solved(N, 0);
  const int F = rig.num_feet();
  std::vector<float> contacts(static_cast<size_t>(N) * F, 0.0f);
  int iterations = 0;
  for (int w : order) {
    const int s = starts[w], T = length_of(w);
    MotionConstraints wc = constraints.slice(s, T);
    Motion src = input.slice(s, s + T);
    // Overlap with an already solved neighbour: full-pose keys from its solution
    // (the user's own constrained values kept where there are some).
    int ov_a = T, ov_b = 0;
    for (int f = 0; f < T; ++f) {
      if (!solved[s + f]) continue;
      ov_a = std::min(ov_a, f);
      ov_b = std::max(ov_b, f + 1);
    }
    if (ov_a < ov_b) {
      std::vector<PoseKey> merged;
      size_t u = 0;
      for (int f = 0; f < T; ++f) {
        while (u < wc.keys.size() && wc.keys[u].frame < f) merged.push_back(wc.keys[u++]);
        const bool user = u < wc.keys.size() && wc.keys[u].frame == f;
        if (f < ov_a || f >= ov_b) continue;
        for (int j = 0; j < J; ++j) {
          if (!(user && wc.key_has_joint(u, j))) src.rotation(f, j) = out.rotation(s + f, j);
        }
        if (!(user && wc.keys[u].root_position)) src.root_positions[f] = out.root_positions[s + f];
        PoseKey full;
        full.frame = f;
        merged.push_back(full);
        if (user) ++u;
      }
      while (u < wc.keys.size()) merged.push_back(wc.keys[u++]);
      wc.keys = merged;
    }
    int anchor = -1;
    for (size_t k = 0; k < wc.keys.size() && anchor < 0; ++k) {
      if (wc.key_fixes_root(k)) anchor = wc.keys[k].frame;
    }
    if (anchor < 0) {
      throw InputError("frames " + std::to_string(s) + ".." + std::to_string(s + T - 1) +
                       " hold no key that fixes the root");  // cannot happen after validation
    }
    const WindowProblem problem = make_window_problem(rig, src, 0, T, wc, anchor);
    InitRequest request;
    request.model = &model;
    request.window = &src;
    request.constraints = &wc;
    request.anchor = anchor;
    request.context = &ctx;
    const InitialGuess start = init->initialize(request);
    LatentSolverOptions window_options = options;
    window_options.max_iterations = window_iterations(options, wc, T);
    LatentSolution sol = solve_latents(model, problem, start, window_options, ctx, iterations, cap * windows);
    iterations += sol.summary.iterations;
    rep.windows.push_back(sol.summary);
    rep.window_starts.push_back(s);

    const DecodedWindow dec = decode_window(model, problem, sol.z_l, sol.z_g);
    Motion piece = Motion::identity(input.skeleton, T, input.fps);
    write_window(dec.local_rotations, dec.root_positions, problem.transform, &piece, 0);
    const at::Tensor piece_contacts = dec.contacts.contiguous();
    const float* pc = piece_contacts.data_ptr<float>();
    // Cross-fade over the overlap; the new window's weight rises away from the solved side.
    const bool solved_before = ov_a < ov_b && ov_a == 0;
    const int n_ov = ov_b - ov_a;
    for (int f = 0; f < T; ++f) {
      const int g = s + f;
      double wn = 1.0;
      if (solved[g]) {
        const int pos = solved_before ? f - ov_a + 1 : ov_b - f;
        wn = static_cast<double>(pos) / (n_ov + 1);
      }
      cross_fade_frame(piece, f, wn, &out, g);
      for (int k = 0; k < F; ++k) {
        float& c = contacts[static_cast<size_t>(g) * F + k];
        c = static_cast<float>(c * (1.0 - wn) + pc[f * F + k] * wn);
      }
      solved[g] = 1;
    }
  }

  measure_effectors(out, constraints, &rep.raw_effectors);
  if (options.overwrite_known) {
    overwrite_known(input, constraints, &out, &rep.raw_known);
    if (options.foot_lock_ramp >= 0) lock_feet(rig, constraints, contacts, options.foot_lock_ramp, &out);
    if (options.effector_falloff >= 0) reach_effectors(constraints, options.effector_falloff, &out);
  } else {
    Motion copy = out;
    overwrite_known(input, constraints, &copy, &rep.raw_known);
  }
  measure_effectors(out, constraints, &rep.effectors);
  rep.iterations = iterations;
  rep.wall_ms = ms_since(t0);
  if (report) *report = std::move(rep);
  return out;
}

}  // namespace mf
