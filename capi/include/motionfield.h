/*
 * motionfield.h: the stable C interface of motionfield, a learned human-motion
 * prior (a NeMF-style implicit motion field) with task solvers for keyframe
 * in-betweening, gap filling and resampling.
 *
 * This is the only public header and libmotionfield.so the only public library.
 * It is plain C89 and compiles as C++; every exported name starts with "mf_"
 * (macros with "MF_").
 *
 * ---------------------------------------------------------------- conventions
 *
 * Units and axes. Lengths are metres, times seconds, angles radians. Y is up and
 * the ground is the XZ plane at y = 0. Rotations are unit quaternions stored
 * (w, x, y, z) (Hamilton convention, rotating column vectors: v' = q v q^-1). A
 * joint's local rotation maps its own frame into its parent's frame; the global
 * transform of joint j is G_j = G_parent(j) * T(offset_j) * R_j, and the root
 * (joint 0) uses its per-frame root position instead of its offset.
 *
 * Arrays. Bulk data is exchanged through caller-owned, row-major float buffers:
 *   rotations        [frames][joints][4]  (w, x, y, z)
 *   root positions   [frames][3]          (x, y, z), metres, world frame
 *   joint offsets    [joints][3]          metres, in the parent's frame
 *   global positions [frames][joints][3]  metres, world frame
 * Getters take the buffer, its capacity in elements and an optional `needed`
 * out-param that receives the number of elements the result has:
 *   - out == NULL and capacity == 0: a size query; *needed is set, MF_OK.
 *   - capacity < needed: MF_ERROR_BUFFER_TOO_SMALL, *needed is set and the
 *     buffer is not touched.
 *   - otherwise the first `needed` elements are written, MF_OK.
 * String getters work the same way with capacities in bytes; `needed` counts
 * the terminating NUL. The library never hands out memory the caller must
 * free: the strings it returns as `const char *` are static and live as long
 * as the library is loaded.
 *
 * Status codes. Every fallible function returns an int status: MF_OK (0) or
 * one of the MF_ERROR_* codes below. On failure a message for the user is
 * available from mf_last_error_message() on the same thread, and out-params
 * and caller buffers are left untouched (the one exception: `needed` is set on
 * MF_ERROR_BUFFER_TOO_SMALL). No C++ exception ever crosses this interface.
 *
 * Handles. Objects are opaque handles created through an out-param and freed
 * by a *_destroy() function that accepts NULL. There is no global
 * initialisation call. A loaded model and a motion are immutable: one handle
 * may be used from any number of threads at once. Functions that take handles
 * never keep references to the caller's buffers after they return.
 *
 * Options. Options structs start with `uint32_t struct_size` and have an
 * mf_*_options_init() function that sets struct_size to sizeof the struct as
 * this header declares it and every other field to its default, which is
 * always zero (or NULL). Passing NULL instead of an options struct means all
 * defaults. The library reads only the first struct_size bytes, so callers
 * compiled against an older header keep working; a struct from a newer header
 * (struct_size larger than the library knows) is accepted when the fields this
 * library does not know are zero, and rejected with MF_ERROR_UNSUPPORTED
 * otherwise.
 *
 * Threads. A task's numeric work runs on the thread that called it: its
 * products with a network's weight on the library's own kernels (where the
 * CPU has AVX2 + FMA or AVX-512), its other matrix products on the BLAS's
 * pool, whose size mf_set_num_threads() sets for the whole process. Tasks may be run from
 * several threads at once on one shared model; each gives the same result as
 * when run alone with the same thread count. Progress callbacks run on the
 * thread that called the task.
 *
 * Versioning. Functions are only ever appended; MF_ABI_VERSION changes (with
 * the SONAME, libmotionfield.so.<MF_ABI_VERSION>) only when an existing
 * function or struct would have to change.
 */
#ifndef MOTIONFIELD_H
#define MOTIONFIELD_H

#include <stddef.h>
#include <stdint.h>

#if defined(_WIN32)
#  if defined(MF_BUILDING_LIBRARY)
#    define MF_API __declspec(dllexport)
#  else
#    define MF_API __declspec(dllimport)
#  endif
#elif defined(__GNUC__) && __GNUC__ >= 4
#  define MF_API __attribute__((visibility("default")))
#else
#  define MF_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ================================================================ handles */

/** A loaded model (the prior). Immutable; share it between threads. */
typedef struct mf_model mf_model;
/** A skeleton with per-frame local rotations and root positions. Immutable. */
typedef struct mf_motion mf_motion;
/** A flag that stops a running task from any thread. */
typedef struct mf_cancel_token mf_cancel_token;
/** A motion encoded by a model as a sequence of window latents. Immutable. */
typedef struct mf_encoding mf_encoding;

/* ================================================================ version */

#define MF_VERSION_MAJOR 0
#define MF_VERSION_MINOR 4
#define MF_VERSION_PATCH 0
/** MAJOR * 10000 + MINOR * 100 + PATCH */
#define MF_VERSION_NUMBER (MF_VERSION_MAJOR * 10000 + MF_VERSION_MINOR * 100 + MF_VERSION_PATCH)
#define MF_VERSION_STRING "0.4.0"
/** The ABI major: the N of libmotionfield.so.N. */
#define MF_ABI_VERSION 0

/** MF_ABI_VERSION of the loaded library (compare with the header's). */
MF_API uint32_t mf_abi_version(void);
/** MF_VERSION_NUMBER of the loaded library. */
MF_API uint32_t mf_version_number(void);
/** MF_VERSION_STRING of the loaded library, e.g. "0.2.0". Never NULL. */
MF_API const char *mf_version_string(void);

/* ================================================================ status */

#define MF_OK 0
/** A NULL pointer, a value out of range, malformed input (a BVH file that does
 *  not parse, keyframes out of order, a non-finite number, joint counts that do
 *  not match, an unknown method name, ...). */
#define MF_ERROR_INVALID_ARGUMENT 1
/** A caller buffer is smaller than the result; `needed` tells the size. */
#define MF_ERROR_BUFFER_TOO_SMALL 2
/** A file could not be opened, read or written (or no default model exists). */
#define MF_ERROR_IO 3
/** A model file is not a valid motionfield model (bad magic, truncated,
 *  corrupted, wrong version or kind), or a method needs a model and none was
 *  given. */
#define MF_ERROR_MODEL 4
/** A progress callback returned non-zero or the cancel token was cancelled. */
#define MF_ERROR_CANCELLED 5
/** A bug in motionfield; the message says what happened. */
#define MF_ERROR_INTERNAL 6
/** The request needs something this library does not have (an options field
 *  from a newer header set to a non-default value, ...). */
#define MF_ERROR_UNSUPPORTED 7
/** Memory could not be allocated. */
#define MF_ERROR_OUT_OF_MEMORY 8

/** The message of the most recent failed call on this thread ("" if none has
 *  failed yet). Never NULL; valid until the next failing call on this thread.
 *  Successful calls leave it unchanged. */
MF_API const char *mf_last_error_message(void);
/** The name of a status code ("MF_OK", "MF_ERROR_IO", ...; "MF_ERROR_UNKNOWN"
 *  for a code this library does not define). Never NULL. */
MF_API const char *mf_status_name(int status);

/** The longest message the library records, in bytes (without the NUL). */
#define MF_MESSAGE_MAX_BYTES 4096

/* Messages (mf_last_error_message) quote file names and bytes of the input;
 * the library records them in a form that is safe to
 * print on a terminal: bytes that are not printable UTF-8 (control characters
 * and escape sequences, invalid UTF-8, C1 controls, bidirectional overrides)
 * are escaped as \n, \t, \r, \xNN or \uNNNN (a backslash itself is kept),
 * and text longer than MF_MESSAGE_MAX_BYTES keeps its start and its end around
 * "... (N bytes left out) ...". Applying the form twice changes nothing. */

/** `text` (`length` bytes, NULs allowed) in that form, for clients that print
 *  messages of their own with file names or input in them. A string getter
 *  (see "Arrays"); text == NULL is allowed with length 0. */
MF_API int mf_printable_text(const char *text, size_t length, char *out, size_t capacity, size_t *needed);

/* ================================================================ threads */

