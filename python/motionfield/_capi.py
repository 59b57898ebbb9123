"""ctypes declarations of libmotionfield.so's C API (motionfield.h).

Every function's argtypes and restype is set here, once; the rest of the
package calls only what this module declares. The library is found by
``_candidates()``, first found wins:

1. ``$MOTIONFIELD_LIBRARY`` (a path; nothing else is tried when it is set);
2. bundled in the package: ``motionfield/lib/libmotionfield.so.0`` (what
   ``pip install ./python`` puts there when it finds a built library), or
   ``motionfield/libmotionfield.so.0``;
3. the CMake install tree: ``cmake --install`` puts this package in
   ``<prefix>/lib/python3/dist-packages/motionfield`` and the library in
   ``<prefix>/<libdir>`` (``lib``, ``lib/<multiarch>`` or ``lib64``);
4. the source checkout's build trees (``python/motionfield`` ->
   ``<root>/build/capi``, then other ``<root>/build*/capi``, newest first);
5. the system's library path (``ldconfig``).
"""

import ctypes
import ctypes.util
import glob
import os

ABI_VERSION = 0  # MF_ABI_VERSION of the header this module mirrors

# Status codes (MF_OK, MF_ERROR_*).
OK = 0
ERROR_INVALID_ARGUMENT = 1
ERROR_BUFFER_TOO_SMALL = 2
ERROR_IO = 3
ERROR_MODEL = 4
ERROR_CANCELLED = 5
ERROR_INTERNAL = 6
ERROR_UNSUPPORTED = 7
ERROR_OUT_OF_MEMORY = 8

METHOD_NEEDS_MODEL = 1
METHOD_COMPLETES = 2
METHOD_RESAMPLES = 4

ROOT_FROM_PRIOR = 0
ROOT_FROM_INPUT = 1

PATH_PER_FRAME = 0
PATH_POLYLINE = 1
ROOT_POSITION = 1
ROOT_ROTATION = 2


class MfModel(ctypes.Structure):
    """Opaque mf_model."""


class MfMotion(ctypes.Structure):
    """Opaque mf_motion."""


class MfEncoding(ctypes.Structure):
    """Opaque mf_encoding."""


class MfCancelToken(ctypes.Structure):
    """Opaque mf_cancel_token."""


class MfConstraints(ctypes.Structure):
    """Opaque mf_constraints."""


class MfOutputSet(ctypes.Structure):
    """Opaque mf_output_set."""


class MfSolution(ctypes.Structure):
    """Opaque mf_solution."""


class MfJobRunner(ctypes.Structure):
    """Opaque mf_job_runner."""


class MfJob(ctypes.Structure):
    """Opaque mf_job."""


class MfJobResult(ctypes.Structure):
    """Opaque mf_job_result."""


class MfConstraintReport(ctypes.Structure):
    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("key_rotations", ctypes.c_int32),
        ("key_rotation_max_deg", ctypes.c_double),
        ("key_rotation_mean_deg", ctypes.c_double),
        ("key_roots", ctypes.c_int32),
        ("key_root_max", ctypes.c_double),
        ("key_root_mean", ctypes.c_double),
        ("targets", ctypes.c_int32),
        ("target_max", ctypes.c_double),
        ("target_mean", ctypes.c_double),
        ("contact_frames", ctypes.c_int32),
        ("contact_slide_max", ctypes.c_double),
        ("contact_slide_mean", ctypes.c_double),
        ("trajectory_rows", ctypes.c_int32),
        ("trajectory_max", ctypes.c_double),
        ("trajectory_mean", ctypes.c_double),
        ("facing_max_deg", ctypes.c_double),
        ("facing_mean_deg", ctypes.c_double),
    ]


class MfProgress(ctypes.Structure):
    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("iteration", ctypes.c_int32),
        ("max_iterations", ctypes.c_int32),
        ("energy", ctypes.c_double),
        ("window", ctypes.c_int32),
        ("window_count", ctypes.c_int32),
    ]


PROGRESS_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.POINTER(MfProgress))


class MfBvhOptions(ctypes.Structure):
    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("length_scale", ctypes.c_double),
    ]


class MfGltfOptions(ctypes.Structure):
    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("format", ctypes.c_int32),
    ]


class MfMotionLoadOptions(ctypes.Structure):
    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("format", ctypes.c_int32),
        ("length_scale", ctypes.c_double),
        ("animation", ctypes.c_char_p),
        ("animation_index", ctypes.c_int32),
        ("fps", ctypes.c_double),
    ]


