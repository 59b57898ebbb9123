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
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "bench/synthetic_rigs.h"
#include "prior/model/model_file.h"
#include "prior/motion/errors.h"
#include "tasks/model_rig.h"

int main(int argc, char** argv) {
  try {
    std::string in, out, rig, anatomy_path;
    double fps = -1;
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--help") {
        std::puts("usage: rig-variant --in IN.bvh --rig NAME --out OUT.bvh [--anatomy FILE] [--fps F]");
        return 0;
      }
      if (i + 1 >= argc) throw mf::InputError("option " + a + " needs a value");
      const std::string v = argv[++i];
      if (a == "--in") in = v;
      else if (a == "--out") out = v;
      else if (a == "--rig") rig = v;
      else if (a == "--anatomy") anatomy_path = v;
      else if (a == "--fps") fps = std::atof(v.c_str());
      else throw mf::InputError("unknown option " + a);
    }
    if (in.empty() || out.empty() || rig.empty()) throw mf::InputError("--in, --rig and --out are required");
    mf::bench::RigVariant variant = mf::bench::rig_variant(rig);
    if (fps >= 0) variant.fps = fps;
    const mf::Motion motion = mf::read_motion(in);
    std::shared_ptr<const mf::RigAnatomy> anatomy;
    if (anatomy_path.empty()) {
      anatomy = mf::load_rig_anatomy_next_to(mf::default_model_path(), motion.skeleton);
      if (!anatomy) throw mf::InputError("no motionfield-rig.json next to the default model: give --anatomy FILE");
    } else {
      std::ifstream f(anatomy_path);
      std::ostringstream text;
      text << f.rdbuf();
      if (!f) throw mf::InputError(anatomy_path + ": cannot read");
      anatomy = std::make_shared<mf::RigAnatomy>(mf::RigAnatomy::from_json(text.str(), motion.skeleton, anatomy_path));
    }
    const mf::bench::VariantMotion vm = mf::bench::make_variant(motion, *anatomy, variant);
    mf::write_motion(out, vm.motion, vm.layout, vm.units);
    std::printf("%s: %d joints, %d frames at %g fps, %g m per unit\n", out.c_str(), vm.motion.num_joints(),
                vm.motion.num_frames(), vm.motion.fps, vm.units.length_scale);
    return 0;
  } catch (const mf::InputError& e) {
    std::fprintf(stderr, "rig-variant: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "rig-variant: internal error: %s\n", e.what());
    return 1;
  }
}
