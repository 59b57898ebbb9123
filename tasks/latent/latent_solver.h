// The latent solvers: in-betweening, gap filling, partial and end-effector
// constraints by optimising the prior's latent codes (z_l, z_g) of each window
// with the network frozen (tasks/reference/energies.h defines the energy).
//
// Two optimisers, selectable:
//   Lbfgs (default)  Ceres' GradientProblemSolver with L-BFGS and a Wolfe line
//                    search; cost and gradient from the Eigen runtime's energy
//                    (tasks/latent/runtime_energy.h; the double parameters of
//                    Ceres converted to float and back), or from the
//                    context's reference energies (TaskContext::reference,
//                    tasks/latent/window_energies.h) when it has them.
//   Adam             NeMF's reference: lr 0.1, 600 iterations, x0.7 every 200;
//                    returns the lowest-energy iterate.
// L-BFGS may run a cheap keys-only stage first (keyed_iterations). Both stop
// early on convergence, report iterations and the final energy per
// term and wall time, and call TaskContext::report() once per iteration, so a
// progress callback or the cancel flag can stop them (CancelledError).
// Deterministic for a given input, options and seed (no step is random: the
// seed is handed to initialisers that sample).
//
// Defaults (docs/BENCHMARKS.md, "Latent solvers", has the measurements):
// L-BFGS: 30 keys-only iterations then at most 20 full ones (a single stage of
// 60 with long gaps or end-effector targets; window_caps()),
// function tolerance 1e-3; weights rotation 5,
// position 10, root orientation 1, root translation 10 (the GMP path), no
// prior, skating or smoothness term (they bought nothing measurable with the
// pilot prior); squared penalties; foot locking with a 5-frame ramp.
//
// complete_motion() is the task: it splits the input into windows of the
// model's length, canonicalises each at its first key that fixes the root,
// initialises (LatentSolverOptions::initializer), solves, decodes every frame
// (root translation from the global motion predictor), and then makes the
// constrained values exact:
//  * Known values come out exactly as given (bit for bit). The residual between
//    the input and the raw solution at each key is spread over the frames
//    around it: between two keys constraining the same joint (or the root
//    position) the residual is blended with smoothstep weights from one key's
//    to the other's; before the first and after the last such key it is held.
//    The error of the raw solution at the keys, before this overwrite, is
//    reported (CompletionReport::raw_known). (tasks/constraints/residuals.h, with
//    smoothstep ramps.)
//  * End-effector targets: the energy pulls the motion toward them (measured on
//    the blended motion, EnergyWeights::on_output, so that the overwrite does
//    not undo it), and a final two-bone IK on the target joint's chain (the
//    joint, its parent and grandparent) places the joint exactly, spreading
//    the same displacement over `effector_falloff` frames on each side with
//    raised-cosine weights (tasks/fixups/effector_ik.h: a target beyond the chain's
//    reach swings the shoulder or moves the root). The error of the raw
//    solution and of the output are reported.
//  * Foot locking (foot_lock_ramp >= 0, on by default; tasks/fixups/foot_locking.h):
//    where the global motion predictor reports an ankle in contact and the
//    output's ankle is low, the ankle's ground position is held by two-bone
//    IK on thigh and shin (known frames, constrained legs and effector frames
//    untouched). The overwrite spreads key residuals over whole gaps, which
//    makes planted feet slide; this takes most of that back.
//  * Inputs longer than a window: windows of the model's length overlapping by
//    `overlap` frames, solved one after the other starting from the first
//    window that holds a key fixing the root; each later (or earlier) window
//    is also constrained by full-pose keys at the overlap frames, taken from
//    the solution of its already solved neighbour, and the two solutions are
//    cross-faded over the overlap (SLERP / LERP with linear weights), so
//    there is no seam (the window loop of tasks/latent/window_solver.h).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "prior/motion/motion.h"
#include "tasks/constraints/constraint_report.h"
#include "tasks/context/task_context.h"
#include "tasks/fixups/effector_ik.h"
#include "tasks/fixups/foot_locking.h"
#include "tasks/latent/energy_weights.h"
#include "tasks/latent/initializers.h"
#include "tasks/latent/fallback.h"
#include "tasks/latent/latent_optimizer.h"
#include "tasks/latent/window_problem.h"
#include "tasks/latent/window_solver.h"

namespace mf {

namespace runtime {
class NemfRuntime;
}

/// The options of complete_motion() and solve_latents(). The optimiser and its
/// settings are embedded (LatentOptimizerSettings, with its defaults: L-BFGS,
/// function tolerance 1e-3, gradient tolerance 1e-8, parameter tolerance
/// 1e-6, L-BFGS rank 20; Adam lr 0.1, x0.7 every 200 iterations, stopping when
/// the best energy improves by less than 1e-4 over 100 iterations).
/// max_iterations is the cap per window (of the full-energy stage); 0 means
/// the method's default (window_caps()).
struct LatentSolverOptions : LatentOptimizerSettings {
  EnergyWeights weights;

  /// L-BFGS only: first up to this many iterations on the terms that need
  /// only the key frames decoded (rotation, position, root orientation, latent
  /// prior), which cost a fraction of a dense evaluation, then the full energy
  /// (max_iterations). 0 = a single stage; -1 = the solver's choice per window
  /// (window_caps()).
  int keyed_iterations = -1;

