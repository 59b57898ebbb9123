"""Model (a loaded prior), the default model and method, and the model a task
runs with."""

from __future__ import annotations

import ctypes
import json
import os
import threading
from typing import Any, Dict, Optional, Tuple

from . import _capi as _c
from ._args import PathLike, _instance_arg, _keywords_after, _str_arg
from ._errors import Error, ModelError, _check
from ._handles import _read_string, _Skeletal
from ._library import _methods_by_name


class Model(_Skeletal):
    """A loaded prior. Immutable; share one between threads.

    Parameters
    ----------
    path : str or os.PathLike, optional
        A model file (.mfm); None loads the default model file (see
        default_model_path(); default_model() shares one instead). The
        transformer in-betweeners (motionfield-twostage.mfm,
        motionfield-citl.mfm) and the rig anatomy (motionfield-rig.json) next
        to it are loaded too.

    Raises
    ------
    FileError
        If the file cannot be read, or `path` is None and there is no default model.
    ModelError
        If it is not a valid model file.

    Attributes
    ----------
    joint_count : int
    joint_names : list of str
    parents : numpy.ndarray
        [joints] int32, -1 for the root.
    offsets : numpy.ndarray
        [joints, 3] float32, metres.
    fps : float
        The frame rate the model works at.
    window : int
        Frames per window.
    latent_sizes : tuple of int
        (local_size, global_size).
    """

    _destroy = staticmethod(_c.mf_model_destroy)
    _get_joint_count = staticmethod(_c.mf_model_get_joint_count)
    _get_joint_name = staticmethod(_c.mf_model_get_joint_name)
    _get_parents = staticmethod(_c.mf_model_get_parents)
    _get_offsets = staticmethod(_c.mf_model_get_offsets)

    def __init__(self, path: Optional[PathLike] = None) -> None:
        handle = ctypes.POINTER(_c.MfModel)()
        _check(_c.mf_model_load(None if path is None else os.fspath(path).encode(), ctypes.byref(handle)))
        super().__init__(handle)

    @classmethod
    def from_bytes(cls, data: bytes) -> "Model":
        """A model from the bytes of a model file.

        No transformer and no rig anatomy are loaded with it: it serves only
        motions on the model's own skeleton (see with_inbetweener()).

        Parameters
        ----------
        data : bytes-like
            The file's contents (copied).

        Returns
        -------
        Model

        Raises
        ------
        ModelError
            If it is not a valid model file.
        """
        data = bytes(data)
        handle = ctypes.POINTER(_c.MfModel)()
        _check(_c.mf_model_load_from_memory(data, len(data), ctypes.byref(handle)))
        return cls._wrap(handle)

    def with_inbetweener(self, path: PathLike) -> "Model":
        """This model plus a transformer in-betweener file.

        Model(path) already loads motionfield-twostage.mfm and
        motionfield-citl.mfm found next to the prior's file.

        Parameters
        ----------
        path : str or os.PathLike
            A transformer file of kind "twostage" or "citl" (read from the file).

        Returns
        -------
        Model
            A new Model: this one's prior and transformers plus that one.

        Raises
        ------
        FileError
            If the file cannot be read.
        ModelError
            If it is not a transformer file or does not fit the prior.
        """
        handle = ctypes.POINTER(_c.MfModel)()
        _check(_c.mf_model_with_inbetweener(self._live(), os.fspath(path).encode(), ctypes.byref(handle)))
        return type(self)._wrap(handle)

    def has_inbetweener(self, kind: str) -> bool:
        """Whether a transformer in-betweener is loaded.

        Parameters
        ----------
        kind : str
            "twostage" (methods context, detail, nemf-context, nemf-detail) or
            "citl" (citl, nemf-citl).

        Returns
        -------
        bool

        Raises
        ------
        InvalidArgumentError
            If `kind` is neither.
        """
        v = ctypes.c_int32(0)
        _check(_c.mf_model_has_inbetweener(self._live(), str(kind).encode(), ctypes.byref(v)))
        return v.value != 0

    @property
    def fps(self) -> float:
        """The frame rate the model works at."""
        return self._f64(_c.mf_model_get_fps)

    @property
    def window(self) -> int:
        """Frames per window."""
        return self._i32(_c.mf_model_get_window)

    def describe(self) -> Dict[str, Any]:
        """What the model holds and what did not load with it (mf_model_describe).

        Returns
        -------
        dict
            {"format_version", "joints", "fps", "window", "inbetweeners":
            {kind: {"file", "loaded", "error"}}, "rig_anatomy",
            "rig_anatomy_error"}: a transformer file next to the model that
            was there but did not load has "loaded" False and the reason in
            "error" (the default method then runs without it).

        Raises
        ------
        InvalidArgumentError
            If the model is closed.
        """
        return json.loads(_read_string(_c.mf_model_describe, self._live()))

    @property
    def latent_sizes(self) -> Tuple[int, int]:
        """(local_size, global_size)."""
        zl, zg = ctypes.c_int32(0), ctypes.c_int32(0)
        _check(_c.mf_model_get_latent_sizes(self._live(), ctypes.byref(zl), ctypes.byref(zg)))
        return zl.value, zg.value