class MfTaskOptions(ctypes.Structure):
    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("method", ctypes.c_char_p),
        ("seed", ctypes.c_uint64),
        ("progress", PROGRESS_FN),
        ("user_data", ctypes.c_void_p),
        ("cancel", ctypes.POINTER(MfCancelToken)),
        ("rig_map", ctypes.c_char_p),
        ("rig_map_path", ctypes.c_char_p),
        ("max_iterations", ctypes.c_int32),
        ("no_fallback", ctypes.c_int32),
    ]


PLACE_AUTO = 0
PLACE_KEEP = 1


class MfTransitionOptions(ctypes.Structure):
    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("frames", ctypes.c_int32),
        ("from_frame", ctypes.c_int32),
        ("to_frame", ctypes.c_int32),
        ("place", ctypes.c_int32),
        ("only_transition", ctypes.c_int32),
    ]


class MfCodecOptions(ctypes.Structure):
    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("hop", ctypes.c_int32),
        ("root_source", ctypes.c_int32),
    ]


class MfRenavOptions(ctypes.Structure):
    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("path_kind", ctypes.c_int32),
        ("frame_count", ctypes.c_int32),
        ("fps", ctypes.c_double),
    ]


JOB_VERBOSE = 1
JOB_QUIET = 2
JOB_PRELOAD_MODEL = 4
JOB_SINGLE = 1
JOB_LOAD_WARNINGS = 2
JOB_PROGRESS_SHOWN = 8


class MfJobRunnerOptions(ctypes.Structure):
    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("flags", ctypes.c_uint32),
        ("threads", ctypes.c_int32),
        ("model", ctypes.c_char_p),
        ("inbetweeners", ctypes.POINTER(ctypes.c_char_p)),
        ("inbetweener_count", ctypes.c_size_t),
        ("rig_map", ctypes.c_char_p),
        ("units", ctypes.c_char_p),
    ]


class MfJobRunOptions(ctypes.Structure):
    _fields_ = [
        ("struct_size", ctypes.c_uint32),
        ("flags", ctypes.c_uint32),
        ("progress", PROGRESS_FN),
        ("user_data", ctypes.c_void_p),
    ]


_LIB_NAMES = ("libmotionfield.so.0", "libmotionfield.so")


def _package_dir():
    return os.path.dirname(os.path.abspath(__file__))


def _bundled_dirs(here):
    """Where a wheel or an install bundles the library inside the package."""
    return [os.path.join(here, "lib"), here]


def _install_tree_dirs(here):
    """<prefix>/<libdir> of a CMake install (capi/CMakeLists.txt): the package
    in <prefix>/lib/python3/dist-packages/motionfield."""
    site = os.path.dirname(here)
    if os.path.basename(site) not in ("dist-packages", "site-packages"):
        return []
    prefix = os.path.normpath(os.path.join(site, "..", "..", ".."))
    dirs = [os.path.join(prefix, "lib")]
    dirs += sorted(glob.glob(os.path.join(prefix, "lib", "*-linux-gnu")))
    dirs += [os.path.join(prefix, "lib64")]
    return dirs


def _build_tree_dirs(here):
    """<root>/build*/capi of the source checkout (python/motionfield)."""
    root = os.path.normpath(os.path.join(here, "..", ".."))
    if not os.path.isfile(os.path.join(root, "capi", "include", "motionfield.h")):
        return []
    builds = [os.path.join(root, "build")] + sorted(
        (d for d in glob.glob(os.path.join(root, "build*")) if os.path.basename(d) != "build"),
        key=lambda d: -os.path.getmtime(d))
    return [os.path.join(b, "capi") for b in builds]


def _candidates():
    env = os.environ.get("MOTIONFIELD_LIBRARY")
    if env:
        yield env
        return
    here = _package_dir()
    for d in _bundled_dirs(here) + _install_tree_dirs(here) + _build_tree_dirs(here):
        for name in _LIB_NAMES:
            path = os.path.join(d, name)
            if os.path.isfile(path):
                yield path
    found = ctypes.util.find_library("motionfield")
    yield found or "libmotionfield.so.0"


