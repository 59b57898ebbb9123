// In-betweening from C++ with motionfield.hpp, the header-only layer over the
// C API: the C sample's job (../c/inbetween.c) without its bookkeeping.
// Loads the default model (or, when none is installed, runs a baseline method
// and says so), keeps every 15th frame of a BVH clip as a keyframe, fills the
// frames between them and writes the result as BVH with the input's skeleton
// and channel layout. Failed calls throw motionfield::Error; handles free
// themselves.
//
//   usage: mf_sample_cpp [IN.bvh [OUT.bvh]]
//   (defaults: samples/walk_keyframes.bvh, walk_inbetween.bvh)
//
// Build it against an installed motionfield with CMake (CMakeLists.txt next to
// this file) or
//   c++ -std=c++17 inbetween.cc $(pkg-config --cflags --libs motionfield)
#include <cstdio>
#include <string>
#include <vector>

#include "motionfield.hpp"

namespace api = motionfield;

int main(int argc, char** argv) {
  const std::string in_path = argc > 1 ? argv[1] : "samples/walk_keyframes.bvh";
  const std::string out_path = argc > 2 ? argv[2] : "walk_inbetween.bvh";
  try {
    std::printf("motionfield %s (ABI %u)\n", api::version().c_str(), static_cast<unsigned>(api::abi_version()));
    if (api::abi_version() != MF_ABI_VERSION) {
      std::fprintf(stderr, "mf_sample_cpp: built against ABI %d, loaded ABI %u\n", MF_ABI_VERSION,
                   static_cast<unsigned>(api::abi_version()));
      return 1;
    }
    api::set_num_threads(1);
    std::printf("threads: 1\n");

    api::Model model;  // empty: no model, and a method that needs none
    const std::string model_path = api::default_model_path();
    if (!model_path.empty()) {
      model = api::Model::load(model_path);
      std::printf("model: %s\n", model_path.c_str());
    } else {
      std::printf("model: none found (set MF_MODEL or install one): running with a baseline method\n");
    }
    const std::string method = api::default_method(model);
    std::printf("method: %s\n", method.c_str());

    const api::Motion input = api::Motion::load_bvh(in_path);
    const int frames = input.frame_count();
    std::printf("input: %s, %d frames, %d joints\n", in_path.c_str(), frames, input.joint_count());

    std::vector<int32_t> keyframes;  // every 15th frame and the last one
    for (int f = 0; f < frames; f += 15) keyframes.push_back(f);
    if (keyframes.back() != frames - 1) keyframes.push_back(frames - 1);

    api::TaskOptions options;
    int progress_reports = 0;
    options.progress = [&](const mf_progress&) {
      ++progress_reports;
      return true;  // false would cancel
    };
    const api::Motion result = api::inbetween(model, input, keyframes, options);

    const std::vector<float> root = result.root_positions();
    std::printf("frame 7 root position: %.3f %.3f %.3f m\n", root[3 * 7], root[3 * 7 + 1], root[3 * 7 + 2]);
    result.save_bvh(out_path);
    std::printf("wrote %s: %d frames from %zu keyframes (method %s, %d progress reports)\n", out_path.c_str(),
                result.frame_count(), keyframes.size(), method.c_str(), progress_reports);
    return 0;
  } catch (const api::Error& e) {
    std::fprintf(stderr, "mf_sample_cpp: %s: %s\n", e.status_name(), e.what());
    return 1;
  }
}
