#include "tasks/latent/energy_weights.h"

namespace mf {

ActiveTerms active_terms(const TermCounts& c, const EnergyWeights& w) {
  ActiveTerms a;
  a.n_rot = c.rotations;
  a.n_root_rot = c.root_rotations;
  a.n_pos = c.positions;
  a.n_root = c.root_positions;
  a.rot = w.rotation > 0 && a.n_rot > 0;
  a.root_rot = w.root_orientation > 0 && a.n_root_rot > 0;
  a.pos = w.position > 0 && a.n_pos > 0;
  a.root = w.root_translation > 0 && a.n_root > 0;
  a.eff = w.effector > 0 && c.effectors > 0;
  a.pin = w.contact > 0 && c.pin_steps > 0;
  a.skate = w.foot_skating > 0 && c.feet > 0 && c.length >= 2;
  a.smooth = w.smoothness > 0 && c.length >= 3;
  a.traj = w.trajectory > 0 && c.trajectory_rows > 0;
  a.facing = w.trajectory_facing > 0 && c.trajectory_rows > 0;
  a.dense = a.root || a.eff || a.pin || a.traj || a.facing || a.skate || a.smooth;
  a.keyed = a.rot || a.root_rot || a.pos;
  return a;
}

}  // namespace mf