def _load():
    errors = []
    for path in _candidates():
        try:
            return ctypes.CDLL(path), path
        except OSError as e:
            errors.append("%s: %s" % (path, e))
    raise ImportError("cannot load libmotionfield.so (set MOTIONFIELD_LIBRARY to its path):\n  " +
                      "\n  ".join(errors))


lib, library_path = _load()

_i32 = ctypes.c_int32
_u32 = ctypes.c_uint32
_u64 = ctypes.c_uint64
_f32 = ctypes.c_float
_f64 = ctypes.c_double
_size = ctypes.c_size_t
_int = ctypes.c_int
_str = ctypes.c_char_p
_P = ctypes.POINTER
_model = _P(MfModel)
_motion = _P(MfMotion)
_encoding = _P(MfEncoding)
_token = _P(MfCancelToken)


def _declare(name, restype, *argtypes):
    f = getattr(lib, name)
    f.restype = restype
    f.argtypes = list(argtypes)
    globals()[name] = f


_declare("mf_abi_version", _u32)
_declare("mf_version_number", _u32)
_declare("mf_version_string", _str)
_declare("mf_last_error_message", _str)
_declare("mf_status_name", _str, _int)
_declare("mf_printable_text", _int, ctypes.c_char_p, _size, ctypes.c_char_p, _size, _P(_size))
_declare("mf_set_num_threads", _int, _i32)
_declare("mf_get_num_threads", _int, _P(_i32))

_declare("mf_cancel_token_create", _int, _P(_token))
_declare("mf_cancel_token_cancel", _int, _token)
_declare("mf_cancel_token_reset", _int, _token)
_declare("mf_cancel_token_is_cancelled", _int, _token, _P(_i32))
_declare("mf_cancel_token_destroy", None, _token)

_declare("mf_method_count", _int, _P(_i32))
_declare("mf_method_get", _int, _i32, _P(_str), _P(_str), _P(_u32))
_declare("mf_method_find", _int, _str, _P(_i32))
_declare("mf_default_method", _int, _model, _P(_str))

_declare("mf_model_default_path", _int, ctypes.c_char_p, _size, _P(_size))
_declare("mf_model_load", _int, _str, _P(_model))
_declare("mf_model_load_from_memory", _int, ctypes.c_void_p, _size, _P(_model))
_declare("mf_model_destroy", None, _model)
_declare("mf_model_with_inbetweener", _int, _model, _str, _P(_model))
_declare("mf_model_has_inbetweener", _int, _model, _str, _P(_i32))
_declare("mf_model_describe", _int, _model, ctypes.c_char_p, _size, _P(_size))
_declare("mf_model_get_joint_count", _int, _model, _P(_i32))
_declare("mf_model_get_joint_name", _int, _model, _i32, ctypes.c_char_p, _size, _P(_size))
_declare("mf_model_get_parents", _int, _model, _P(_i32), _size, _P(_size))
_declare("mf_model_get_offsets", _int, _model, _P(_f32), _size, _P(_size))
_declare("mf_model_get_fps", _int, _model, _P(_f64))
_declare("mf_model_get_window", _int, _model, _P(_i32))
_declare("mf_model_get_latent_sizes", _int, _model, _P(_i32), _P(_i32))

