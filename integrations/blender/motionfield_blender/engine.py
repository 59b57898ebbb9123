"""Finding the motionfield Python package (ctypes over libmotionfield.so),
the models, and running one task with progress and cancellation.

The package is looked for, first found wins, in:

1. the add-on preference "Python package folder" (a folder that holds the
   ``motionfield`` package, e.g. ``<checkout>/python``);
2. ``$MOTIONFIELD_PYTHON`` (the same, as an environment variable);
3. an installed ``motionfield`` package (``pip install ./python`` into the
   Python Blender runs, or ``cmake --install``'s dist-packages);
4. next to the add-on: a copy bundled in the add-on (``_vendor/``, what
   ``make_zip.py`` puts there), then the source checkout the add-on sits in
   (``integrations/blender/motionfield_blender`` -> ``python/``).

The library itself is found by the package (``$MOTIONFIELD_LIBRARY``, the
checkout's build tree, the install tree, ...); the add-on preference
"Library" sets ``$MOTIONFIELD_LIBRARY`` before the first import.
"""

import importlib
import os
import sys
import threading

_here = os.path.dirname(os.path.realpath(__file__))
_mf = None
_models = {}


class NotFound(ImportError):
    pass


def _candidate_dirs(pref_dir):
    env = os.environ.get("MOTIONFIELD_PYTHON", "")
    return [d for d in (pref_dir, env) if d]


def _fallback_dirs():
    return [os.path.join(_here, "_vendor"),
            os.path.normpath(os.path.join(_here, "..", "..", "..", "python"))]


def _import_from(d):
    if not os.path.isfile(os.path.join(d, "motionfield", "__init__.py")):
        return None
    if d not in sys.path:
        sys.path.insert(0, d)
    return importlib.import_module("motionfield")


def load(pref_dir="", pref_library=""):
    """The motionfield module (imported once). Raises NotFound saying where it looked."""
    global _mf
    if _mf is not None:
        return _mf
    if pref_library:
        os.environ["MOTIONFIELD_LIBRARY"] = pref_library
    looked = []
    for d in _candidate_dirs(pref_dir):
        looked.append(d)
        mod = _import_from(d)
        if mod is not None:
            _mf = mod
            return mod
    try:
        _mf = importlib.import_module("motionfield")
        return _mf
    except ImportError as e:
        if getattr(e, "name", None) != "motionfield":
            raise NotFound("motionfield was found but does not import: %s" % e) from None
        looked.append("installed packages")
    for d in _fallback_dirs():
        looked.append(d)
        mod = _import_from(d)
        if mod is not None:
            _mf = mod
            return mod
    raise NotFound("the motionfield Python package was not found (looked in: %s); set the add-on's "
                   "'Python package folder' preference or $MOTIONFIELD_PYTHON to <checkout>/python"
                   % ", ".join(looked))


def model(path=""):
    """The model at `path` ("" = the default model, mf_model_default_path), loaded once."""
    mf = load()
    key = path or ""
    if key not in _models:
        if path:
            _models[key] = mf.Model(path)
        else:
            m = mf.default_model()
            if m is None:
                raise mf.ModelError("there is no default model (set a model path or $MF_MODEL)")
            _models[key] = m
    return _models[key]


# The transformer file each method family needs next to the model (the
# library's inbetweener kinds, mf_model_has_inbetweener); "nemf-X" starts from X's.
TRANSFORMER_KIND = {"context": "twostage", "detail": "twostage", "citl": "citl", "keyframe": "keyframe",
                    "refine": "keyframe"}


def can_run(method, model):
    """Whether `method` (a motionfield.Method) can run with `model` (None: no model)."""
    if not method.needs_model:
        return True
    if model is None:
        return False
    name = method.name[5:] if method.name.startswith("nemf-") else method.name
    kind = TRANSFORMER_KIND.get(name)
    return kind is None or model.has_inbetweener(kind)


def model_or_none(path=""):
    """model(path), or None when it cannot be loaded."""
    try:
        return model(path)
    except Exception:  # no model: only the methods without one are offered
        return None


def default_model_path():
    return load().default_model_path() or ""


class Job:
    """One task call, `run(progress=, cancel=)` -> Motion, on a thread or inline.

    progress: (iteration, max_iterations, window, window_count), updated by
    the library's progress callback (motionfield.Progress); cancel(): the
    cancel token.
    """

    def __init__(self, run):
        mf = load()
        self._run = run
        self.token = mf.CancelToken()
        self.progress = (0, 0, 0, 0)
        self.result = None
        self.error = None
        self.done = False
        self._thread = None

    def _on_progress(self, p):
        self.progress = (p.iteration, p.max_iterations, p.window, p.window_count)
        return False

    def _call(self):
        try:
            self.result = self._run(progress=self._on_progress, cancel=self.token)
        except BaseException as e:  # reported on the main thread
            self.error = e
        finally:
            self.done = True

    def start(self):
        self._thread = threading.Thread(target=self._call, name="motionfield task", daemon=True)
        self._thread.start()

    def run_inline(self, on_progress=None):
        if on_progress is not None:
            inner = self._on_progress

            def both(p):
                inner(p)
                return bool(on_progress(self.progress))
            self._on_progress = both
        self._call()

    def cancel(self):
        self.token.cancel()

    def join(self):
        if self._thread is not None:
            self._thread.join()