/** Sets the number of threads of the matrix products in this process
 *  (1..1024): the size of the BLAS library's own thread pool (OpenBLAS's,
 *  process-wide). Every task runs its numeric work on its calling thread
 *  and, until this is called, multiplies matrices there too (the pool held at
 *  one thread). More threads pay only for long windows on an otherwise idle
 *  machine; to run several tasks at once, call them from several threads.
 *  Results may differ in the last bits between thread counts. */
MF_API int mf_set_num_threads(int32_t num_threads);
/** The count set by mf_set_num_threads(), else 1. */
MF_API int mf_get_num_threads(int32_t *out);

/* ================================================================ cancel, progress */

MF_API int mf_cancel_token_create(mf_cancel_token **out);
/** Asks every task that uses the token to stop (thread-safe; the task returns
 *  MF_ERROR_CANCELLED at its next check). The token stays cancelled until reset. */
MF_API int mf_cancel_token_cancel(mf_cancel_token *token);
/** Clears the flag so that the token can be used again. */
MF_API int mf_cancel_token_reset(mf_cancel_token *token);
/** *out = 1 if cancelled, else 0. */
MF_API int mf_cancel_token_is_cancelled(const mf_cancel_token *token, int32_t *out);
/** Destroys the token (NULL is fine). No task may still be using it. */
MF_API void mf_cancel_token_destroy(mf_cancel_token *token);

/** What a progress callback is told. Filled by the library; struct_size is the
 *  size the library filled, so read only fields that fit in it. */
typedef struct mf_progress {
  uint32_t struct_size;
  /** Iterations done so far (0 before the work starts). */
  int32_t iteration;
  /** Total iterations if known, else 0. */
  int32_t max_iterations;
  /** The solver's current energy (0 for methods without one). */
  double energy;
  /** Since 0.1 (appended): the window being solved (0-based) and the number
   *  of windows of a long clip solved window by window (iterations and
   *  max_iterations are summed over the windows); 0 and 0 for methods that
   *  do not work in windows. */
  int32_t window;
  int32_t window_count;
} mf_progress;

/** Progress callback: called on the task's thread before the work starts and
 *  now and then during long methods. Return 0 to continue, non-zero to cancel
 *  (the task then returns MF_ERROR_CANCELLED and produces nothing). */
typedef int (*mf_progress_fn)(void *user_data, const mf_progress *progress);

/* ================================================================ methods */

/** The method needs a model (the prior). */
#define MF_METHOD_NEEDS_MODEL 1u
/** The method does in-betweening and gap filling. */
#define MF_METHOD_COMPLETES 2u
/** The method does resampling. */
#define MF_METHOD_RESAMPLES 4u

/** Number of registered methods ("interp", "zerovel", the prior's, ...). */
MF_API int mf_method_count(int32_t *out);
/** Facts about method `index` (0 <= index < mf_method_count()). Each out-param
 *  may be NULL; the strings are static. `flags` is a combination of
 *  MF_METHOD_* bits. */
MF_API int mf_method_get(int32_t index, const char **name, const char **description, uint32_t *flags);
/** Index of the method named `name`; MF_ERROR_INVALID_ARGUMENT naming the
 *  available methods if there is none. */
MF_API int mf_method_find(const char *name, int32_t *index);
/** The method used for in-betweening and gap filling when an options struct
 *  gives none: the best measured method that can run with `model` (which may
 *  be NULL: then a method that does not need one): "nemf-detail" when the
 *  model has the two-stage transformer, "nemf" with the prior alone, "interp"
 *  without a model. Resampling without a method uses "prior" with a model and
 *  "quintic" (local quintic interpolation) without. mf_solve with constraints that carry a trajectory uses
 *  "nemf-refine" instead when the model has the keyframe transformer
 *  (mf_solution_get_method says which ran). The string is static. */
MF_API int mf_default_method(const mf_model *model, const char **name);

/* ================================================================ model */

/** Path of the default model: $MF_MODEL if set, else the model installed next
 *  to the library (<prefix>/share/motionfield/motionfield-prior.mfm), else the
 *  source tree's models/motionfield-prior.mfm; "" (and MF_OK) when none exists.
 *  A string getter (see "Arrays" above). */
MF_API int mf_model_default_path(char *out, size_t capacity, size_t *needed);

/** Loads a model file (.mfm). path == NULL loads the default model
 *  (MF_ERROR_IO if there is none). MF_ERROR_IO if the file cannot be read,
 *  MF_ERROR_MODEL if it is not a valid model. The transformer files next to
 *  it are loaded too (see below), and so is the anatomy of the prior's rig,
 *  motionfield-rig.json, which lets the prior's methods serve motions on other
 *  humanoid rigs (see "Other rigs" below; a broken anatomy file does not stop
 *  the load: tasks on other rigs then fail with MF_ERROR_MODEL saying why). */
MF_API int mf_model_load(const char *path, mf_model **out);
/** Loads a model from the bytes of a model file (copied; the buffer may be
 *  freed after the call). No transformer is loaded with it (see
 *  mf_model_with_inbetweener), and no rig anatomy: such a handle serves only
 *  motions on the model's own skeleton. */
MF_API int mf_model_load_from_memory(const void *data, size_t size, mf_model **out);
/** Destroys a model (NULL is fine). Motions and tasks do not need it to stay
 *  alive once they have returned. */
MF_API void mf_model_destroy(mf_model *model);

/* The transformer in-betweeners (methods "context", "detail", "citl" and the
 * solver methods "nemf-context", "nemf-detail", "nemf-citl") live in their own
 * files: motionfield-twostage.mfm (kind "twostage") and motionfield-citl.mfm
 * (kind "citl"). mf_model_load also loads whichever of the two exist in the
 * prior file's directory (for the default model too); a model handle without
 * them works for every other method, and a method that needs a missing one
 * fails with MF_ERROR_MODEL naming the file (and, when the file was there,
 * why it did not load). */

/** A new model handle: `model`'s prior and transformers plus the transformer
 *  file at `path` (its kind is read from the file and replaces the handle's
 *  transformer of that kind). `model` is unchanged. MF_ERROR_IO if the file
 *  cannot be read, MF_ERROR_MODEL if it is not a transformer model file or
 *  its skeleton is not the prior's. */
MF_API int mf_model_with_inbetweener(const mf_model *model, const char *path, mf_model **out);
/** *out = 1 if `model` has the transformer of `kind` ("twostage" or "citl"),
 *  else 0. MF_ERROR_INVALID_ARGUMENT for any other kind. */
MF_API int mf_model_has_inbetweener(const mf_model *model, const char *kind, int32_t *out);

/** What a model handle holds and what did not load with it, as JSON text (a
 *  string getter, UTF-8):
 *    {"format_version": 1,            (of the prior's model file)
 *     "joints": 21, "fps": 30, "window": 128,
 *     "inbetweeners": {"twostage": {"file": "motionfield-twostage.mfm",
 *                                   "loaded": true, "error": ""}, ...},
 *     "rig_anatomy": true, "rig_anatomy_error": ""}
 *  One entry per transformer kind: "loaded" false with "error" "" when its
 *  file was absent, with the reason when a file was there but did not load
 *  (a truncated file, another skeleton): mf_model_load goes on without it, and
 *  the default method (mf_default_method) is then chosen without it. */
MF_API int mf_model_describe(const mf_model *model, char *out, size_t capacity, size_t *needed);

/** The model's skeleton: joint count, names, parent indices (-1 for the root,
 *  joint 0) and rest offsets [joints][3] in metres. */
MF_API int mf_model_get_joint_count(const mf_model *model, int32_t *out);
MF_API int mf_model_get_joint_name(const mf_model *model, int32_t joint, char *out, size_t capacity, size_t *needed);
MF_API int mf_model_get_parents(const mf_model *model, int32_t *out, size_t capacity, size_t *needed);
MF_API int mf_model_get_offsets(const mf_model *model, float *out, size_t capacity, size_t *needed);
/** Frame rate of the training data (frames per second). */
MF_API int mf_model_get_fps(const mf_model *model, double *out);
/** Frames per window: the longest span one latent code describes. */
MF_API int mf_model_get_window(const mf_model *model, int32_t *out);
/** Sizes of the local (pose) and global (root orientation) latent codes. */
MF_API int mf_model_get_latent_sizes(const mf_model *model, int32_t *local_size, int32_t *global_size);

/* ================================================================ motion */

