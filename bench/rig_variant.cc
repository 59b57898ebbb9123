// rig-variant: rewrites a BVH file on the training data's rig onto one of the
// synthetic rigs of bench/synthetic_rigs.h (other names, rest pose, units,
// channel orders, extra joints, frame rate), for tests and for trying the
// any-rig path by hand.
//
//   rig-variant --in IN.bvh --rig NAME --out OUT.bvh [--anatomy FILE] [--fps F]
//
// --anatomy: the rig anatomy of IN's rig (default: motionfield-rig.json next
// to the default model). Exit codes: 0 ok, 2 bad input, 1 internal error.
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "bench/synthetic_rigs.h"
#include "prior/model/model_file.h"
#include "prior/motion/errors.h"
#include "prior/util/command_line.h"
#include "tasks/context/model_rig.h"

namespace {

struct Args {
  std::string in, out, rig, anatomy;
  double fps = -1;
};

// The rig anatomy of the input's rig: --anatomy FILE, else the one next to the default model.
std::shared_ptr<const mf::RigAnatomy> input_anatomy(const std::string& path, const mf::Skeleton& skeleton) {
  if (path.empty()) {
    auto anatomy = mf::load_rig_anatomy_next_to(mf::default_model_path(), skeleton);
    if (!anatomy) throw mf::InputError("no motionfield-rig.json next to the default model: give --anatomy FILE");
    return anatomy;
  }
  std::ifstream f(path);
  std::ostringstream text;
  text << f.rdbuf();
  if (!f) throw mf::InputError(path + ": cannot read");
  return std::make_shared<mf::RigAnatomy>(mf::RigAnatomy::from_json(text.str(), skeleton, path));
}

int run(const Args& a) {
  mf::bench::RigVariant variant = mf::bench::rig_variant(a.rig);
  if (a.fps >= 0) variant.fps = a.fps;
  const mf::Motion motion = mf::read_motion(a.in);
  const std::shared_ptr<const mf::RigAnatomy> anatomy = input_anatomy(a.anatomy, motion.skeleton);
  const mf::bench::VariantMotion vm = mf::bench::make_variant(motion, *anatomy, variant);
  mf::write_motion(a.out, vm.motion, vm.layout, vm.units);
  std::printf("%s: %d joints, %d frames at %g fps, %g m per unit\n", a.out.c_str(), vm.motion.num_joints(),
              vm.motion.num_frames(), vm.motion.fps, vm.units.length_scale);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Args a;
  CLI::App app{"Rewrites a BVH file on the training data's rig onto a synthetic rig (bench/synthetic_rigs.h).",
               "rig-variant"};
  mf::cli::use_tool_defaults(app);
  app.add_option("--in", a.in, "the input BVH, on the training data's rig")->required();
  app.add_option("--rig", a.rig, "mixamo, cmu, lafan1, unreal, rigify, smpl or mixamo-rough")->required();
  app.add_option("--out", a.out, "the output BVH")->required();
  app.add_option("--anatomy", a.anatomy, "the rig anatomy of the input's rig (default: motionfield-rig.json next to "
                                         "the default model)");
  app.add_option("--fps", a.fps, "the output's frame rate (default: the synthetic rig's)")->default_str("");
  return mf::cli::run(app, argc, argv, [&] { return run(a); });
}
