#include "tasks/latent/latent_solver.h"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <memory>
#include <optional>
#include <random>
#include <sstream>

#include "prior/motion/errors.h"
#include "prior/motion/rotations.h"
#include "prior/runtime/nemf_runtime.h"
#include "tasks/constraints/interpolation_fill.h"
#include "tasks/constraints/residuals.h"
#include "tasks/fixups/effector_ik.h"
#include "tasks/fixups/foot_locking.h"
#include "tasks/latent/latent_optimizer.h"
#include "tasks/latent/runtime_latent_energy.h"
#include "tasks/latent/window_energies.h"
#include "tasks/latent/windows.h"

namespace mf {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

int default_iterations(LatentOptimizer m) { return m == LatentOptimizer::Adam ? 600 : 40; }

// A keys-only stage only pays where a dense term is left for the second stage.
bool has_dense_term(const EnergyWeights& w) {
  return w.root_translation > 0 || w.effector > 0 || w.trajectory > 0 || w.trajectory_facing > 0 ||
         w.foot_skating > 0 || w.smoothness > 0;
}

std::vector<int> key_frames_of(const MotionConstraints& c) {
  std::vector<int> frames;
  for (const PoseKey& k : c.keys) frames.push_back(k.frame);
  return frames;
}

std::vector<int> key_frames_of(const RuntimeWindowProblem& p) { return p.key_frames; }

// Makes the constrained values of `out` exactly the input's, spreading the
// residuals with smoothstep ramps (see the header). Records the raw error first.
void overwrite_known(const Motion& input, const MotionConstraints& c, Motion* out, ConstraintError* err) {
  const Motion raw = *out;
  *err = key_error(input, c, raw);
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

// ---------------------------------------------------------------------------
// complete_motion() in steps

void check_solver_options(const LatentSolverOptions& options) {
  const std::string bad = options.validate();
  if (!bad.empty()) throw InputError("invalid solver options: " + bad);
}

// Throws InputError unless the call can run: valid options, the model's
// skeleton, a well-formed motion and constraints, finite known values.
void check_completion(const runtime::NemfRuntime& model, const Motion& input, const MotionConstraints& constraints,
                      const LatentSolverOptions& options) {
  check_solver_options(options);
  const int N = input.num_frames(), J = input.num_joints();
  check_model_skeleton(model.rig(), input.skeleton, "motion");
  if (N < 2) throw InputError("the motion needs at least two frames");
  if (input.rotations.size() != static_cast<size_t>(N) * J)
    throw InputError("the motion's rotation count does not match its frames and joints");
  constraints.validate(N, J);
  constraints.check_values(input);
}

// One window of the solve, in solve order: where it lies (WindowSpan) and
// what it is solved under.
struct WindowPlan : WindowSpan {
  /// The caller's constraints of the window (window frames), and the same
  /// with full-pose keys at the shared frames (what the window is solved under).
  MotionConstraints user, constraints;
  int anchor = 0;      ///< window frame of the first key that fixes the root
  WindowCaps caps;     ///< the window's iteration caps (window_caps())
};

// Full-pose keys at window frames [begin, end) merged into `user`'s keys (a
// user key there is replaced by the full-pose key).
MotionConstraints with_shared_keys(const MotionConstraints& user, int begin, int end, int length) {
  MotionConstraints c = user;
  std::vector<PoseKey> merged;
  size_t u = 0;
  for (int f = 0; f < length; ++f) {
    while (u < user.keys.size() && user.keys[u].frame < f) merged.push_back(user.keys[u++]);
    const bool given = u < user.keys.size() && user.keys[u].frame == f;
    if (f < begin || f >= end) continue;
    PoseKey full;
    full.frame = f;
    merged.push_back(full);
    if (given) ++u;
  }
  while (u < user.keys.size()) merged.push_back(user.keys[u++]);
  c.keys = merged;
  return c;
}

// The windows in solve order: the first window that holds a key fixing the
// root, the later ones forward, then the earlier ones backward; each
// constrained, where it overlaps windows solved before, by full-pose keys
// taken from their solution.
std::vector<WindowPlan> plan_windows(int W, int N, const MotionConstraints& constraints,
                                     const LatentSolverOptions& options) {
  const std::vector<int> starts = window_starts(N, W, W - std::min(options.overlap, W / 2));
  const int windows = static_cast<int>(starts.size());
  auto length_of = [&](int k) { return std::min(W, N - starts[k]); };
  int first = -1;
  for (size_t k = 0; k < constraints.keys.size() && first < 0; ++k) {
    if (!constraints.key_fixes_root(k)) continue;
    for (int w = 0; w < windows && first < 0; ++w) {
      if (constraints.keys[k].frame >= starts[w] && constraints.keys[k].frame < starts[w] + length_of(w)) first = w;
    }
  }
  std::vector<int> order;
  for (int w = first; w < windows; ++w) order.push_back(w);
  for (int w = first - 1; w >= 0; --w) order.push_back(w);

  std::vector<WindowPlan> plan;
  std::vector<char> solved(N, 0);
  for (int w : order) {
    WindowPlan p;
    p.start = starts[w];
    p.length = length_of(w);
    p.shared_begin = p.length;
    for (int f = 0; f < p.length; ++f) {
      if (!solved[p.start + f]) continue;
      p.shared_begin = std::min(p.shared_begin, f);
      p.shared_end = std::max(p.shared_end, f + 1);
    }
    p.user = constraints.slice(p.start, p.length);
    p.constraints = p.shared_begin < p.shared_end
                        ? with_shared_keys(p.user, p.shared_begin, p.shared_end, p.length)
                        : p.user;
    p.anchor = -1;
    for (size_t k = 0; k < p.constraints.keys.size() && p.anchor < 0; ++k) {
      if (p.constraints.key_fixes_root(k)) p.anchor = p.constraints.keys[k].frame;
    }
    if (p.anchor < 0) {
      throw InputError("frames " + std::to_string(p.start) + ".." + std::to_string(p.start + p.length - 1) +
                       " hold no key that fixes the root");  // cannot happen after validation
    }
    p.caps = window_caps(options, key_frames_of(p.constraints),
                         !p.constraints.effectors.empty() || !p.constraints.contacts.empty() ||
                             !p.constraints.followed_trajectory().empty(),
                         p.length);
    std::fill(solved.begin() + p.start, solved.begin() + p.start + p.length, 1);
    plan.push_back(std::move(p));
  }
  return plan;
}

// The frames of window `w` of `input`, the shared frames' unconstrained
// values taken from the solution so far (`out`).
Motion window_source(const Motion& input, const Motion& out, const WindowPlan& w) {
  Motion src = input.slice(w.start, w.start + w.length);
  size_t u = 0;
  for (int f = w.shared_begin; f < w.shared_end; ++f) {
    while (u < w.user.keys.size() && w.user.keys[u].frame < f) ++u;
    const bool given = u < w.user.keys.size() && w.user.keys[u].frame == f;
    for (int j = 0; j < input.num_joints(); ++j) {
      if (!(given && w.user.key_has_joint(u, j))) src.rotation(f, j) = out.rotation(w.start + f, j);
    }
    if (!(given && w.user.keys[u].root_position)) src.root_positions[f] = out.root_positions[w.start + f];
  }
  return src;
}

// The start of an alternative solution: Gaussian noise on the codes
// (LatentSolverOptions::start_noise), its own stream per window.
InitialGuess perturbed(InitialGuess g, const LatentSolverOptions& o, int window) {
  if (o.start_noise <= 0.0) return g;
  std::mt19937_64 rng(o.start_seed * 1000003ull + static_cast<uint64_t>(window));
  std::normal_distribution<float> normal(0.0f, 1.0f);
  for (Eigen::VectorXf* z : {&g.z_l, &g.z_g}) {
    for (Eigen::Index i = 0; i < z->size(); ++i) (*z)[i] += static_cast<float>(o.start_noise) * normal(rng);
  }
  return g;
}

// A window's energies on the Eigen runtime: the product's.
class RuntimeWindowEnergies final : public WindowEnergies {
 public:
  RuntimeWindowEnergies(const runtime::NemfRuntime& model, const RuntimeWindowProblem& p,
                        const EnergyWeights& full_weights, const EnergyWeights& keyed_weights)
      : evaluator_(model),
        problem_(p),
        full_(evaluator_, problem_, full_weights, model.config().zl, model.config().zg),
        keyed_(evaluator_, problem_, keyed_weights, model.config().zl, model.config().zg) {}
  DirectLatentEnergy& full() override { return full_; }
  DirectLatentEnergy& keyed() override { return keyed_; }
  DecodedWindow decode(const Eigen::VectorXf& z_l, const Eigen::VectorXf& z_g) override {
    return evaluator_.decode_window(problem_, z_l, z_g);
  }
  bool on_runtime() const override { return true; }

 private:
  RuntimeEnergy evaluator_;
  const RuntimeWindowProblem& problem_;
  RuntimeLatentEnergy full_, keyed_;
};

// The context's reference energies when it has them, else the runtime's.
std::unique_ptr<WindowEnergies> window_energies(const runtime::NemfRuntime& model, const TaskContext& ctx,
                                                const RuntimeWindowProblem& p, const EnergyWeights& full,
                                                const EnergyWeights& keyed) {
  if (ctx.reference) return ctx.reference->latent_window(p, full, keyed);
  return std::make_unique<RuntimeWindowEnergies>(model, p, full, keyed);
}

// The keys-only weights of a window's first stage.
EnergyWeights keyed_weights(const EnergyWeights& full) {
  EnergyWeights keyed = full;
  keyed.root_translation = keyed.effector = keyed.foot_skating = keyed.smoothness = 0.0;
  keyed.trajectory = keyed.trajectory_facing = 0.0;
  return keyed;
}

// solve_latents() on options the caller validated: complete_motion() checks
// them once per call, not once per window.
LatentSolution solve_window_latents(WindowEnergies& energies, const NemfConfig& config,
                                    const RuntimeWindowProblem& problem,
                                    const InitialGuess& start, const LatentSolverOptions& options,
                                    const TaskContext& ctx, int iteration_offset, int iteration_total) {
  assert(options.validate().empty());
  const int zl = config.zl, zg = config.zg;
  if (start.z_l.size() != zl || start.z_g.size() != zg)
    throw InputError("initial codes must have " + std::to_string(zl) + " + " + std::to_string(zg) + " values");
  const auto t0 = Clock::now();
  const WindowCaps caps =
      window_caps(options, key_frames_of(problem),
                  problem.num_effectors() > 0 || problem.num_pin_steps() > 0 || problem.num_trajectory() > 0, problem.length);
  const int total = iteration_total > 0 ? iteration_total : caps.keyed + caps.full;
  FirstStage first;
  if (caps.keyed > 0) first = {&energies.keyed(), caps.keyed};
  LatentSolution out;
  const Eigen::VectorXd x = minimize_window(energies.full(), join_codes(start.z_l, start.z_g),
                                            options.capped(caps.full), ctx, iteration_offset, total, &out.summary,
                                            first);
  out.z_l = head_codes(x, zl);
  out.z_g = tail_codes(x, zg);
  out.summary.runtime_energy = energies.on_runtime();
  out.summary.wall_ms = ms_since(t0);
  return out;
}

// Solves window `w` of `input` from its initial codes (`whole`: the
// initialiser's fill of the whole input, when there is one) given the
// solution so far, and records its summary.
SolvedWindow solve_window(const runtime::NemfRuntime& model, const Motion& input, const WindowPlan& w,
                          const Motion& so_far, const LatentInitializer& init, const std::optional<Motion>& whole,
                          const LatentSolverOptions& options, const TaskContext& ctx, const TaskContext& window_ctx,
                          int iteration_offset, int iteration_total, CompletionReport* rep) {
  const Motion src = window_source(input, so_far, w);
  const RuntimeWindowProblem problem = make_runtime_problem(model.rig(), src, 0, w.length, w.constraints, w.anchor);
  InitRequest request;
  request.model = &model;
  request.window = &src;
  request.constraints = &w.constraints;
  request.anchor = w.anchor;
  request.context = &ctx;
  const InitialGuess start =
      perturbed(whole ? encode_window(request, whole->slice(w.start, w.start + w.length))
                      : init.initialize(request),
                options, window_ctx.window);
  LatentSolverOptions window_options = options;
  window_options.keyed_iterations = w.caps.keyed;
  window_options.max_iterations = w.caps.full;
  const std::unique_ptr<WindowEnergies> energies =
      window_energies(model, ctx, problem, options.weights, keyed_weights(options.weights));
  const LatentSolution sol = solve_window_latents(*energies, model.config(), problem, start, window_options,
                                                  window_ctx, iteration_offset, iteration_total);
  rep->windows.push_back(sol.summary);
  rep->window_starts.push_back(w.start);
  std::vector<int> keys;
  for (const PoseKey& k : w.user.keys) keys.push_back(k.frame);
  rep->trust.push_back(judge_window(options.fallback, sol.summary, src, keys));
  return {energies->decode(sol.z_l, sol.z_g), problem.transform, sol.summary.iterations};
}

// Solves the windows of `plan` in order (the progress total is the sum of
// their caps) and joins their solutions (WindowSolver). With several windows,
// each starts from its slice of the initialiser's fill of the whole input
// when it has one (LatentInitializer::fill_input).
WindowedSolution solve_windows(const runtime::NemfRuntime& model, const Motion& input,
                               const MotionConstraints& constraints, const std::vector<WindowPlan>& plan,
                               const LatentSolverOptions& options, const TaskContext& ctx, CompletionReport* rep) {
  std::shared_ptr<const LatentInitializer> init = options.initializer;
  if (!init) init = std::make_shared<InterpolationEncoderInitializer>();
  int total = 0;
  for (const WindowPlan& w : plan) total += w.caps.keyed + w.caps.full;
  const std::optional<Motion> whole = plan.size() > 1 ? init->fill_input(input, constraints, ctx) : std::nullopt;
  const WindowSolver solver(std::vector<WindowSpan>(plan.begin(), plan.end()), input.skeleton, input.num_frames(),
                            input.fps, model.rig().num_feet());
  WindowedSolution out = solver.solve(ctx, [&](int k, const WindowedSolution& so_far, const TaskContext& window_ctx,
                                               int offset) {
    return solve_window(model, input, plan[k], so_far.motion, *init, whole, options, ctx, window_ctx, offset, total,
                        rep);
  });
  rep->iterations = out.iterations;
  return out;
}

// The known values made exact (see the header): the overwrite, foot locking
// and end-effector IK, each as the options ask, with their errors reported.
void make_known_values_exact(const RigInfo& rig, const Motion& input, const MotionConstraints& constraints,
                             const LatentSolverOptions& options, const std::vector<float>& contacts, Motion* out,
                             CompletionReport* rep) {
  rep->raw_effectors = effector_error(*out, constraints);
  if (options.overwrite_known) {
    overwrite_known(input, constraints, out, &rep->raw_known);
    if (options.foot_lock_ramp >= 0) lock_feet(rig, constraints, contacts, options.foot_lock_ramp, out);
    if (options.effector_falloff >= 0) reach_effectors(constraints, options.effector_falloff, out);
    rep->warnings = pin_contacts(constraints, options.contact_ramp, out);
  } else {
    Motion copy = *out;
    overwrite_known(input, constraints, &copy, &rep->raw_known);
  }
  rep->effectors = effector_error(*out, constraints);
}

// Each window's weighted energy terms, "initial.<term>" and "final.<term>",
// one entry per window and term (TaskContext::diagnostics).
void append_term_diagnostics(const std::vector<SolveSummary>& windows,
                             std::vector<std::pair<std::string, double>>* out) {
  for (const SolveSummary& s : windows) {
    for (const auto& [name, value] : s.initial_terms) out->emplace_back("initial." + name, value);
    for (const auto& [name, value] : s.final_terms) out->emplace_back("final." + name, value);
  }
}

}  // namespace

WindowCaps window_caps(const LatentSolverOptions& o, const std::vector<int>& key_frames, bool has_effectors, int T) {
  WindowCaps caps;
  if (o.optimizer == LatentOptimizer::Adam) {
    caps.full = o.max_iterations > 0 ? o.max_iterations : default_iterations(o.optimizer);
    return caps;
  }
  std::vector<int> frames = key_frames;
  std::sort(frames.begin(), frames.end());
  int longest = 0, previous = -1;
  for (int f : frames) {
    longest = std::max(longest, f - previous - 1);
    previous = f;
  }
  longest = std::max(longest, T - previous - 1);
  const bool long_window = has_effectors || longest >= 40;
  caps.keyed = o.keyed_iterations >= 0 ? o.keyed_iterations : (long_window ? 0 : 30);
  if (!has_dense_term(o.weights)) caps.keyed = 0;
  if (o.max_iterations > 0) {
    caps.full = o.max_iterations;
  } else {
    caps.full = long_window ? 60 : caps.keyed > 0 ? 20 : default_iterations(o.optimizer);
  }
  return caps;
}

std::string LatentSolverOptions::validate() const {
  std::ostringstream e;
  e << LatentOptimizerSettings::validate();
  if (overlap < 1) e << "overlap must be >= 1; ";
  if (keyed_iterations < -1) e << "keyed_iterations must be >= 0, or -1 for the default; ";
  if (contact_ramp < 0) e << "contact_ramp must be >= 0; ";
  if (!(start_noise >= 0) || !std::isfinite(start_noise)) e << "start_noise must be finite and non-negative; ";
  const EnergyWeights& w = weights;
  for (double v : {w.rotation, w.position, w.root_orientation, w.root_translation, w.effector, w.contact, w.trajectory,
                   w.trajectory_facing, w.latent_prior, w.foot_skating, w.smoothness}) {
    if (!(v >= 0) || !std::isfinite(v)) {
      e << "energy weights must be finite and non-negative; ";
      break;
    }
  }
  return e.str();
}

LatentSolverOptions default_solver_options(LatentOptimizer optimizer) {
  LatentSolverOptions o;
  o.optimizer = optimizer;
  return o;
}

LatentSolution solve_latents(const runtime::NemfRuntime& model, const RuntimeWindowProblem& problem,
                             const InitialGuess& start, const LatentSolverOptions& options, const TaskContext& ctx,
                             int iteration_offset, int iteration_total) {
  check_solver_options(options);
  const std::unique_ptr<WindowEnergies> energies =
      window_energies(model, ctx, problem, options.weights, keyed_weights(options.weights));
  return solve_window_latents(*energies, model.config(), problem, start, options, ctx, iteration_offset,
                              iteration_total);
}

Motion complete_motion(const runtime::NemfRuntime& model, const Motion& input, const MotionConstraints& constraints,
                       const LatentSolverOptions& options, const TaskContext& ctx, CompletionReport* report) {
  const auto t0 = Clock::now();
  check_completion(model, input, constraints, options);
  const std::vector<WindowPlan> plan = plan_windows(model.config().window, input.num_frames(), constraints, options);
  CompletionReport rep;
  LatentSolverOptions o = options;
  o.fallback.enabled = options.fallback.enabled && options.start_noise == 0.0 && !constraints.beyond_full_poses();
  WindowedSolution solved = solve_windows(model, input, constraints, plan, o, ctx, &rep);
  const std::string note = fallback_note(rep.trust, o.fallback);
  if (!note.empty()) {
    const std::vector<WindowSpan> spans(plan.begin(), plan.end());
    blend_toward_interpolation(o.fallback.toward_input ? input : fill_by_interpolation(input, constraints),
                               interpolation_weights(spans, rep.trust, input.num_frames()), &solved.motion,
                               &solved.contacts);
  }
  make_known_values_exact(model.rig(), input, constraints, options, solved.contacts, &solved.motion, &rep);
  if (!note.empty()) rep.warnings.push_back(note);
  rep.wall_ms = ms_since(t0);
  if (ctx.diagnostics) append_term_diagnostics(rep.windows, ctx.diagnostics);
  if (report) *report = std::move(rep);
  return std::move(solved.motion);
}

}  // namespace mf