/** BVH reading and writing options. */
typedef struct mf_bvh_options {
  uint32_t struct_size;
  /** Metres per file length unit. 0 when reading: detected from the
   *  skeleton's leg length (cm, m, mm, in, ft or CMU's ASF unit; centimetres
   *  when no humanoid legs are found), see mf_motion_get_length_scale. 0 when
   *  writing: the scale the motion (or its task input) was read with. */
  double length_scale;
} mf_bvh_options;

MF_API int mf_bvh_options_init(mf_bvh_options *options);

/** A motion on an explicit skeleton. joint_names: joint_count NUL-terminated
 *  unique names; parents: joint_count indices, -1 for joint 0 (the only root),
 *  every parent before its child; offsets: [joint_count][3] metres;
 *  frame_count >= 1; fps finite and positive; rotations
 *  [frame_count][joint_count][4] (w, x, y, z; normalised by consumers, norm at
 *  least 1e-6); root_positions [frame_count][3]. Every number must be finite.
 *  The arrays are copied. */
MF_API int mf_motion_create(int32_t joint_count, const char *const *joint_names, const int32_t *parents,
                            const float *offsets, int32_t frame_count, double fps, const float *rotations,
                            const float *root_positions, mf_motion **out);
/** The same on the model's skeleton; joint_count must equal the model's. */
MF_API int mf_motion_create_for_model(const mf_model *model, int32_t joint_count, int32_t frame_count, double fps,
                                      const float *rotations, const float *root_positions, mf_motion **out);
/** The same on the skeleton of `like` (joint_count must equal its joint
 *  count); the new motion also keeps the BVH layout of `like`. */
MF_API int mf_motion_create_like(const mf_motion *like, int32_t joint_count, int32_t frame_count, double fps,
                                 const float *rotations, const float *root_positions, mf_motion **out);

/** Reads a BVH file (any channel order, position channels on any joint, End
 *  Sites). MF_ERROR_IO if it cannot be opened, MF_ERROR_INVALID_ARGUMENT with
 *  "<path>:<line>: ..." if it is malformed. The motion remembers the file's
 *  layout (hierarchy, channel order, frame time) for mf_motion_save_bvh. */
MF_API int mf_motion_load_bvh(const char *path, const mf_bvh_options *options, mf_motion **out);
/** The same from BVH text in memory (`size` bytes, no NUL needed). */
MF_API int mf_motion_load_bvh_from_memory(const char *data, size_t size, const mf_bvh_options *options,
                                          mf_motion **out);
/** Writes a BVH file, atomically (through a temporary file and a rename). A
 *  motion that came from BVH, or from a task or mf_motion_create_like on one,
 *  keeps that file's hierarchy, channel layout and joint order, and its frame
 *  time as written when the frame rate is unchanged; other motions get a
 *  default layout (root "Xposition Yposition Zposition Zrotation Xrotation
 *  Yrotation", other joints "Zrotation Xrotation Yrotation"). */
MF_API int mf_motion_save_bvh(const mf_motion *motion, const char *path, const mf_bvh_options *options);
/** The same BVH text into a caller buffer (a string getter: capacity in bytes
 *  including the terminating NUL). */
MF_API int mf_motion_save_bvh_to_memory(const mf_motion *motion, const mf_bvh_options *options, char *out,
                                        size_t capacity, size_t *needed);
MF_API void mf_motion_destroy(mf_motion *motion);

MF_API int mf_motion_get_joint_count(const mf_motion *motion, int32_t *out);
MF_API int mf_motion_get_frame_count(const mf_motion *motion, int32_t *out);
MF_API int mf_motion_get_fps(const mf_motion *motion, double *out);
/** Seconds between frames as mf_motion_save_bvh writes them (for a motion read
 *  from BVH: the file's frame time as written, e.g. 0.0333333). */
MF_API int mf_motion_get_frame_time(const mf_motion *motion, double *out);
MF_API int mf_motion_get_joint_name(const mf_motion *motion, int32_t joint, char *out, size_t capacity,
                                    size_t *needed);
MF_API int mf_motion_get_parents(const mf_motion *motion, int32_t *out, size_t capacity, size_t *needed);
MF_API int mf_motion_get_offsets(const mf_motion *motion, float *out, size_t capacity, size_t *needed);
/** [frames][joints][4] local rotations (w, x, y, z). */
MF_API int mf_motion_get_rotations(const mf_motion *motion, float *out, size_t capacity, size_t *needed);
/** [frames][3] root positions, metres. */
MF_API int mf_motion_get_root_positions(const mf_motion *motion, float *out, size_t capacity, size_t *needed);
/** [frames][joints][3] global joint positions (forward kinematics), metres. */
MF_API int mf_motion_get_global_positions(const mf_motion *motion, float *out, size_t capacity, size_t *needed);

/** glTF formats (mf_gltf_options.format). */
#define MF_GLTF_AUTO 0     /**< from the file name: ".glb" binary, ".gltf" JSON */
#define MF_GLTF_BINARY 1   /**< .glb: JSON and binary chunks in one file */
#define MF_GLTF_EMBEDDED 2 /**< .gltf: JSON text, the buffer embedded as base64 */

/** glTF writing options. */
typedef struct mf_gltf_options {
  uint32_t struct_size;
  /** MF_GLTF_AUTO (0, the default): from the path's extension (".glb" or
   *  ".gltf", any case; another name is MF_ERROR_INVALID_ARGUMENT), binary
   *  for mf_motion_save_gltf_to_memory. MF_GLTF_BINARY or MF_GLTF_EMBEDDED
   *  whatever the name. */
  int32_t format;
} mf_gltf_options;

MF_API int mf_gltf_options_init(mf_gltf_options *options);
/** Writes the motion as glTF 2.0, atomically: a skin-less armature, one node
 *  per joint named after it (node j = joint j, children as in the skeleton,
 *  translation = the joint's rest offset, rotation identity; the scene's root
 *  is joint 0), and one animation "motion" with LINEAR samplers at the frame
 *  times (frame f at f / fps seconds): every joint's local rotation and joint
 *  0's translation (the root positions). Metres (a BVH's unit converted with
 *  the length scale it was read with, mf_motion_get_length_scale), seconds,
 *  Y up; 32-bit floats. MF_ERROR_IO if the file cannot be written;
 *  MF_ERROR_INVALID_ARGUMENT for an unknown extension with MF_GLTF_AUTO or a
 *  motion glTF cannot hold (a number beyond 32-bit floats). */
MF_API int mf_motion_save_gltf(const mf_motion *motion, const char *path, const mf_gltf_options *options);
/** The same bytes into a caller buffer (a buffer getter, see "Arrays": counts
 *  in bytes; the JSON of MF_GLTF_EMBEDDED has no terminating NUL). */
MF_API int mf_motion_save_gltf_to_memory(const mf_motion *motion, const mf_gltf_options *options, uint8_t *out,
                                         size_t capacity, size_t *needed);

/* ================================================================ motion files */

/** Motion file formats (mf_motion_load_options.format). */
#define MF_FORMAT_AUTO 0 /**< from the content, then the name (see mf_motion_load) */
#define MF_FORMAT_BVH 1
#define MF_FORMAT_GLTF 2 /**< glTF 2.0: .glb or .gltf */
#define MF_FORMAT_FBX 3  /**< FBX, binary or ASCII (read with assimp) */

/** Options of mf_motion_load (appended in 0.3). */
typedef struct mf_motion_load_options {
  uint32_t struct_size;
  /** MF_FORMAT_AUTO (0, the default) or the format to read the file as. */
  int32_t format;
  /** BVH: metres per file unit, as mf_bvh_options.length_scale (0: detected).
   *  Ignored for glTF (metres) and FBX (the file's UnitScaleFactor). */
  double length_scale;
  /** glTF and FBX: the name of the animation to read; NULL or "": the one at
   *  animation_index. */
  const char *animation;
  /** glTF and FBX: the index of the animation (0, the default: the first). */
  int32_t animation_index;
  /** glTF and FBX: the frame rate to sample the animation at (at most 1000);
   *  0 (the default): the keys' rate (one over the smallest interval between
   *  keys, e.g. 30 when keys are 1/30 s apart). */
  double fps;
} mf_motion_load_options;

