#include "tasks/latent/window_solver.h"

#include <string>
#include <utility>
#include <vector>

#include "tasks/latent/windows.h"

namespace mf {

Eigen::VectorXd minimize_window(DirectLatentEnergy& energy, const Eigen::VectorXd& x0,
                                const LatentOptimizerSettings& settings, const TaskContext& ctx, int iteration_offset,
                                int iteration_total, SolveSummary* summary, const FirstStage& first) {
  SolveSummary& s = *summary;
  s.initial_terms = energy.terms(x0.data(), &s.initial_energy);
  Eigen::VectorXd x = x0;
  if (first.energy && first.max_iterations > 0) {
    LatentOptimizerStats stats;
    x = minimize_latent(*first.energy, x, settings.capped(first.max_iterations), ctx, &stats, iteration_offset,
                        iteration_total);
    s.keyed_iterations = stats.iterations;
    s.evaluations += stats.evaluations;
  }
  LatentOptimizerStats stats;
  x = minimize_latent(energy, x, settings, ctx, &stats, iteration_offset + s.keyed_iterations, iteration_total);
  s.iterations = s.keyed_iterations + stats.iterations;
  s.evaluations += stats.evaluations;
  s.converged = stats.converged;
  s.message = stats.message;
  s.final_terms = energy.terms(x.data(), &s.final_energy);
  return x;
}

Eigen::VectorXd join_codes(const Eigen::VectorXf& z_l, const Eigen::VectorXf& z_g) {
  Eigen::VectorXd x(z_l.size() + z_g.size());
  x << z_l.cast<double>(), z_g.cast<double>();
  return x;
}

Eigen::VectorXf head_codes(const Eigen::VectorXd& x, int zl) { return x.head(zl).cast<float>(); }

Eigen::VectorXf tail_codes(const Eigen::VectorXd& x, int zg) { return x.tail(zg).cast<float>(); }

WindowSolver::WindowSolver(std::vector<WindowSpan> spans, const Skeleton& skeleton, int frames, double fps, int feet)
    : spans_(std::move(spans)), skeleton_(skeleton), frames_(frames), fps_(fps), feet_(feet) {}

WindowedSolution WindowSolver::solve(const TaskContext& ctx, const SolveWindowFn& solve_window) const {
  WindowedSolution out{Motion::identity(skeleton_, frames_, fps_),
                       std::vector<float>(static_cast<size_t>(frames_) * feet_, 0.0f), std::vector<char>(frames_, 0)};
  TaskContext window_ctx = ctx;  // reports carry the window
  window_ctx.window_count = static_cast<int>(spans_.size());
  for (size_t k = 0; k < spans_.size(); ++k) {
    window_ctx.window = static_cast<int>(k);
    const SolvedWindow window = solve_window(window_ctx.window, out, window_ctx, out.iterations);
    out.iterations += window.iterations;
    blend(spans_[k], window, &out);
  }
  return out;
}

// Written to the world, then copied where no window was solved before, and
// elsewhere weighing pos / (n + 1) at the pos-th of the n shared frames
// counted from the side away from the earlier windows.
void WindowSolver::blend(const WindowSpan& w, const SolvedWindow& window, WindowedSolution* out) const {
  Motion piece = Motion::identity(skeleton_, w.length, fps_);
  write_window(window.decoded.local_rotations.cast<double>(), window.decoded.root_positions.cast<double>(),
               window.transform, &piece, 0);
  const float* pc = window.decoded.contacts.data();
  const bool solved_before = w.shared_begin < w.shared_end && w.shared_begin == 0;
  const int n_ov = w.shared_end - w.shared_begin;
  for (int f = 0; f < w.length; ++f) {
    const int g = w.start + f;
    double wn = 1.0;
    if (out->solved[g]) {
      const int pos = solved_before ? f - w.shared_begin + 1 : w.shared_end - f;
      wn = static_cast<double>(pos) / (n_ov + 1);
    }
    cross_fade_frame(piece, f, wn, &out->motion, g);
    for (int k = 0; k < feet_; ++k) {
      float& c = out->contacts[static_cast<size_t>(g) * feet_ + k];
      c = static_cast<float>(c * (1.0 - wn) + pc[static_cast<size_t>(f) * feet_ + k] * wn);
    }
    out->solved[g] = 1;
  }
}

}  // namespace mf