  /// Null means InterpolationEncoderInitializer.
  std::shared_ptr<const LatentInitializer> initializer;

  /// Foot locking after the overwrite (see the top of this file): the ramp in
  /// frames on each side of a contact; negative disables it.
  int foot_lock_ramp = kFootLockRamp;

  /// End-effector IK after the overwrite and the foot locking (see the top of
  /// this file): the falloff in frames on each side of a target; negative
  /// disables it (the targets are then only as close as the energy pulls them).
  int effector_falloff = kDefaultEffectorFalloff;

  /// Contact pins (MotionConstraints::contacts) are held after everything
  /// else with a ramp of this many frames on each side (tasks/fixups/foot_locking.h
  /// pin_contacts()).
  int contact_ramp = kDefaultContactRamp;

  /// Alternative solutions: Gaussian noise of this standard deviation is added
  /// to the initialiser's codes of every window (the prior's codes have unit
  /// variance), drawn from `start_seed` and the window's index; 0 = none.
  double start_noise = 0.0;
  uint64_t start_seed = 0;

  /// Diagnostics only: false returns the raw solution, without the overwrite
  /// of the known values (which then do not come out as given).
  bool overwrite_known = true;

  /// Frames shared by consecutive windows of long inputs (at least 1; at most
  /// half the model's window is used).
  int overlap = 32;

  /// Interpolation for the windows whose solution cannot reach the keys
  /// (tasks/latent/fallback.h); off unless enabled. Only with whole-pose keys
  /// and no start noise: other constraints are not interpolation's to meet.
  InterpolationFallback fallback;

  /// Empty when valid, else what is wrong (Ceres' Options::IsValid style).
  std::string validate() const;
};

/// The iteration caps of one window: `keyed` iterations of the keys-only
/// first stage (0: none), then at most `full` on the whole energy.
struct WindowCaps {
  int keyed = 0, full = 0;
};

/// The caps a window is solved with: the options' where they set them, else
/// the defaults. Adam: 600, a single stage. L-BFGS: a window with end-effector
/// targets or with 40 or more frames in a row without a key (long gaps) gets a
/// single stage of 60 iterations; any other window 30 keys-only iterations,
/// then 20 on the whole energy (without a keys-only stage: 40). Measured in
/// docs/BENCHMARKS.md ("Iteration caps") and docs/experiments/2026-12-07-solver-defaults.md: the
/// keys-only stage costs a fraction of a dense iteration and leaves the full
/// stage less to do on short gaps and sparse keys, while long gaps keep
/// improving up to 60 full iterations. `key_frames` are the window's key
/// frames (any order); T its length.
WindowCaps window_caps(const LatentSolverOptions& options, const std::vector<int>& key_frames, bool has_effectors,
                       int T);

/// The options of the registered methods: "nemf" (L-BFGS) and "nemf-adam".
LatentSolverOptions default_solver_options(LatentOptimizer optimizer = LatentOptimizer::Lbfgs);

struct LatentSolution {
  Eigen::VectorXf z_l;  ///< [zl]
  Eigen::VectorXf z_g;  ///< [zg]
  SolveSummary summary;  ///< wall_ms: the minimisation, initialisation excluded
};

/// Optimises the codes of one window from `start`. `iteration_offset` and
/// `iteration_total` only shape the progress reports (iteration =
/// offset + this window's iteration, max_iterations = total; 0 = this window's
/// cap). Throws InputError on invalid `options` (checked here, once per call;
/// complete_motion() checks its options once per request and solves its
/// windows without checking them again), CancelledError when the context asks
/// to stop.
LatentSolution solve_latents(const runtime::NemfRuntime& model, const RuntimeWindowProblem& problem,
                             const InitialGuess& start, const LatentSolverOptions& options, const TaskContext& ctx,
                             int iteration_offset = 0, int iteration_total = 0);

struct CompletionReport {
  std::vector<SolveSummary> windows;   ///< in solve order
  std::vector<int> window_starts;      ///< first frame of each window, in solve order
  ConstraintError raw_known;           ///< raw solution vs keys, before the overwrite
  EffectorError raw_effectors;         ///< raw solution vs end-effector targets
  EffectorError effectors;             ///< output vs end-effector targets (after the blend)
  std::vector<WindowTrust> trust;      ///< per window, in solve order: the fallback rule's view
  std::vector<std::string> warnings;   ///< constraints that could not hold exactly (contact pins), the fallback
  int iterations = 0;                  ///< summed over windows
  double wall_ms = 0.0;                ///< the whole call
};

/// Completes `input` under `constraints` (validated; unconstrained values of
/// the input are never read). The output has the input's skeleton, length and
/// fps. With ctx.diagnostics, each window's weighted energy terms before and
/// after its minimisation are appended to it ("initial.<term>",
/// "final.<term>"; one entry per window and term). Throws mf::InputError on bad constraints, a skeleton that does not
/// match the model or bad options; CancelledError when cancelled.
Motion complete_motion(const runtime::NemfRuntime& model, const Motion& input, const MotionConstraints& constraints,
                       const LatentSolverOptions& options, const TaskContext& ctx = {},
                       CompletionReport* report = nullptr);

}  // namespace mf