MF_API int mf_motion_load_options_init(mf_motion_load_options *options);
/** Reads a motion file of any format motionfield reads: BVH (as
 *  mf_motion_load_bvh), glTF 2.0 (.glb or .gltf: a skinned or skin-less
 *  armature, the joints of its skin or the animated nodes) or FBX (binary or
 *  ASCII; its unit and up axis from the file's settings). The format is
 *  options->format, or (MF_FORMAT_AUTO) told from the content: "glTF" (GLB),
 *  "Kaydara FBX Binary" or "; FBX" (FBX), "HIERARCHY" (BVH), "{" (glTF JSON);
 *  else from the extension (.bvh, .glb, .gltf, .fbx). glTF and FBX
 *  animations are sampled from their first key to their last; rotations are
 *  made relative to the rest pose (whose rotations become identity, as in
 *  BVH), so bone orientations do not show; the root is the armature's top
 *  joint, or, as for BVH, the one child of a container joint whose
 *  translation carries the motion (an armature object, a "joint_Root"); the
 *  other joints keep their rest offsets. Such motions have no BVH layout: a
 *  BVH is written with the default one, in metres (glTF) or the FBX file's
 *  unit (mf_motion_get_length_scale). MF_ERROR_IO if the file cannot be
 *  read; MF_ERROR_INVALID_ARGUMENT with "<path>: <problem>" for a malformed
 *  file (truncated, no animation, no armature, two roots, NaN keys, counts
 *  beyond the limits). */
MF_API int mf_motion_load(const char *path, const mf_motion_load_options *options, mf_motion **out);
/** The same from `size` bytes in memory (named "<memory>" in messages; a glTF
 *  with external buffers cannot be read from memory). */
MF_API int mf_motion_load_from_memory(const uint8_t *data, size_t size, const mf_motion_load_options *options,
                                      mf_motion **out);

/* ================================================================ tasks */

/** Options of every task. Fields a task does not use are ignored. */
typedef struct mf_task_options {
  uint32_t struct_size;
  /** Method name (see mf_method_get); NULL or "" = mf_default_method(model). */
  const char *method;
  /** Seed of the method's random choices; equal seeds give equal results. */
  uint64_t seed;
  /** Optional progress callback and the pointer it is given. */
  mf_progress_fn progress;
  void *user_data;
  /** Optional cancel token (may be cancelled from another thread). */
  mf_cancel_token *cancel;
  /** A rig map as JSON text, {"user joint": "model joint" or null, ...}, that
   *  overrides the automatic map of an input on another rig onto the model's
   *  (only the joints it names; null leaves a user joint unmapped). NULL or ""
   *  = automatic. Used only by methods that need the model. */
  const char *rig_map;
  /** The same from a JSON file (MF_ERROR_IO if it cannot be read; errors in it
   *  are prefixed with the path). Giving both rig_map and rig_map_path is
   *  MF_ERROR_INVALID_ARGUMENT. */
  const char *rig_map_path;
  /** Since 0.1 (appended): the iteration budget of the methods that iterate
   *  (the latent solvers "nemf*", "prior" resampling, re-navigation): the
   *  most iterations of the full solve per window; 0 (the default) = each
   *  method's own. Must be >= 0; methods that do not iterate ignore it. */
  int32_t max_iterations;
  /** Since 0.4 (appended): non-zero keeps what the latent solvers ("nemf",
   *  "nemf-detail", ...) find even where their fit to the keys is poor. By
   *  default (0) in-betweening, gap filling and transitions with whole-pose
   *  keys take interpolation of the keys in such a window instead, and say so
   *  in the result's warnings ("interpolation was used: the prior could not
   *  reach the keys ..."; docs/API.md, "When the prior cannot reach the keys"). */
  int32_t no_fallback;
} mf_task_options;

MF_API int mf_task_options_init(mf_task_options *options);

/* Every task takes an optional model (NULL is fine for methods without
 * MF_METHOD_NEEDS_MODEL; a method that needs one fails with MF_ERROR_MODEL
 * without), an input motion that is not modified, optional options, and
 * returns a new motion through `out` on the input's skeleton (and BVH layout).
 * When the method needs the model, the input may be on any humanoid rig (see
 * "Other rigs" above). Unknown frames of the input are never read (they must
 * still be finite); known frames are copied exactly. */

/* Other rigs. Methods that need the model run on the model's skeleton at the
 * model's frame rate. An input on another humanoid skeleton (other joint
 * names, counts, rest pose, bone lengths or units) or at another frame rate is
 * retargeted to the model's rig, solved there, and brought back: the result is
 * on the input's skeleton and frame rate; joints the model lacks (fingers,
 * twist bones, props) are interpolated between the known frames. This needs
 * the model's rig anatomy (motionfield-rig.json next to the model file, loaded
 * by mf_model_load); without it, or when the skeleton is not a humanoid the
 * rig map understands, the task fails with MF_ERROR_INVALID_ARGUMENT saying
 * why (MF_ERROR_MODEL when the anatomy file is there but broken). Which user
 * joint plays which model joint is found from the joint names and the
 * hierarchy's shape; mf_task_options.rig_map / rig_map_path override it, and
 * mf_rig_describe shows it. */

/** Keyframe in-betweening: keyframes (0-based frame indices, strictly
 *  increasing, at least two, each in [0, frames)) are kept; every other frame
 *  is produced. The output has the input's length and frame rate. */
MF_API int mf_inbetween(const mf_model *model, const mf_motion *input, const int32_t *keyframes,
                        size_t keyframe_count, const mf_task_options *options, mf_motion **out);
/** Gap filling: frames gap_begin..gap_end-1 are unknown, every other frame is
 *  kept; 1 <= gap_begin < gap_end <= frames - 1. */
MF_API int mf_fill(const mf_model *model, const mf_motion *input, int32_t gap_begin, int32_t gap_end,
                   const mf_task_options *options, mf_motion **out);
/** Resampling to `fps`, keeping the time span: output frame i sits at i / fps
 *  seconds and the output has mf_resample_frame_count() frames. */
MF_API int mf_resample(const mf_model *model, const mf_motion *input, double fps, const mf_task_options *options,
                       mf_motion **out);
/** Frame count of resampling `frame_count` frames from fps_in to fps_out:
 *  (frame_count - 1) * fps_out / fps_in + 1, taken as the nearest integer when
 *  within 1e-5 relative of it (BVH frame times carry about six digits),
 *  otherwise rounded down; then *rounded (optional) is 1, else 0. */
MF_API int mf_resample_frame_count(int32_t frame_count, double fps_in, double fps_out, int32_t *out,
                                   int32_t *rounded);

/* ================================================================ encode, decode */

/* The prior as a codec. A motion (at least 2 frames, any frame rate, on the
 * model's skeleton: same joint names and parents) is resampled to the model's
 * frame rate if needed and cut into overlapping windows of
 * mf_model_get_window() model frames; each window is encoded to a local latent
 * (mf_model_get_latent_sizes: local_size floats) and a global latent
 * (global_size floats), the encoder's mean, so encoding is deterministic.
 * Decoding evaluates the decoder at any times (seconds from the motion's first
 * frame; times outside the encoded span hold the ends) and blends the windows
 * with raised-cosine weights. The root translation comes from the model's
 * global motion predictor (MF_ROOT_FROM_PRIOR) or from the encoded input's root
 * path (MF_ROOT_FROM_INPUT). */

#define MF_ROOT_FROM_PRIOR 0
#define MF_ROOT_FROM_INPUT 1

typedef struct mf_codec_options {
  uint32_t struct_size;
  /** Encoding: model frames between window starts, in [1, window - 1];
   *  0 = window / 2. */
  int32_t hop;
  /** Decoding: MF_ROOT_FROM_PRIOR (0, the default) or MF_ROOT_FROM_INPUT. */
  int32_t root_source;
} mf_codec_options;

MF_API int mf_codec_options_init(mf_codec_options *options);

/** Encodes `input` with `model`. The encoding keeps a reference to the model
 *  (the model handle itself may be destroyed) and the input's BVH layout. */
MF_API int mf_encode(const mf_model *model, const mf_motion *input, const mf_codec_options *options,
                     mf_encoding **out);
MF_API void mf_encoding_destroy(mf_encoding *encoding);