def default_model_path() -> Optional[str]:
    """Path of the default model (the CLI's, mf_model_default_path).

    ``$MF_MODEL`` if set; else ``share/motionfield/motionfield-prior.mfm``
    installed next to the library (``<prefix>/share/motionfield`` of a CMake
    install, ``motionfield/share/motionfield`` of a package that bundles the
    library); else the source tree's ``models/motionfield-prior.mfm``.

    Returns
    -------
    str or None
        The path, or None when there is no default model.

    Raises
    ------
    Error
        Never in practice.
    """
    path = _read_string(_c.mf_model_default_path)
    return path or None


_default_models: Dict[str, "Model"] = {}
_default_models_lock = threading.Lock()


def default_model() -> Optional["Model"]:
    """The default model, loaded on first use and then shared.

    What the tasks use without ``model=`` (and what the CLI uses without
    ``--model``): the file at default_model_path() with the transformer
    in-betweeners and the rig anatomy found next to it.

    Returns
    -------
    Model or None
        The shared Model, or None when there is no default model.

    Raises
    ------
    FileError, ModelError
        If the default model exists but cannot be loaded (the message names it).
    """
    path = default_model_path()
    if path is None:
        return None
    with _default_models_lock:
        model = _default_models.get(path)
        if model is None:
            try:
                model = Model(path)
            except Error as e:
                raise type(e)("cannot load the default model: %s" % e, e.status) from None
            _default_models[path] = model
    return model


@_keywords_after("model")
def default_method(*, model: Optional["Model"] = None) -> str:
    """The in-betweening and gap-filling method used when none is named.

    The best measured method that can run with the model (mf_default_method):
    "nemf-detail" when it has the two-stage transformer, "nemf" with the
    prior alone, "interp" without a model. Resampling without a method uses
    "prior" with a model and "quintic" without; re-navigation uses "nemf".
    solve() with a trajectory uses "nemf-refine" instead when the model has the
    keyframe transformer (Solution.method says which ran).

    Parameters
    ----------
    model : Model, optional
        The model; by default the default model (see default_model()), as the
        tasks and the CLI use it.

    Returns
    -------
    str
        The method's name.

    Raises
    ------
    FileError, ModelError
        If the default model exists but cannot be loaded.
    """
    if model is None:
        model = default_model()
    name = ctypes.c_char_p()
    _check(_c.mf_default_method(model._live() if model is not None else None, ctypes.byref(name)))
    return name.value.decode()


def _task_model(model: Optional[Model], method: Optional[str]) -> Any:
    """The model handle a task runs with, chosen as the CLI chooses it: the
    given model; else the default model when no method is named or the method
    needs a model (None when there is none: the default method is then one
    without a model); else none."""
    _instance_arg(model, Model, "model", optional=True)
    _str_arg(method, "method", optional=True)
    if model is None and (not method or _needs_model(method)):
        model = default_model()
    return model._live() if model is not None else None


def _needs_model(method: str) -> bool:
    m = _methods_by_name().get(method)
    return m is not None and m.needs_model  # unknown names: the library says so


def _required_model(model: Optional[Model], what: str) -> Model:
    if model is None:
        model = default_model()
        if model is None:
            raise ModelError("%s needs the model, and there is no default model (pass model=, or set MF_MODEL)" % what,
                             _c.ERROR_MODEL)
    return model
