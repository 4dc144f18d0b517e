# SPDX-License-Identifier: BSD-3-Clause
"""Every file rotacal writes goes through :func:`write_output` (the C++ rule of
``rotacal/io/output_file.hpp``, the same for both languages).

- A regular file, or a path that does not exist yet, is written to a uniquely named temporary
  file in the same directory, fsynced and renamed over it: the old file or the new one, never
  half of one, and nothing left behind on failure.
- A character device or FIFO (``-o /dev/null``, a pipe) is written through, never replaced.
- A symbolic link is followed to its target.
- Refused with :class:`rotacal.IoError` naming the path: a directory, a block device, a
  missing parent directory, one of the command's ``inputs`` or ``other_outputs``.
"""

from __future__ import annotations

import os
from typing import Callable, Iterable, Union

from . import _core

PathLike = Union[str, "os.PathLike[str]"]


def _path(p: PathLike) -> str:
    if p is None or not isinstance(p, (str, os.PathLike)):
        raise _core.IoError(f"{p!r}: an output path must be a str or os.PathLike")
    return os.fspath(p)


def _paths(ps: Iterable[PathLike]) -> list[str]:
    return [_path(p) for p in ps if p is not None]


def check_output(
    path: PathLike, inputs: Iterable[PathLike] = (), other_outputs: Iterable[PathLike] = ()
) -> str:
    """Refuse a bad output path before any work; returns ``"replace"`` or ``"write-through"``."""
    return _core.check_output(_path(path), _paths(inputs), _paths(other_outputs))


def write_output(
    path: PathLike,
    data: Union[bytes, str, Callable[[], Union[bytes, str]]],
    inputs: Iterable[PathLike] = (),
    other_outputs: Iterable[PathLike] = (),
) -> None:
    """Write ``data`` (bytes, or str encoded as UTF-8) to ``path`` by the output rule.

    ``data`` may be a callable producing the content: the path is checked first, and if the
    callable raises, nothing is written and the old file stays.
    """
    p = _path(path)
    ins, others = _paths(inputs), _paths(other_outputs)
    if callable(data):
        _core.check_output(p, ins, others)
        data = data()
    if isinstance(data, str):
        data = data.encode("utf-8")
    if not isinstance(data, (bytes, bytearray, memoryview)):
        raise TypeError(f"write_output: data must be bytes or str, got {type(data).__name__}")
    _core.write_output(p, bytes(data), ins, others)


def write_outputs(
    outputs: Iterable[tuple[PathLike, Union[bytes, str]]], inputs: Iterable[PathLike] = ()
) -> None:
    """Write every output of one command, or none where it can be known: each path is checked
    against the inputs and the other outputs first, then the devices and FIFOs (which may
    still fail while written, e.g. /dev/full) are written before any regular file is replaced,
    so a failure leaves no new file beside an old one."""
    outs = [(_path(p), data) for p, data in outputs]
    ins = _paths(inputs)
    kinds = [
        check_output(p, ins, [q for j, (q, _) in enumerate(outs) if j != k])
        for k, (p, _) in enumerate(outs)
    ]
    order = sorted(range(len(outs)), key=lambda k: kinds[k] != "write-through")
    for k in order:
        p, data = outs[k]
        write_output(p, data, ins, [q for j, (q, _) in enumerate(outs) if j != k])