/** Number of windows. */
MF_API int mf_encoding_get_window_count(const mf_encoding *encoding, int32_t *out);
/** Seconds from the first to the last frame of the encoded input. */
MF_API int mf_encoding_get_duration(const mf_encoding *encoding, double *out);
/** [windows] start time of each window, seconds. */
MF_API int mf_encoding_get_window_times(const mf_encoding *encoding, double *out, size_t capacity, size_t *needed);
/** [windows][local_size] local latents. */
MF_API int mf_encoding_get_local_latents(const mf_encoding *encoding, float *out, size_t capacity, size_t *needed);
/** [windows][global_size] global latents. */
MF_API int mf_encoding_get_global_latents(const mf_encoding *encoding, float *out, size_t capacity, size_t *needed);
/** A copy of `encoding` with other latents (for editing or interpolating in
 *  latent space): local [windows][local_size] and global [windows][global_size]
 *  floats, `*_count` giving each array's length; NULL (with count 0) keeps
 *  that part. Every value must be finite. */
MF_API int mf_encoding_with_latents(const mf_encoding *encoding, const float *local_latents, size_t local_count,
                                    const float *global_latents, size_t global_count, mf_encoding **out);

/** Decodes at times i / fps, i = 0 .. frame_count - 1; frame_count 0 means
 *  the frames that fit the encoded input's time span,
 *  mf_resample_frame_count(input frames, input fps, fps). The motion is on
 *  the encoded input's skeleton and BVH layout, at `fps`. */
MF_API int mf_decode(const mf_encoding *encoding, double fps, int32_t frame_count, const mf_codec_options *options,
                     mf_motion **out);
/** Decodes at `time_count` (>= 1) arbitrary finite times (seconds, any order):
 *  one frame per time; the motion carries `fps` as its frame rate. */
MF_API int mf_decode_times(const mf_encoding *encoding, const double *times, size_t time_count, double fps,
                           const mf_codec_options *options, mf_motion **out);

/* ================================================================ re-navigation */

/* Re-navigation: a reference motion (on any humanoid rig, see "Other rigs"
 * above; at least 2 frames, any frame rate) and a new ground path give
 * a motion that follows the path in the reference's style, by optimising the
 * prior's latent codes (NeMF's energy: path L1 + soft-DTW divergence of the
 * joint positions in the heading frame + soft-DTW divergence of the
 * heading-vs-path-tangent signal, against the reference). Always needs a model.
 *
 * A path is `point_count` (>= 2) ground points (x, z) in metres, world frame,
 * as floats [point_count][2]; every value finite; a total length of at least
 * 1 mm. Either one point per output frame (MF_PATH_PER_FRAME) at
 * mf_renav_options.fps, or the vertices of a polyline (MF_PATH_POLYLINE)
 * resampled by arc length at constant speed to mf_renav_options.frame_count
 * frames (0: as many as walking it at the reference's mean ground speed
 * takes; MF_ERROR_INVALID_ARGUMENT if the reference barely moves). Paths
 * longer than the model's window are solved in overlapping windows that agree
 * where they overlap. A path walked faster or slower than the reference (by
 * more than 5 %, mean ground speeds) is followed with the reference played at
 * the path's pace, at most 2x faster or slower: its steps come quicker or
 * slower, its poses stay the reference's. The output has the reference's skeleton and BVH layout,
 * starts exactly at the path's first point, and has as many frames as the
 * (resampled) path at mf_renav_options.fps. On another rig than the model's,
 * the path stays in the reference's metres and joints the model lacks hold
 * their pose of the reference's first frame.
 *
 * Methods (mf_task_options.method): "nemf" (L-BFGS, the default; NULL or "")
 * and "nemf-adam" (NeMF's Adam reference, slower). The progress callback
 * reports iterations summed over windows; cancelling returns
 * MF_ERROR_CANCELLED. */

#define MF_PATH_PER_FRAME 0
#define MF_PATH_POLYLINE 1

typedef struct mf_renav_options {
  uint32_t struct_size;
  /** MF_PATH_PER_FRAME (0, the default) or MF_PATH_POLYLINE. */
  int32_t path_kind;
  /** MF_PATH_POLYLINE: output frames (>= 2); 0 = at the reference's mean
   *  ground speed. Must be 0 for MF_PATH_PER_FRAME. */
  int32_t frame_count;
  /** Frame rate of the path's points and of the output; 0 = the reference's. */
  double fps;
} mf_renav_options;

MF_API int mf_renav_options_init(mf_renav_options *options);

/** Re-navigates `reference` along `path_xz` ([point_count][2] floats, see
 *  above). `renav` and `options` may be NULL (defaults). MF_ERROR_MODEL
 *  without a model; MF_ERROR_INVALID_ARGUMENT for a bad path, a skeleton
 *  that cannot be retargeted to the model's or an unknown method. */
MF_API int mf_renav(const mf_model *model, const mf_motion *reference, const float *path_xz, size_t point_count,
                    const mf_renav_options *renav, const mf_task_options *options, mf_motion **out);

/** Reads a path CSV file into [points][2] floats (x, z, metres), a buffer
 *  getter (see "Arrays": `needed` counts floats, twice the points). Format:
 *  one "x,z" pair per line; an optional first line "x,z"; blank lines and
 *  lines starting with '#' are skipped. MF_ERROR_IO if the file cannot be
 *  read, MF_ERROR_INVALID_ARGUMENT "<path>:<line>: ..." on a malformed line
 *  or a non-finite value, or when fewer than two points remain. */
MF_API int mf_path_load_csv(const char *path, float *out, size_t capacity, size_t *needed);

/* ================================================================ units and rigs */

/** Metres per file unit of a motion read from BVH (the length_scale it was
 *  read with, given or detected); 0.01 for motions made from arrays. Tasks
 *  pass it on to their results, so files are written back in the input's
 *  unit. */
MF_API int mf_motion_get_length_scale(const mf_motion *motion, double *out);
/** Metres per unit of a length unit name: "cm", "m", "mm", "in", "ft" or "asf"
 *  (CMU's ASF/AMC unit, 1/0.45 inch). MF_ERROR_INVALID_ARGUMENT for any other
 *  name, listing these. */
MF_API int mf_length_unit_scale(const char *unit, double *out);
/** How `motion`'s rig is read and mapped onto `model`'s, as JSON text (a
 *  string getter, UTF-8):
 *    {"unit": "cm", "length_scale": 0.01, "unit_detected": true,
 *     "unit_from_file": false, "joints": 65,
 *     "map": {"user joint": "model joint", ...},       (model joint order)
 *     "how": {"model joint": "name" | "shape" | "map file", ...},
 *     "unmapped_user_joints": ["user joint", ...],
 *     "model_joints": ["model joint", ...],            (every model joint)
 *     "retargeting": true,
 *     "anatomy": "rest pose" | "known frames" | "model rig"}
 *  "unit" is the unit's name ("custom" for a length_scale that is none of
 *  mf_length_unit_scale's), "unit_detected" false when it was given or could
 *  not be detected (no humanoid legs found: centimetres), "unit_from_file"
 *  true when the file set it (glTF: metres, FBX: its UnitScaleFactor; added
 *  in 0.3), "joints" the
 *  motion's joint count, "retargeting" whether the model has the rig anatomy
 *  that tasks on another rig need, "anatomy" where the user's anatomical
 *  joint frames come from: the rig's rest pose when it is a T or A pose,
 *  otherwise the known frames of each task's input ("model rig": the
 *  model's own skeleton, not retargeted; docs/RIGS.md). `rig_map_json` (NULL or "" = automatic) as
 *  mf_task_options.rig_map. MF_ERROR_MODEL without a model;
 *  MF_ERROR_INVALID_ARGUMENT with the rig map's message when the skeleton
 *  cannot be mapped or the map is malformed. */
MF_API int mf_rig_describe(const mf_model *model, const mf_motion *motion, const char *rig_map_json, char *out,
                           size_t capacity, size_t *needed);

/* ================================================================ warnings */

/** What the task that made `motion` wants its caller to know although it
 *  succeeded, as sentences for the user, one per line ("" when there is
 *  nothing, and for motions not made by a task): today mf_resample's "...
 *  rounded down to N frames ..." when the target frame rate does not give a
 *  whole number of frames (see mf_resample_frame_count). A string getter. */
MF_API int mf_motion_get_warnings(const mf_motion *motion, char *out, size_t capacity, size_t *needed);

/* ================================================================ constraints and several solutions */

