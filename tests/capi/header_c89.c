/* motionfield.h must compile as C89 with -pedantic -Wall -Wextra -Werror. This
   file also uses the declarations (types, callbacks, options) the way a C89
   caller would. */
#include "motionfield.h"

static int on_progress(void *user_data, const mf_progress *p) {
  (void)user_data;
  return p->iteration > 100 ? 1 : 0;
}

int use_motionfield(const char *path);

int use_motionfield(const char *path) {
  mf_model *model = NULL;
  mf_motion *input = NULL, *out = NULL;
  mf_task_options options;
  mf_bvh_options bvh;
  mf_codec_options codec;
  int32_t keys[2];
  float buffer[16];
  size_t needed = 0;
  int status;

  keys[0] = 0;
  keys[1] = 10;
  mf_task_options_init(&options);
  mf_bvh_options_init(&bvh);
  mf_codec_options_init(&codec);
  options.progress = on_progress;
  options.method = "interp";
  status = mf_model_load(NULL, &model);
  if (status != MF_OK && status != MF_ERROR_IO) return 1;
  status = mf_motion_load_bvh(path, &bvh, &input);
  if (status != MF_OK) return 1;
  status = mf_inbetween(model, input, keys, 2, &options, &out);
  if (status == MF_OK) status = mf_motion_get_rotations(out, buffer, 16, &needed);
  mf_motion_destroy(out);
  mf_motion_destroy(input);
  mf_model_destroy(model);
  return status == MF_ERROR_BUFFER_TOO_SMALL ? (int)needed : status;
}
