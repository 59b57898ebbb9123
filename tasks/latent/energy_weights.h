// The weights of the latent solvers' energy terms (tasks/reference/energies.h
// defines the terms) and which terms a window problem makes active: torch-free,
// shared by the Eigen energy (runtime_energy.h) and the libtorch reference
// (tasks/reference/energies.h), so both switch the same terms on.
#pragma once

namespace mf {

/// How residuals are penalised (see the top of tasks/reference/energies.h).
enum class Penalty { Squared, Absolute };

/// Weights of the energy terms (see the top of tasks/reference/energies.h for each
/// term's definition and unit). Defaults were chosen by measurement
/// (docs/experiments/2026-12-07-solver-defaults.md, "Energy weights").
struct EnergyWeights {
  double rotation = 5.0;
  double position = 10.0;
  double root_orientation = 1.0;
  double root_translation = 10.0;
  double effector = 100.0;
  double contact = 10.0;
  /// The trajectory terms' weights: docs/CONSTRAINTS.md ("Trajectory") has
  /// their measurement (trajectory-bench).
  double trajectory = 100.0;
  double trajectory_facing = 30.0;
  double latent_prior = 0.0;
  double foot_skating = 0.0;
  double smoothness = 0.0;
  Penalty penalty = Penalty::Squared;
  /// The dense output terms (effector, contact, trajectory, foot_skating,
  /// smoothness) see the
  /// motion as complete_motion() returns it: after the overwrite of the known
  /// values, whose residuals are blended into the frames between keys (see
  /// tasks/latent/latent_solver.h); otherwise the raw decoded motion.
  bool on_output = true;
};

/// What a window problem has for each term to average over: the constrained
/// items of the keys (non-root rotations, root rotations, positions, root
/// positions) and the counts of the other constraints.
struct TermCounts {
  double rotations = 0, root_rotations = 0, positions = 0, root_positions = 0;
  int effectors = 0, pin_steps = 0, trajectory_rows = 0;
  int feet = 0;    ///< the rig's
  int length = 0;  ///< the window's frames
};

/// Which terms are active (a positive weight and something to measure) and
/// how many items each averages over.
struct ActiveTerms {
  double n_rot = 0, n_root_rot = 0, n_pos = 0, n_root = 0;
  bool rot = false, root_rot = false, pos = false, root = false, eff = false, pin = false, skate = false,
       smooth = false;
  bool traj = false, facing = false;
  bool dense = false;  ///< a term that needs the whole window decoded
  bool keyed = false;  ///< a term that needs the key frames decoded
};

ActiveTerms active_terms(const TermCounts& counts, const EnergyWeights& w);

}  // namespace mf
