#include "tasks/latent_solver.h"

#include <ATen/ATen.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <sstream>

#include "prior/model/nemf.h"
#include "prior/motion/errors.h"
#include "prior/motion/rotations.h"
#include "tasks/effector_ik.h"
#include "tasks/foot_locking.h"
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
  check_model_skeleton(rig, input.skeleton, "motion");
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