_declare("mf_bvh_options_init", _int, _P(MfBvhOptions))
_declare("mf_motion_create", _int, _i32, _P(_str), _P(_i32), _P(_f32), _i32, _f64, _P(_f32), _P(_f32), _P(_motion))
_declare("mf_motion_create_for_model", _int, _model, _i32, _i32, _f64, _P(_f32), _P(_f32), _P(_motion))
_declare("mf_motion_create_like", _int, _motion, _i32, _i32, _f64, _P(_f32), _P(_f32), _P(_motion))
_declare("mf_motion_load_bvh", _int, _str, _P(MfBvhOptions), _P(_motion))
_declare("mf_motion_load_bvh_from_memory", _int, ctypes.c_char_p, _size, _P(MfBvhOptions), _P(_motion))
_declare("mf_motion_save_bvh", _int, _motion, _str, _P(MfBvhOptions))
_declare("mf_motion_save_bvh_to_memory", _int, _motion, _P(MfBvhOptions), ctypes.c_char_p, _size, _P(_size))
_declare("mf_motion_destroy", None, _motion)
_declare("mf_motion_get_joint_count", _int, _motion, _P(_i32))
_declare("mf_motion_get_frame_count", _int, _motion, _P(_i32))
_declare("mf_motion_get_fps", _int, _motion, _P(_f64))
_declare("mf_motion_get_frame_time", _int, _motion, _P(_f64))
_declare("mf_motion_get_joint_name", _int, _motion, _i32, ctypes.c_char_p, _size, _P(_size))
_declare("mf_motion_get_parents", _int, _motion, _P(_i32), _size, _P(_size))
_declare("mf_motion_get_offsets", _int, _motion, _P(_f32), _size, _P(_size))
_declare("mf_motion_get_rotations", _int, _motion, _P(_f32), _size, _P(_size))
_declare("mf_motion_get_root_positions", _int, _motion, _P(_f32), _size, _P(_size))
_declare("mf_motion_get_global_positions", _int, _motion, _P(_f32), _size, _P(_size))
_declare("mf_gltf_options_init", _int, _P(MfGltfOptions))
_declare("mf_motion_load_options_init", _int, _P(MfMotionLoadOptions))
_declare("mf_motion_load", _int, _str, _P(MfMotionLoadOptions), _P(_motion))
_declare("mf_motion_load_from_memory", _int, _P(ctypes.c_uint8), _size, _P(MfMotionLoadOptions), _P(_motion))
_declare("mf_motion_save_gltf", _int, _motion, _str, _P(MfGltfOptions))
_declare("mf_motion_save_gltf_to_memory", _int, _motion, _P(MfGltfOptions), _P(ctypes.c_uint8), _size, _P(_size))

_declare("mf_task_options_init", _int, _P(MfTaskOptions))
_declare("mf_inbetween", _int, _model, _motion, _P(_i32), _size, _P(MfTaskOptions), _P(_motion))
_declare("mf_fill", _int, _model, _motion, _i32, _i32, _P(MfTaskOptions), _P(_motion))
_declare("mf_resample", _int, _model, _motion, _f64, _P(MfTaskOptions), _P(_motion))
_declare("mf_resample_frame_count", _int, _i32, _f64, _f64, _P(_i32), _P(_i32))

_declare("mf_codec_options_init", _int, _P(MfCodecOptions))
_declare("mf_encode", _int, _model, _motion, _P(MfCodecOptions), _P(_encoding))
_declare("mf_encoding_destroy", None, _encoding)
_declare("mf_encoding_get_window_count", _int, _encoding, _P(_i32))
_declare("mf_encoding_get_duration", _int, _encoding, _P(_f64))
_declare("mf_encoding_get_window_times", _int, _encoding, _P(_f64), _size, _P(_size))
_declare("mf_encoding_get_local_latents", _int, _encoding, _P(_f32), _size, _P(_size))
_declare("mf_encoding_get_global_latents", _int, _encoding, _P(_f32), _size, _P(_size))
_declare("mf_encoding_with_latents", _int, _encoding, _P(_f32), _size, _P(_f32), _size, _P(_encoding))
_declare("mf_decode", _int, _encoding, _f64, _i32, _P(MfCodecOptions), _P(_motion))
_declare("mf_decode_times", _int, _encoding, _P(_f64), _size, _f64, _P(MfCodecOptions), _P(_motion))

_declare("mf_renav_options_init", _int, _P(MfRenavOptions))
_declare("mf_renav", _int, _model, _motion, _P(_f32), _size, _P(MfRenavOptions), _P(MfTaskOptions), _P(_motion))
_declare("mf_path_load_csv", _int, _str, _P(_f32), _size, _P(_size))

_declare("mf_motion_get_length_scale", _int, _motion, _P(_f64))
_declare("mf_length_unit_scale", _int, _str, _P(_f64))
_declare("mf_rig_describe", _int, _model, _motion, _str, ctypes.c_char_p, _size, _P(_size))
_declare("mf_motion_get_warnings", _int, _motion, ctypes.c_char_p, _size, _P(_size))

