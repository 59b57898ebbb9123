// The window loop of every latent-space task: in-betweening, gap filling and
// resampling (complete_motion(), tasks/latent/latent_solver.h) and
// re-navigation (renavigate(), tasks/renav/renav.h). A motion longer than the
// model's window is solved window by window (window_starts(),
// tasks/latent/windows.h), in the order the task chooses. For each window the
// task builds its problem from the solution so far, picks the initial codes
// and minimises its energy of the codes (minimize_window(): one stage, or a
// cheap first stage and then the full energy) and decodes the result; the
// WindowSolver places the decoded window in the world and cross-fades it into
// the solution over the frames it shares with windows solved before (SLERP /
// LERP, the window's weight rising linearly away from them, the foot contact
// probabilities of the global motion predictor alike), and counts the
// iterations, so that the progress reports of later windows continue.
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "prior/model/canonical_window.h"
#include "prior/motion/motion.h"
#include "tasks/context/task_context.h"
#include "tasks/latent/latent_optimizer.h"
#include "tasks/latent/window_problem.h"

namespace mf {

/// What one window's solve did.
struct SolveSummary {
  int iterations = 0;        ///< all stages
  int keyed_iterations = 0;  ///< of them, in the cheap first stage (the latent solver's keys-only stage)
  int evaluations = 0;       ///< energy evaluations (with or without gradient)
  bool converged = false;    ///< stopped by a tolerance, not by the iteration cap
  double initial_energy = 0.0;
  double final_energy = 0.0;
  std::vector<std::pair<std::string, double>> initial_terms;  ///< weighted, as in EnergyTerms
  std::vector<std::pair<std::string, double>> final_terms;
  /// Wall time: of the minimisation (complete_motion(), solve_latents()), or
  /// of the whole window, initialisation included (renavigate()).
  double wall_ms = 0.0;
  std::string message;       ///< the optimiser's stop reason
  /// The stages minimised the Eigen runtime's energy
  /// (tasks/latent/runtime_energy.h), not a reference one
  /// (TaskContext::reference; set by the task).
  bool runtime_energy = false;
};

/// An optional first stage of a window's minimisation on a cheaper energy.
struct FirstStage {
  DirectLatentEnergy* energy = nullptr;  ///< null: no first stage
  int max_iterations = 0;                ///< 0: no first stage
};

/// Minimises `energy` from x0 ([zl + zg]) with settings.optimizer: first,
/// when `first` has an energy and a positive cap, up to first.max_iterations
/// iterations on first.energy, then up to settings.max_iterations on
/// `energy`. Fills `summary` (the terms of `energy` before and after, the
/// iterations and evaluations of both stages, the last stage's convergence
/// and stop reason; not wall_ms nor runtime_energy) and returns the solution
/// x. Progress reports carry iteration = `iteration_offset` + the window's
/// iteration and max_iterations = `iteration_total` (minimize_latent(),
/// tasks/latent/latent_optimizer.h). Throws CancelledError when the context
/// asks to stop.
Eigen::VectorXd minimize_window(DirectLatentEnergy& energy, const Eigen::VectorXd& x0,
                                const LatentOptimizerSettings& settings, const TaskContext& ctx, int iteration_offset,
                                int iteration_total, SolveSummary* summary, const FirstStage& first = {});

/// x = [z_l, z_g] of the codes, and the codes of x.
Eigen::VectorXd join_codes(const Eigen::VectorXf& z_l, const Eigen::VectorXf& z_g);
Eigen::VectorXf head_codes(const Eigen::VectorXd& x, int zl);
Eigen::VectorXf tail_codes(const Eigen::VectorXd& x, int zg);

/// A window of a solve: output frames [start, start + length); its window
/// frames [shared_begin, shared_end) are also in windows solved before it
/// (none when shared_begin >= shared_end).
struct WindowSpan {
  int start = 0, length = 0;
  int shared_begin = 0, shared_end = 0;
};

/// A window's solution as a task hands it to the WindowSolver.
struct SolvedWindow {
  DecodedWindow decoded;      ///< canonical
  GroundTransform transform;  ///< canonical -> world
  int iterations = 0;         ///< the optimiser's, all stages
};

/// The solution of a windowed solve.
struct WindowedSolution {
  Motion motion;
  std::vector<float> contacts;  ///< [frames, feet], cross-faded like the poses
  std::vector<char> solved;     ///< per frame: covered by a window solved so far
  int iterations = 0;           ///< summed over the windows solved so far
};

class WindowSolver {
 public:
  /// Solves window `index` of the spans. `so_far` holds the windows solved
  /// before; `ctx` is the task's context with the window and window count
  /// set, for the optimiser's progress reports; `iteration_offset` is
  /// so_far.iterations.
  using SolveWindowFn = std::function<SolvedWindow(int index, const WindowedSolution& so_far, const TaskContext& ctx,
                                                   int iteration_offset)>;

  /// An output of `frames` frames at `fps` on `skeleton` with `feet` foot
  /// contact channels, covered by `spans` in solve order.
  WindowSolver(std::vector<WindowSpan> spans, const Skeleton& skeleton, int frames, double fps, int feet);

  const std::vector<WindowSpan>& spans() const { return spans_; }

  /// Solves the windows one after the other and joins their solutions.
  /// Exceptions of `solve_window` (CancelledError, InputError) propagate.
  WindowedSolution solve(const TaskContext& ctx, const SolveWindowFn& solve_window) const;

 private:
  void blend(const WindowSpan& span, const SolvedWindow& window, WindowedSolution* out) const;

  std::vector<WindowSpan> spans_;
  Skeleton skeleton_;
  int frames_ = 0;
  double fps_ = 0.0;
  int feet_ = 0;
};

}  // namespace mf
