"""OutputSet: the files one job reads and writes, staged and put in place together."""

from __future__ import annotations

import ctypes
import os
from typing import Union

from . import _capi as _c
from ._args import PathLike, _instance_arg, _str_arg
from ._errors import _check
from ._handles import _Handle
from ._motion import Motion


class OutputSet(_Handle):
    """The files one job reads and writes (mf_output_set): the one safe
    writer of the C API, for several outputs at once.

    Files are checked as they are added: no two outputs, and no output and
    input, may be the same file (by inode, through links; devices excepted).
    ``write()`` stages an output (a temporary file with a unique name beside
    it; a device's bytes are kept and written in place), ``commit()`` puts
    them all in place; closed or collected without ``commit()``, the set
    leaves none of them behind.

    Raises
    ------
    OutOfMemoryError
        If the set cannot be made.
    """

    _destroy = staticmethod(_c.mf_output_set_destroy)

    def __init__(self) -> None:
        handle = ctypes.POINTER(_c.MfOutputSet)()
        _check(_c.mf_output_set_create(ctypes.byref(handle)))
        super().__init__(handle)

    def add_input(self, path: PathLike, role: str = "input") -> None:
        """Adds a file the job reads.

        Parameters
        ----------
        path : str or os.PathLike
            The file as the user named it ("" adds nothing).
        role : str
            What it is, for messages ("input", "rig map file").

        Returns
        -------
        None

        Raises
        ------
        InvalidArgumentError
            If it is an output added before ("the output O is the input I:
            refusing to overwrite it (name another output file)").
        """
        _check(_c.mf_output_set_add_input(self._live(), os.fsencode(path), _str_arg(role, "role").encode()))

    def add_output(self, path: PathLike, role: str = "output") -> None:
        """Adds a file the job writes.

        Parameters
        ----------
        path : str or os.PathLike
            The file as the user named it.
        role : str
            What it is, for messages ("output", "alternative", "report").

        Returns
        -------
        None

        Raises
        ------
        FileError
            If it is a directory or its directory does not exist.
        InvalidArgumentError
            If it is an input or another output (nothing is added).
        """
        _check(_c.mf_output_set_add_output(self._live(), os.fsencode(path), _str_arg(role, "role").encode()))

    def merge(self, job: "OutputSet", label: str) -> None:
        """Adds every file of another job's set, or none (a batch's check).

        Parameters
        ----------
        job : OutputSet
            The job's files.
        label : str
            The job's name in later messages ("line 3").

        Returns
        -------
        None

        Raises
        ------
        InvalidArgumentError
            If one of its files is one of this set's and either is written
            ("line 2 already writes O: ...").
        """
        _instance_arg(job, OutputSet, "job")
        _check(_c.mf_output_set_merge(self._live(), job._live(), _str_arg(label, "label").encode()))

    def write(self, path: PathLike, data: Union[bytes, str]) -> None:
        """Stages the bytes of an output.

        Parameters
        ----------
        path : str or os.PathLike
            The output, named as it was added.
        data : bytes or str
            Its bytes (a str is written as UTF-8).

        Returns
        -------
        None

        Raises
        ------
        FileError
            If the temporary file cannot be written ("cannot write F: No
            space left on device").
        InvalidArgumentError
            If `path` is no output of the set.
        """
        raw = data.encode() if isinstance(data, str) else bytes(data)
        _check(_c.mf_output_set_write(self._live(), os.fsencode(path), raw, len(raw)))

    def write_motion(self, path: PathLike, motion: "Motion") -> None:
        """Stages a motion: glTF 2.0 for a .glb or .gltf name, BVH otherwise.

        Parameters
        ----------
        path : str or os.PathLike
            The output, named as it was added.
        motion : Motion
            The motion.

        Returns
        -------
        None

        Raises
        ------
        FileError
            As write().
        """
        ext = os.path.splitext(os.fspath(path))[1].lower()
        _instance_arg(motion, Motion, "motion")
        self.write(path, motion.to_gltf_bytes(ext[1:]) if ext in (".glb", ".gltf") else motion.to_bvh_text())

    def commit(self) -> None:
        """Puts every staged output in place (devices written in place, files renamed), once.

        Returns
        -------
        None

        Raises
        ------
        FileError
            With the file and the reason; the outputs not yet in place are removed.
        """
        _check(_c.mf_output_set_commit(self._live()))
