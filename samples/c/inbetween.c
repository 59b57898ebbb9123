/*
 * In-betweening from C with motionfield's C API: loads the default model (or,
 * when none is installed, runs with a baseline method and says so), keeps
 * every 15th frame of a BVH clip as a keyframe, fills the frames between them
 * and writes the result as BVH with the input's skeleton and channel layout.
 *
 *   usage: mf_sample_c [IN.bvh [OUT.bvh]]
 *   (defaults: samples/walk_keyframes.bvh, walk_inbetween.bvh)
 *
 * Plain C89; build it against an installed motionfield with
 *   cc inbetween.c $(pkg-config --cflags --libs motionfield)
 * or with CMake (see CMakeLists.txt next to this file).
 */
#include <stdio.h>

#include "motionfield.h"

/* Prints the failed call's status and message and returns 1. */
static int report(const char *what, int status) {
  fprintf(stderr, "mf_sample_c: %s failed: %s: %s\n", what, mf_status_name(status), mf_last_error_message());
  return 1;
}

/* Progress callback: counts the reports; returning non-zero would cancel. */
static int on_progress(void *user_data, const mf_progress *progress) {
  int *calls = (int *)user_data;
  (void)progress;
  ++*calls;
  return 0;
}

int main(int argc, char **argv) {
  const char *in_path = argc > 1 ? argv[1] : "samples/walk_keyframes.bvh";
  const char *out_path = argc > 2 ? argv[2] : "walk_inbetween.bvh";
  mf_model *model = NULL;
  mf_motion *input = NULL, *result = NULL;
  mf_task_options options;
  const char *method = NULL;
  char model_path[4096];
  int32_t keyframes[256];
  int32_t frames = 0, joints = 0, f, result_frames = 0;
  size_t count = 0, needed = 0;
  int status, progress_calls = 0, exit_code = 1;
  float root[3];

  printf("motionfield %s (ABI %u)\n", mf_version_string(), (unsigned)mf_abi_version());
  if (mf_abi_version() != MF_ABI_VERSION) {
    fprintf(stderr, "mf_sample_c: built against ABI %d, loaded ABI %u\n", MF_ABI_VERSION, (unsigned)mf_abi_version());
    return 1;
  }
  mf_set_num_threads(1);
  printf("threads: 1\n");

  /* The default model, if there is one. */
  status = mf_model_default_path(model_path, sizeof model_path, &needed);
  if (status != MF_OK) return report("mf_model_default_path", status);
  if (model_path[0] != '\0') {
    status = mf_model_load(model_path, &model);
    if (status != MF_OK) return report("mf_model_load", status);
    printf("model: %s\n", model_path);
  } else {
    printf("model: none found (set MF_MODEL or install one): running with a baseline method\n");
  }
  status = mf_default_method(model, &method);
  if (status != MF_OK) {
    report("mf_default_method", status);
    goto done;
  }
  printf("method: %s\n", method);

  status = mf_motion_load_bvh(in_path, NULL, &input);
  if (status != MF_OK) {
    report("mf_motion_load_bvh", status);
    goto done;
  }
  mf_motion_get_frame_count(input, &frames);
  mf_motion_get_joint_count(input, &joints);
  printf("input: %s, %d frames, %d joints\n", in_path, (int)frames, (int)joints);

  /* Keyframes: every 15th frame and the last one. */
  for (f = 0; f < frames && count < 255; f += 15) keyframes[count++] = f;
  if (keyframes[count - 1] != frames - 1) keyframes[count++] = frames - 1;

  mf_task_options_init(&options);
  options.progress = on_progress;
  options.user_data = &progress_calls;
  status = mf_inbetween(model, input, keyframes, count, &options, &result);
  if (status != MF_OK) {
    report("mf_inbetween", status);
    goto done;
  }
  mf_motion_get_frame_count(result, &result_frames);

  /* One root position of an in-between frame, through the buffer protocol:
     ask for the size, then read (here into a fixed buffer of one frame). */
  {
    float positions[3 * 1024];
    size_t need = 0;
    status = mf_motion_get_root_positions(result, NULL, 0, &need);
    if (status == MF_OK && need <= sizeof positions / sizeof positions[0]) {
      mf_motion_get_root_positions(result, positions, need, &need);
      root[0] = positions[3 * 7];
      root[1] = positions[3 * 7 + 1];
      root[2] = positions[3 * 7 + 2];
      printf("frame 7 root position: %.3f %.3f %.3f m\n", root[0], root[1], root[2]);
    }
  }

  status = mf_motion_save_bvh(result, out_path, NULL);
  if (status != MF_OK) {
    report("mf_motion_save_bvh", status);
    goto done;
  }
  printf("wrote %s: %d frames from %d keyframes (method %s, %d progress reports)\n", out_path, (int)result_frames,
         (int)count, method, progress_calls);
  exit_code = 0;

done:
  mf_motion_destroy(result);
  mf_motion_destroy(input);
  mf_model_destroy(model);
  return exit_code;
}