/* Beyond whole-pose keyframes: partial keys (some joints' local rotations, or
 * the root alone), end-effector world targets, and contacts the caller pins,
 * in one description (the same as the constraints file of the CLI and batch
 * jobs, docs/CONSTRAINTS.md), built here or parsed from that JSON. Joints are
 * named as in the input motion; frames are the input's; positions are in the
 * input's world frame and its own length unit (mf_motion_get_length_scale).
 * mf_solve runs it and can return several distinct solutions. Names and frames
 * are checked against the input when mf_solve runs (unknown joints, frames out
 * of range, overlapping pins: MF_ERROR_INVALID_ARGUMENT naming the item); keys
 * at one frame merge into one (a whole pose covers everything). */

/** A set of constraints (not thread-safe while being built; const use is). */
typedef struct mf_constraints mf_constraints;
/** The result of mf_solve: one or more motions and how well each meets the
 *  constraints. */
typedef struct mf_solution mf_solution;

/** Root flags of a partial key. */
#define MF_ROOT_NONE 0u
#define MF_ROOT_POSITION 1u
#define MF_ROOT_ROTATION 2u

/** A new, empty set. */
MF_API int mf_constraints_create(mf_constraints **out);
/** A set from the constraints file format (JSON text, `length` bytes):
 *  MF_ERROR_INVALID_ARGUMENT naming the item on a malformed document. */
MF_API int mf_constraints_parse_json(const char *json, size_t length, mf_constraints **out);
/** The same from a file (MF_ERROR_IO if it cannot be read; at most 16 MiB;
 *  errors are prefixed with the path). */
MF_API int mf_constraints_load_json(const char *path, mf_constraints **out);
MF_API void mf_constraints_destroy(mf_constraints *constraints);
/** Whole-pose keys at `frames` (any order). */
MF_API int mf_constraints_add_pose_keys(mf_constraints *constraints, const int32_t *frames, size_t count);
/** A partial key at `frame`: the local rotations of `joints` (names; may be
 *  empty) and, by `root` (MF_ROOT_* flags), the root's position and/or
 *  rotation. A key must constrain something. */
MF_API int mf_constraints_add_partial_key(mf_constraints *constraints, int32_t frame, const char *const *joints,
                                          size_t joint_count, uint32_t root);
/** An end-effector target: joint `joint` at `position` (x, y, z, world, the
 *  input's unit) at `frame`, with a relative `weight` (finite, >= 0; 1 is the
 *  usual). The solver pulls the joint there and IK places it (within reach). */
MF_API int mf_constraints_add_target(mf_constraints *constraints, int32_t frame, const char *joint,
                                     const float position[3], float weight);
/** A contact pin: `joint` (a foot, a hand) stays put in the world from frame
 *  `first` to `last` inclusive (first < last): where keys inside the range
 *  fix it, at their positions; else where the solution puts it on average. */
MF_API int mf_constraints_add_contact(mf_constraints *constraints, const char *joint, int32_t first, int32_t last);
/** The set as constraints-file JSON (a string getter). */
MF_API int mf_constraints_to_json(const mf_constraints *constraints, char *out, size_t capacity, size_t *needed);

/** Completes `input` under `constraints` (at least one key must give the
 *  root's rotation and position) with the method of `options` (default as
 *  mf_inbetween), plus `alternatives` (0..16) more solutions that honour the
 *  same constraints from other starts (deterministic for options->seed).
 *  Partial keys, targets, contacts and alternatives need a latent solver
 *  method ("nemf", "nemf-detail", ...; "interp" takes them without
 *  alternatives). Like mf_inbetween, the model's methods serve any humanoid
 *  rig, unit and frame rate (options->rig_map applies); on a rig that is not
 *  the model's, one key must give the whole pose, and target and pin joints
 *  must have a counterpart on the model's rig. Known values, targets and
 *  pins are made exact on the input's own rig. Known values come out exactly
 *  as given.
 *  Constraints that cannot all hold (a target out of reach, a pin that keys
 *  contradict) give the best compromise and a warning naming the frames
 *  (mf_motion_get_warnings of each motion, and the report). */
MF_API int mf_solve(const mf_model *model, const mf_motion *input, const mf_constraints *constraints,
                    int32_t alternatives, const mf_task_options *options, mf_solution **out);
MF_API void mf_solution_destroy(mf_solution *solution);
/** Number of motions: 1 + alternatives. */
MF_API int mf_solution_get_count(const mf_solution *solution, int32_t *out);
/** A new motion handle (the caller destroys it) holding solution `index`: 0
 *  is the method's answer, 1.. the alternatives. */
MF_API int mf_solution_get_motion(const mf_solution *solution, int32_t index, mf_motion **out);

/** How well one solution meets the constraints, measured on it. Lengths in
 *  the input's unit. Targets: distance of the joint from its target; contacts:
 *  distance of the pinned joint from where it is at the pin's first frame. */
typedef struct mf_constraint_report {
  uint32_t struct_size;
  int32_t key_rotations;       /**< constrained rotations measured */
  double key_rotation_max_deg;
  double key_rotation_mean_deg;
  int32_t key_roots;           /**< constrained root positions measured */
  double key_root_max;
  double key_root_mean;
  int32_t targets;
  double target_max;
  double target_mean;
  int32_t contact_frames;      /**< pinned frames measured */
  double contact_slide_max;
  double contact_slide_mean;
  /* Appended (a caller's older, smaller struct_size gets the fields above). */
  int32_t trajectory_rows;     /**< trajectory rows measured (those not at a frame whose root position a key fixes) */
  double trajectory_max;       /**< ground distance (x, z) of the root from its row, the input's unit */
  double trajectory_mean;
  double facing_max_deg;       /**< angle between the root's facing and the row's forward */
  double facing_mean_deg;
} mf_constraint_report;

MF_API int mf_constraint_report_init(mf_constraint_report *report);
/** The report of solution `index` (fills what fits in report->struct_size). */
MF_API int mf_solution_get_report(const mf_solution *solution, int32_t index, mf_constraint_report *report);
/** Every solution's report and the warnings as JSON (a string getter):
 *    {"unit": "cm", "solutions": [{"index": 0, "keys": {"rotations": n,
 *      "rotation_max_deg": x, "rotation_mean_deg": x, "roots": n,
 *      "root_max": x, "root_mean": x}, "targets": {"count": n, "max": x,
 *      "mean": x}, "contacts": {"frames": n, "max": x, "mean": x}}, ...],
 *     "warnings": ["...", ...]}
 *  With a trajectory, each solution also has "trajectory": {"rows": n,
 *  "max": x, "mean": x, "facing_max_deg": x, "facing_mean_deg": x}. */
MF_API int mf_solution_get_report_json(const mf_solution *solution, char *out, size_t capacity, size_t *needed);

/** A ground trajectory for the solve: `count` rows, row i at frame
 *  `frames[i]` (non-negative, strictly increasing across all rows of the set
 *  when mf_solve runs), with `rows[4 * i ..]` = x, z (the root's ground
 *  position, world, the input's unit) and forward_x, forward_z (the facing
 *  direction: any non-zero length). The latent solvers pull the root's ground
 *  position and facing toward every row not at a frame whose root position a
 *  key fixes (the known frames win); other methods refuse a trajectory
 *  (MF_ERROR_INVALID_ARGUMENT naming those that can). Non-finite values and a
 *  zero-length facing are MF_ERROR_INVALID_ARGUMENT naming the row. */
MF_API int mf_constraints_add_trajectory(mf_constraints *constraints, const int32_t *frames, const float *rows,
                                         size_t count);
/** The same from a trajectory CSV file (header frame,x,z,forward_x,forward_z,
 *  docs/CONSTRAINTS.md): MF_ERROR_IO if it cannot be read,
 *  MF_ERROR_INVALID_ARGUMENT "<path>:<line>: ..." on a malformed file. */
MF_API int mf_constraints_load_trajectory_csv(mf_constraints *constraints, const char *path);

/** The name of the method that produced `solution` (static string): the one
 *  the options named, else the default method for these constraints (with a
 *  trajectory and the keyframe transformer loaded that is "nemf-refine", see
 *  mf_default_method). */
MF_API int mf_solution_get_method(const mf_solution *solution, const char **name);

