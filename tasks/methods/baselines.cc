// The non-learned methods (method.h: baseline_methods()): interpolation,
// zero velocity and the cubic spline of prior/motion/interpolation.h, and
// interpolation under partial keys (tasks/constraints/interpolation_fill.h).
#include <string>

#include "prior/motion/errors.h"
#include "tasks/constraints/interpolation_fill.h"
#include "tasks/fixups/effector_ik.h"
#include "tasks/fixups/foot_locking.h"
#include "tasks/methods/method.h"

namespace mf {

std::vector<Method> baseline_methods() {
  Method interp;
  interp.name = "interp";
  interp.description = "root LERP and rotation SLERP between known frames";
  interp.complete = [](const Motion& in, const std::vector<int>& known, const TaskContext&, CompletionNotes*) {
    return interpolate_motion(in, known);
  };
  interp.complete_constrained = [](const Motion& in, const MotionConstraints& c, int variant, const TaskContext&,
                                   std::vector<std::string>* warnings) {
    if (variant > 0) throw InputError("method 'interp' has a single solution: alternatives need a latent solver");
    Motion out = fill_by_interpolation(in, c);
    reach_effectors(c, kDefaultEffectorFalloff, &out);
    for (std::string& w : pin_contacts(c, kDefaultContactRamp, &out)) warnings->push_back(std::move(w));
    return out;
  };
  interp.resample = [](const Motion& in, double fps, int frames, const TaskContext&, std::vector<std::string>*) {
    return resample_interpolate(in, fps, frames);
  };
  Method zerovel;
  zerovel.name = "zerovel";
  zerovel.description = "hold the last known frame (zero velocity)";
  zerovel.complete = [](const Motion& in, const std::vector<int>& known, const TaskContext&, CompletionNotes*) {
    return zero_velocity_motion(in, known);
  };
  zerovel.resample = [](const Motion& in, double fps, int frames, const TaskContext&, std::vector<std::string>*) {
    return resample_zero_velocity(in, fps, frames);
  };
  Method cubic;
  cubic.name = "cubic";
  cubic.description = "Catmull-Rom spline through the input frames (resampling)";
  cubic.resample = [](const Motion& in, double fps, int frames, const TaskContext&, std::vector<std::string>*) {
    return resample_cubic(in, fps, frames);
  };
  Method quintic;
  quintic.name = "quintic";
  quintic.description = "local quintic interpolation through the six nearest input frames (resampling)";
  quintic.resample = [](const Motion& in, double fps, int frames, const TaskContext&, std::vector<std::string>*) {
    return resample_quintic(in, fps, frames);
  };
  return {interp, zerovel, cubic, quintic};
}

}  // namespace mf