_constraints = _P(MfConstraints)
_solution = _P(MfSolution)
_declare("mf_constraints_create", _int, _P(_constraints))
_declare("mf_constraints_parse_json", _int, ctypes.c_char_p, _size, _P(_constraints))
_declare("mf_constraints_load_json", _int, _str, _P(_constraints))
_declare("mf_constraints_destroy", None, _constraints)
_declare("mf_constraints_add_pose_keys", _int, _constraints, _P(_i32), _size)
_declare("mf_constraints_add_partial_key", _int, _constraints, _i32, _P(_str), _size, _u32)
_declare("mf_constraints_add_target", _int, _constraints, _i32, _str, _P(_f32), _f32)
_declare("mf_constraints_add_contact", _int, _constraints, _str, _i32, _i32)
_declare("mf_constraints_to_json", _int, _constraints, ctypes.c_char_p, _size, _P(_size))
_declare("mf_solve", _int, _model, _motion, _constraints, _i32, _P(MfTaskOptions), _P(_solution))
_declare("mf_solution_destroy", None, _solution)
_declare("mf_solution_get_count", _int, _solution, _P(_i32))
_declare("mf_solution_get_motion", _int, _solution, _i32, _P(_motion))
_declare("mf_constraint_report_init", _int, _P(MfConstraintReport))
_declare("mf_solution_get_report", _int, _solution, _i32, _P(MfConstraintReport))
_declare("mf_solution_get_report_json", _int, _solution, ctypes.c_char_p, _size, _P(_size))
_declare("mf_solution_get_method", _int, _solution, _P(_str))
_declare("mf_constraints_add_trajectory", _int, _constraints, _P(_i32), _P(_f32), _size)
_declare("mf_constraints_load_trajectory_csv", _int, _constraints, _str)
_declare("mf_transition_options_init", _int, _P(MfTransitionOptions))
_declare("mf_transition", _int, _model, _motion, _motion, _P(MfTransitionOptions), _constraints, _i32,
         _P(MfTaskOptions), _P(_solution))
_declare("mf_solution_get_transition", _int, _solution, _P(_i32), _P(_i32))

_output_set = _P(MfOutputSet)
_declare("mf_output_set_create", _int, _P(_output_set))
_declare("mf_output_set_destroy", None, _output_set)
_declare("mf_output_set_add_input", _int, _output_set, _str, _str)
_declare("mf_output_set_add_output", _int, _output_set, _str, _str)
_declare("mf_output_set_merge", _int, _output_set, _output_set, _str)
_declare("mf_output_set_write", _int, _output_set, _str, ctypes.c_void_p, _size)
_declare("mf_output_set_commit", _int, _output_set)
_declare("mf_rig_map_read_file", _int, _str, ctypes.c_char_p, _size, _P(_size))

if mf_abi_version() != ABI_VERSION:  # noqa: F821 (declared above)
    raise ImportError("%s has ABI version %d; this package needs %d" %
                      (library_path, mf_abi_version(), ABI_VERSION))  # noqa: F821

_declare("mf_model_load_set", _int, _str, _P(ctypes.c_char_p), _size, _P(_model))
_declare("mf_model_get_load_warnings", _int, _model, ctypes.c_char_p, _size, _P(_size))

_runner = _P(MfJobRunner)
_job = _P(MfJob)
_result = _P(MfJobResult)
_declare("mf_job_runner_options_init", _int, _P(MfJobRunnerOptions))
_declare("mf_job_runner_create", _int, _P(MfJobRunnerOptions), _P(_runner))
_declare("mf_job_runner_destroy", None, _runner)
_declare("mf_job_runner_check_line", _int, _runner, ctypes.c_char_p, _size, ctypes.c_uint64, _str, _P(_job))
_declare("mf_job_is_runnable", _int, _job)
_declare("mf_job_has_load_warnings", _int, _job)
_declare("mf_job_destroy", None, _job)
_declare("mf_job_run_options_init", _int, _P(MfJobRunOptions))
_declare("mf_job_run", _int, _runner, _job, _P(MfJobRunOptions), _P(_result))
_declare("mf_job_runner_run_line", _int, _runner, ctypes.c_char_p, _size, ctypes.c_uint64, _str,
         _P(MfJobRunOptions), _P(_result))
_declare("mf_job_runner_load_model", _int, _runner, _P(_model))
_declare("mf_job_runner_get_model_path", _int, _runner, ctypes.c_char_p, _size, _P(_size))
_declare("mf_job_result_destroy", None, _result)
_declare("mf_job_result_get_exit_code", _int, _result, _P(_i32))
_declare("mf_job_result_get_messages", _int, _result, ctypes.c_char_p, _size, _P(_size))
_declare("mf_job_result_get_json", _int, _result, ctypes.c_char_p, _size, _P(_size))
_declare("mf_job_batch_summary", _int, ctypes.c_char_p, _P(_i32), _size, ctypes.c_uint32, _P(_i32), ctypes.c_char_p,
         _size, _P(_size))