/* ------------------------------------------------------------ output files
 * The one safe writer every save above uses, for a job's several outputs at
 * once (a motion, its alternatives, a report; the CLI's jobs and batches, the
 * Python package's batch). A set holds the files a job reads and the files it
 * writes, checked against each other as they are added: no two outputs, and
 * no output and input, may be the same file (by device and inode through
 * symbolic links and hard links; by absolute name for files not yet there;
 * devices and FIFOs excepted). Outputs are staged with mf_output_set_write (a
 * regular file into a temporary file with a unique name beside it, a device's
 * bytes kept) and put in place by mf_output_set_commit (devices written in
 * place, then every temporary file renamed over its target). Destroying a
 * set that was not committed, or a failed commit, removes every temporary
 * file: a failed job leaves none of its outputs behind and the files they
 * would have replaced unchanged. Failures are MF_ERROR_IO "cannot write
 * <path>: <reason>" (strerror: "No space left on device", "Permission
 * denied"). A set belongs to one thread at a time. */
typedef struct mf_output_set mf_output_set;

MF_API int mf_output_set_create(mf_output_set **out);
/** Accepts NULL; removes the temporary files of a set not committed. */
MF_API void mf_output_set_destroy(mf_output_set *set);
/** A file the job reads; `role` names it in messages ("input", "rig map
 *  file"). "" adds nothing. MF_ERROR_INVALID_ARGUMENT "the output O is the
 *  input I: refusing to overwrite it (name another output file)" when it is
 *  an output added before. */
MF_API int mf_output_set_add_input(mf_output_set *set, const char *path, const char *role);
/** A file the job writes; `role` names it ("output", "alternative",
 *  "report"). MF_ERROR_IO "cannot write O: it is a directory" / "cannot
 *  write O: directory D does not exist"; MF_ERROR_INVALID_ARGUMENT when it is
 *  an input or another output ("the report O is also the output P: refusing
 *  to write one file twice (name another output file)"). Nothing is added on
 *  failure. */
MF_API int mf_output_set_add_output(mf_output_set *set, const char *path, const char *role);
/** Adds every file of `job` (another set) to `set` under `label` ("line 3"),
 *  or none: MF_ERROR_INVALID_ARGUMENT when one of them is the same file as
 *  one of `set` and either is written ("line 2 already writes O: refusing to
 *  overwrite another job's output (give each job its own output files)",
 *  "line 2 reads O: ...", "line 2 writes I, which this job reads: ..."). For
 *  a batch: its jobs may run side by side. */
MF_API int mf_output_set_merge(mf_output_set *set, const mf_output_set *job, const char *label);
/** Stages `size` bytes (`data` may be NULL when size is 0) for output
 *  `path`, named exactly as it was added. MF_ERROR_IO when the temporary
 *  file cannot be written; MF_ERROR_INVALID_ARGUMENT when `path` is no
 *  output of the set. The motion's bytes come from
 *  mf_motion_save_bvh_to_memory or mf_motion_save_gltf_to_memory. */
MF_API int mf_output_set_write(mf_output_set *set, const char *path, const void *data, size_t size);
/** Puts every staged output in place (once). On MF_ERROR_IO the outputs not
 *  yet in place are removed. */
MF_API int mf_output_set_commit(mf_output_set *set);

/** The text of a rig map file (mf_task_options.rig_map_path), read with the
 *  library's limit of 1 MiB and its checks (not a directory or a device):
 *  MF_ERROR_IO "cannot read rig map file F: larger than the limit of 1 MiB
 *  for a rig map file". For mf_rig_describe, which takes the text. */
MF_API int mf_rig_map_read_file(const char *path, char *out, size_t capacity, size_t *needed);

/* ------------------------------------------------------------ model sets
 * Since 0.2.0. */

/** mf_model_load (path NULL: the default model, with the transformer
 *  in-betweeners and the rig anatomy next to it), then every file of
 *  `inbetweeners` (`count` paths, none NULL or empty) added in order as
 *  mf_model_with_inbetweener adds it (replacing a loaded one of its kind): the
 *  model set the CLI's --model, --twostage and --citl name. Errors are those
 *  of the two functions. */
MF_API int mf_model_load_set(const char *path, const char *const *inbetweeners, size_t count, mf_model **out);
/** The transformer files that lay next to the model's file but did not load
 *  (the methods that need them cannot run; the default method does without
 *  them), one warning per line in the CLI's words ("" when every file there
 *  loaded): a string getter. */
MF_API int mf_model_get_load_warnings(const mf_model *model, char *out, size_t capacity, size_t *needed);

/* ------------------------------------------------------------ batch jobs
 * Since 0.2.0. The JSON-lines jobs of `motionfield batch` (docs/CLI.md:
 * {"task": "inbetween" | "fill" | "resample" | "renav" | "transition", "in": ..., "out": ...,
 * ...}) parsed, checked and run by the library, with the CLI's messages: the
 * one implementation the CLI, its single commands and the Python package's
 * batch runners use.
 *
 * A runner holds what the jobs of one run share: the settings below, the
 * model (the one named, or the default one loaded on first need and then kept
 * for every job), and the files of the lines checked so far. A batch checks
 * every line first, in line order (mf_job_runner_check_line: a line may not
 * write what an earlier line writes or reads), then runs the checked jobs
 * (mf_job_run), in any order and on several threads at once;
 * mf_job_runner_run_line does both for one line on its own (a worker of a
 * distributed run, whose lines were checked elsewhere). Each run gives a
 * result: the exit code of the job (0 ok, 2 bad input, 1 internal error), the
 * lines the CLI prints on stderr for it ("motionfield: JOBS.jsonl line 3 (id
 * x): error: ...", warnings, the --verbose line) and its --json summary.
 * Relative paths are relative to the current directory. A runner may be used
 * from several threads at once; a checked job and a result belong to one
 * thread at a time. */
typedef struct mf_job_runner mf_job_runner;
/** One line parsed and its files checked (runnable or not). */
typedef struct mf_job mf_job;
/** What a job run said. */
typedef struct mf_job_result mf_job_result;

/** mf_job_runner_options.flags: a line of what ran and how long it took. */
#define MF_JOB_VERBOSE 1u
/** mf_job_runner_options.flags: no warnings in the messages (errors stay). */
#define MF_JOB_QUIET 2u
/** mf_job_runner_options.flags: mf_job_runner_check_line loads the model a
 *  job needs (a failed load is then that line's failure), so that the jobs
 *  can run side by side on it. */
#define MF_JOB_PRELOAD_MODEL 4u

typedef struct mf_job_runner_options {
  uint32_t struct_size;
  /** MF_JOB_* flags. */
  uint32_t flags;
  /** The thread count named in the --verbose line (mf_set_num_threads sets
   *  it); 0: 1. */
  int32_t threads;
  /** The model file; NULL or "": the default model, loaded on first need. */
  const char *model;
  /** Transformer in-betweener files added to the model (mf_model_load_set). */
  const char *const *inbetweeners;
  size_t inbetweener_count;
  /** The rig map file of every job without its own "rig_map"; NULL: none. */
  const char *rig_map;
  /** The BVH length unit of every job without its own "units" (a unit name,
   *  "auto" or metres per unit); NULL or "": auto. */
  const char *units;
} mf_job_runner_options;

MF_API int mf_job_runner_options_init(mf_job_runner_options *options);
/** A runner; loads options->model when given (its load error otherwise). */
MF_API int mf_job_runner_create(const mf_job_runner_options *options, mf_job_runner **out);
/** Accepts NULL. Jobs and results made by the runner stay valid. */
MF_API void mf_job_runner_destroy(mf_job_runner *runner);
/** Parses line `line_number` (1-based) of the batch file `batch_path` (named
 *  in messages), `length` bytes of `text` (no newline), and checks its files
 *  against every line checked by this runner before. Always makes a job
 *  (MF_OK); one that is not runnable gives its failure when run. */
MF_API int mf_job_runner_check_line(mf_job_runner *runner, const char *text, size_t length, uint64_t line_number,
                                    const char *batch_path, mf_job **out);
/** 1 if the checked job will run, 0 if it failed its checks. */
MF_API int mf_job_is_runnable(const mf_job *job);
/** 1 if the job carries the model's load warnings (mf_model_get_load_warnings):
 *  they go with the first runnable job of a batch that names no method. */
MF_API int mf_job_has_load_warnings(const mf_job *job);
/** Accepts NULL. */
MF_API void mf_job_destroy(mf_job *job);

/** mf_job_run_options.flags (mf_job_runner_run_line): a single command of the
 *  CLI: "-" as "in" (standard input) or "out" (standard output, BVH) and the
 *  task "export" accepted; messages without a line label and a summary
 *  without "line". */
