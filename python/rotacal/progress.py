# SPDX-License-Identifier: BSD-3-Clause
"""A progress bar for long work (recording, Monte Carlo, diagnosis of long sessions)."""

from __future__ import annotations

import os
import sys
import time
from typing import TextIO


class ProgressBar:
    """A one-line progress bar on stderr for long work (recording, Monte Carlo).

    On a terminal it redraws in place; otherwise (a log file, CI) it prints a line at every
    tenth of the way, so logs stay short. ``ROTACAL_PROGRESS=0`` silences it.
    """

    def __init__(
        self,
        label: str,
        total: float,
        unit: str = "",
        stream: TextIO | None = None,
        delay_s: float = 0.0,
    ):
        """``delay_s``: draw nothing until the work has taken this long (short work stays quiet)."""
        self.label, self.total, self.unit = label, float(total), unit
        self.delay_s = delay_s
        self._drawn = False
        self.stream = stream or sys.stderr
        self.enabled = os.environ.get("ROTACAL_PROGRESS", "1") != "0"
        self.tty = self.stream.isatty()
        self._last_decile = -1
        self._t0 = self._t_eta = time.monotonic()

    def update(self, done: float, note: str = "") -> None:
        if not self.enabled:
            return
        elapsed = time.monotonic() - self._t0
        if elapsed < self.delay_s:
            return
        self._drawn = True
        frac = min(max(done / self.total, 0.0), 1.0) if self.total > 0 else 0.0
        since = time.monotonic() - self._t_eta
        eta = f", {since * (1 - frac) / frac:4.0f} s left" if 0.02 < frac < 1 else ""
        text = (
            f"{self.label} [{'#' * int(30 * frac):<30s}] {100 * frac:5.1f}% "
            f"{done:.1f}/{self.total:.1f}{self.unit}{eta}" + (f"  {note}" if note else "")
        )
        if self.tty:
            self.stream.write("\r" + text + "\033[K")
            self.stream.flush()
        elif int(10 * frac) > self._last_decile:
            self._last_decile = int(10 * frac)
            self.stream.write(text + "\n")
            self.stream.flush()

    def reset(self, total: float) -> None:
        """Start a new stage of `total` (the bar refills; the delay still counts from the start)."""
        self.total = float(total)
        self._last_decile = -1
        self._t_eta = time.monotonic()

    def close(self) -> None:
        if self.enabled and self.tty and self._drawn:
            self.stream.write("\n")
            self.stream.flush()
