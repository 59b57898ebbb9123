// foreign-training-set: the training part of the foreign capture
// (bench/foreign_data.h; never its validation part) on the model's rig, as
// BVH files a trainer reads beside the training data: each clip retargeted
// with the product's own retargeter (tasks/context/model_rig.h, anatomy measured on
// the whole clip), at the model's frame rate, lowered onto the training data's
// floor (tasks/context/ground_level.h), in centimetres like the training data.
#include <filesystem>
#include <iostream>

#include "bench/foreign_data.h"
#include "bench/options.h"
#include "prior/runtime/nemf_runtime.h"
#include "prior/motion/motion_bvh.h"
#include "prior/util/command_line.h"
#include "tasks/context/ground_level.h"
#include "tasks/context/model_rig.h"

namespace {

struct Args {
  std::string model;
  std::string source = mf::default_foreign_archive();
  std::string cache_dir = mf::default_cache_dir();
  std::string out;
};

int run(const Args& args) {
  mf::TaskContext ctx;
  const std::string model_path = args.model.empty() ? mf::default_model_path() : args.model;
  ctx.model = std::make_shared<const mf::runtime::NemfRuntime>(mf::runtime::NemfRuntime::load(model_path));
  const std::shared_ptr<const mf::runtime::NemfRuntime> model = ctx.model;
  ctx.model_anatomy = mf::load_rig_anatomy_next_to(model_path, model->rig().skeleton);
  if (!ctx.model_anatomy) throw mf::InputError("no rig anatomy next to " + model_path);
  const double fps = model->config().fps;
  const mf::bench::ForeignData data = mf::bench::load_foreign_data(args.source, args.cache_dir, fps, true);
  std::filesystem::create_directories(args.out);
  mf::BvhUnits cm;
  const mf::BvhDocument layout = mf::default_bvh_layout(model->rig().skeleton, cm);
  for (const mf::bench::ForeignClip& c : data.train) {
    mf::Motion on_model = mf::model_retargeter(c.clip.motion, {}, ctx).to_model(c.clip.motion);
    std::vector<int> all(static_cast<size_t>(on_model.num_frames()));
    for (int f = 0; f < on_model.num_frames(); ++f) all[f] = f;
    mf::shift_root_heights(&on_model, mf::ground_heights(on_model, all, model->rig(), static_cast<int>(fps)), -1.0);
    std::string name = c.clip.name;
    for (char& ch : name)
      if (ch == '/') ch = '-';
    const std::string path = args.out + "/foreign-" + name;
    mf::write_motion(path, on_model, layout, cm);
    std::cerr << "wrote " << path << " (" << on_model.num_frames() << " frames)\n";
  }
  std::cerr << data.train.size() << " training clips written; " << data.validation.size()
            << " validation clips left out\n";
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Args args;
  CLI::App app{"Writes the foreign capture's training split on the model's rig (BVH, cm, the model's frame rate) "
               "for training beside the training data; the validation split is never written.",
               "foreign-training-set"};
  mf::cli::use_tool_defaults(app);
  app.add_option("--model", args.model, "the prior, with motionfield-rig.json next to it (default: the default model)");
  app.add_option("--source", args.source, "the foreign capture (folder or archive)");
  app.add_option("--cache-dir", args.cache_dir, "where an archive is extracted");
  app.add_option("--out", args.out, "output folder")->required();
  return mf::cli::run(app, argc, argv, [&] { return run(args); });
}