#define MF_JOB_SINGLE 1u
/** mf_job_run_options.flags (mf_job_runner_run_line): the job carries the
 *  model's load warnings (see mf_job_has_load_warnings). */
#define MF_JOB_LOAD_WARNINGS 2u

typedef struct mf_job_run_options {
  uint32_t struct_size;
  /** MF_JOB_SINGLE, MF_JOB_LOAD_WARNINGS (mf_job_runner_run_line only). */
  uint32_t flags;
  /** Progress of the job's solver, on the calling thread; NULL: none. */
  mf_progress_fn progress;
  void *user_data;
} mf_job_run_options;

MF_API int mf_job_run_options_init(mf_job_run_options *options);
/** Runs a checked job (once: the job is spent). Every failure of the job
 *  itself is in the result (MF_OK). */
MF_API int mf_job_run(mf_job_runner *runner, mf_job *job, const mf_job_run_options *options, mf_job_result **out);
/** Parses, checks and runs one line on its own (no other line's files are
 *  checked against it). Every failure of the job itself is in the result. */
MF_API int mf_job_runner_run_line(mf_job_runner *runner, const char *text, size_t length, uint64_t line_number,
                                  const char *batch_path, const mf_job_run_options *options, mf_job_result **out);
/** Loads the runner's model now if not yet (the named one, else the default
 *  one), as a job needing it would. `out` (may be NULL): a new handle of it,
 *  or NULL when there is no model. MF_ERROR_INVALID_ARGUMENT "cannot load the
 *  default model: ..." when the default model does not load. */
MF_API int mf_job_runner_load_model(mf_job_runner *runner, mf_model **out);
/** The loaded model's path ("" before one is loaded): a string getter. */
MF_API int mf_job_runner_get_model_path(const mf_job_runner *runner, char *out, size_t capacity, size_t *needed);

/** Accepts NULL. */
MF_API void mf_job_result_destroy(mf_job_result *result);
/** The job's exit code: 0 ok, 2 bad input, 1 internal error. */
MF_API int mf_job_result_get_exit_code(const mf_job_result *result, int32_t *out);
/** Its stderr lines, each "motionfield: ...\n" ("" for none): a string getter. */
MF_API int mf_job_result_get_messages(const mf_job_result *result, char *out, size_t capacity, size_t *needed);
/** Its --json summary, one line of JSON without the newline: {"line", "id",
 *  "task", "in", "out", "status": "ok", "method", "model", "frames_in",
 *  "frames_out", "timings_ms", "warnings", ...} or {..., "status": "error",
 *  "exit_code", "error"}: a string getter. */
MF_API int mf_job_result_get_json(const mf_job_result *result, char *out, size_t capacity, size_t *needed);

/** mf_job_batch_summary's flags: a progress line was drawn during the batch. */
#define MF_JOB_PROGRESS_SHOWN 8u
/** Since 0.4.0. The end of a batch as `motionfield batch` ends it, from its
 *  jobs' exit codes (mf_job_result_get_exit_code, `count` of them, any order;
 *  `exit_codes` may be NULL when `count` is 0): *exit_code (optional) 1 when a
 *  job hit an internal error, else 2 when one had bad input, else 0; and, a
 *  string getter, its last standard-error line "motionfield: batch PATH: N
 *  jobs, K ok, F failed\n" (PATH printable) when a job failed, with
 *  MF_JOB_VERBOSE in `flags`, or with MF_JOB_PROGRESS_SHOWN unless
 *  MF_JOB_QUIET; "" otherwise. */
MF_API int mf_job_batch_summary(const char *batch_path, const int32_t *exit_codes, size_t count, uint32_t flags,
                                int32_t *exit_code, char *out, size_t capacity, size_t *needed);

/* ------------------------------------------------------------ transitions
 * Since 0.4.0. Two clips in, one transition out: the end of clip A (up to
 * frame I) and the start of clip B (from frame J) with N generated frames
 * between them, as one clip on A's rig, unit and frame rate:
 *   A's frames 0..I | N generated frames (I + 1 .. I + N) | B's frames J..
 * A's and B's parts come out exactly as given (B's after its placement).
 *
 * Clip B may be on A's rig with its joints in another order (matched by
 * name) or under other names on the same hierarchy (matched in order, with a
 * warning); anything else is MF_ERROR_INVALID_ARGUMENT "clip B's rig differs
 * from A's: ..." naming the first difference. B at another frame rate is
 * resampled to A's (the "cubic" spline), with a warning.
 *
 * Placement MF_PLACE_AUTO moves and turns B on the ground (about the vertical;
 * heights untouched) so that its frame J continues A's frame I: B is turned
 * by the yaw between the two root orientations so it starts facing the way A
 * ends, and its root at J is put where A's root gets in the N + 1 frame steps
 * at the mean of A's end ground velocity and B's start ground velocity (each
 * over at most 5 frame steps at the seam). MF_PLACE_KEEP leaves B where it is.
 *
 * The generated frames are made by the method of the task options (default as
 * mf_solve: every method that fills gaps) with whole-pose keys on every frame
 * of A's and B's parts. Optional constraints (partial keys, targets, pins, a
 * trajectory; mf_solve's) and alternatives work as for mf_solve; their frame
 * numbers refer to the whole output clip (the frame count of the transition
 * must then be given or read first), their joints to A's and their positions
 * to A's world and unit.
 *
 * Automatic length (frames 0): the larger of the time the joints need to go
 * from A's pose at I to B's at J at 1.5 m/s (poses compared with the root at
 * the origin, facing alike) and, with MF_PLACE_KEEP, the time the root needs
 * to cover the ground between the two seams at the mean of the two end speeds
 * (at least 1 m/s); in frames at A's rate, clamped to 10..60 at 30 fps
 * (scaled for other rates). The chosen count is in
 * mf_solution_get_transition and, when automatic, in a warning. */

/** mf_transition_options.place */
#define MF_PLACE_AUTO 0
#define MF_PLACE_KEEP 1

typedef struct mf_transition_options {
  uint32_t struct_size;
  /** Generated frames N, 1..600; 0 (the default) = automatic. */
  int32_t frames;
  /** A's last kept frame I; negative counts from A's end; -1 (the default of
   *  mf_transition_options_init) = A's last frame. A keeps at least two
   *  frames: I in 1..frames(A) - 1. */
  int32_t from_frame;
  /** B's first kept frame J (default 0); negative counts from B's end. B
   *  keeps at least two frames: J in 0..frames(B) - 2 (at A's rate). */
  int32_t to_frame;
  /** MF_PLACE_AUTO (default) or MF_PLACE_KEEP. */
  int32_t place;
  /** Non-zero: the motions hold only the N generated frames (not the seam
   *  frames A[I] and B[J]); the reports are still measured on the whole
   *  clip. */
  int32_t only_transition;
} mf_transition_options;

MF_API int mf_transition_options_init(mf_transition_options *options);
/** The transition of `a` into `b` (see above); `transition` NULL = the
 *  defaults of mf_transition_options_init; `constraints` optional (NULL:
 *  none); `alternatives` 0..16 more solutions; `options` as every task's (the
 *  method, seed, progress, cancel, rig map, iterations). The result is an
 *  mf_solution (mf_solution_get_motion, _get_report, _get_method, warnings
 *  with each motion) whose motions are on A's skeleton, BVH layout and unit.
 *  MF_ERROR_INVALID_ARGUMENT for a clip of fewer than two frames, I or J out
 *  of range, frames out of 0..600, a place that is not MF_PLACE_*, rigs that
 *  do not match, and what mf_solve refuses. */
MF_API int mf_transition(const mf_model *model, const mf_motion *a, const mf_motion *b,
                         const mf_transition_options *transition, const mf_constraints *constraints,
                         int32_t alternatives, const mf_task_options *options, mf_solution **out);
/** Where the transition of a solution made by mf_transition is: its frame
 *  count N (as given or chosen) and its first frame in the whole clip
 *  (I + 1; also with only_transition). Either pointer may be NULL.
 *  MF_ERROR_INVALID_ARGUMENT for a solution of mf_solve. */
MF_API int mf_solution_get_transition(const mf_solution *solution, int32_t *frames, int32_t *first_frame);

#ifdef __cplusplus
}
#endif

#endif /* MOTIONFIELD_H */
