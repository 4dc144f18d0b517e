# SPDX-License-Identifier: BSD-3-Clause
"""The results file of a batch: JSON lines, one record per item, written as each item finishes,
so that an interrupted run resumes where it stopped.

Line 1 says what the batch is (``{"rotacal_batch": 1, "command": ..., "options": ...}``); each
further line is one item's record, ``{"item": KEY, "ok": true, "result": ...}`` or
``{"item": KEY, "ok": false, "error": {...}}``. Each record is flushed and synced before the
next item is taken, and a line cut by a kill (no newline at its end) is dropped when the file is
opened again: every item is recorded exactly once, and no recorded item is computed again.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any, Mapping

from .. import jsontext
from .executor import BatchError

FORMAT = 1


class ResultsFile:
    """Open (or create) ``path`` for the batch ``header`` (command and options): a file of
    another batch is refused rather than mixed with this one."""

    def __init__(self, path: str | Path, header: Mapping[str, Any]):
        self.path = Path(path)
        self.header = {"rotacal_batch": FORMAT, **header}
        self.records: dict[str, dict] = {}
        if self.path.exists() and self.path.stat().st_size > 0:
            self._read()
        else:
            self.path.write_text(jsontext.dumps(self.header, indent=None) + "\n")
        self._out = open(self.path, "a", encoding="utf-8")

    def _read(self) -> None:
        data = self.path.read_bytes()
        whole = data[: data.rfind(b"\n") + 1]
        if len(whole) < len(data):  # the last record, cut by a kill: that item runs again
            with open(self.path, "r+b") as f:
                f.truncate(len(whole))
        lines = whole.decode("utf-8").splitlines()
        where = f"{self.path}:1"
        try:
            first = json.loads(lines[0]) if lines else None
        except ValueError as e:
            raise BatchError(f"{where}: not a rotacal batch results file ({e})") from None
        if not isinstance(first, dict) or first.get("rotacal_batch") != FORMAT:
            raise BatchError(f"{where}: not a rotacal batch results file (format {FORMAT})")
        if {k: first.get(k) for k in self.header} != self.header:
            raise BatchError(
                f"{where}: the results of another batch ({first.get('command')}, options "
                f"{first.get('options')}); give another --results file or the same options"
            )
        for n, line in enumerate(lines[1:], 2):
            try:
                rec = json.loads(line)
                key = rec["item"]
            except (ValueError, KeyError, TypeError) as e:
                raise BatchError(f"{self.path}:{n}: not a batch record ({e})") from None
            if key in self.records:
                raise BatchError(f"{self.path}:{n}: item {key!r} recorded twice")
            self.records[key] = rec

    def add(self, key: str, ok: bool, value: Any) -> dict:
        """Record item ``key``'s result (ok) or error, durably, before the next one."""
        if key in self.records:
            raise BatchError(f"{self.path}: item {key!r} is recorded already")
        rec = {"item": key, "ok": ok, ("result" if ok else "error"): value}
        self._out.write(jsontext.dumps(rec, indent=None) + "\n")
        self._out.flush()
        os.fsync(self._out.fileno())
        self.records[key] = rec
        return rec

    def close(self) -> None:
        self._out.close()

    def __enter__(self) -> "ResultsFile":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()
