# SPDX-License-Identifier: BSD-3-Clause
"""The two ends of a serial line, shared by ``rotacal virtual``, ``rotacal record`` and
``rotacal circular virtual|record``: the link's options, the faults a virtual instrument acts
out, serving a virtual instrument until stopped, and the exit code of a recording."""

from __future__ import annotations

import argparse
import time
from typing import Any

from .. import _core, jsontext
from .options import EXIT_IO, EXIT_OK, number, path, say


def faults(a: argparse.Namespace) -> Any:
    """The --fault-* options as the C++ FaultInjection."""
    f = _core.FaultInjection()
    f.garbage_every, f.corrupt_every, f.drop_every = a.fault_garbage, a.fault_corrupt, a.fault_drop
    f.split_frames = a.fault_split
    f.close_after, f.silence_after = a.fault_unplug_after, a.fault_silence_after
    return f


def serve(dev, what: str, a: argparse.Namespace, detail: str) -> int:
    """Print the device path, then serve until Ctrl-C or SIGTERM (or the program's end with
    --exit-when-done)."""
    import signal

    def stop(*_: Any) -> None:
        raise KeyboardInterrupt

    # Installed explicitly: a process started in the background by a shell script inherits
    # SIGINT ignored, and Python then leaves it ignored (the instrument never stopped).
    signal.signal(signal.SIGINT, stop)
    signal.signal(signal.SIGTERM, stop)
    print(dev.port, flush=True)
    say(f"virtual {what} on {dev.port} ({detail}); Ctrl-C to stop")
    try:
        while not (a.exit_when_done and dev.finished):
            time.sleep(0.05)
        time.sleep(0.5)  # let the host read the last bytes before the line goes away
    except KeyboardInterrupt:
        pass
    dev.stop()
    st = dev.stats()
    say(
        f"virtual {what}: {st['frames_sent']} frames, {st['replies_sent']} replies, "
        f"{st['frames_dropped']} dropped and {st['frames_corrupted']} corrupted on purpose"
        + (", program finished" if st["finished"] else "")
    )
    return EXIT_OK


# Exit code of a recording by how it stopped: the data are in the file either way.
_RECORD_EXIT = {
    "end of program": EXIT_OK,
    "stopped": EXIT_OK,
    "device disconnected": EXIT_IO,
    "silence (timeout)": EXIT_IO,
    "no valid data": EXIT_IO,
}


def report_recording(summary, path: str, json_out: bool) -> int:
    if json_out:
        print(
            jsontext.dumps(
                {
                    k: getattr(summary, k)
                    for k in (
                        "rows",
                        "frames",
                        "lost",
                        "crc_errors",
                        "malformed",
                        "garbage_bytes",
                        "over_range",
                        "timeouts",
                        "outside_window",
                        "reason",
                        "detail",
                    )
                }
                | {"path": path},
                indent=None,
            )
        )
    if summary.rows == 0:  # nothing measured: the recorder left an existing file as it was
        say(f"rotacal: {path} not written, no row was recorded: {summary.describe()}")
        return EXIT_IO
    say(f"wrote {path}: {summary.describe()}")
    return _RECORD_EXIT[summary.reason]


def add_link_args(q: argparse.ArgumentParser, rate: float) -> None:
    g = q.add_argument_group("serial link")
    g.add_argument(
        "--baud",
        type=number("--baud", 50, 4_000_000, integer=True),
        default=115200,
        help="baud rate (default 115200)",
    )
    g.add_argument(
        "--rate",
        type=number("--rate", 0.0, 1e5, "Hz", lo_open=True),
        default=rate,
        help=f"stream sample rate, Hz (default {rate:g})",
    )


def add_virtual_args(q: argparse.ArgumentParser) -> None:
    q.add_argument(
        "--speed",
        type=number("--speed", 0.0, 1e4, lo_open=True),
        default=1.0,
        help="virtual seconds per real second (default 1: real time)",
    )
    q.add_argument(
        "--exit-when-done", action="store_true", help="stop serving when the program has run"
    )
    q.add_argument(
        "--truth", metavar="JSON", type=path("--truth"), help="write the simulated machine here"
    )
    g = q.add_argument_group("faults to act out (for testing recorders; 0 or -1: never)")
    g.add_argument(
        "--fault-garbage",
        type=number("--fault-garbage", -1, 1e9, integer=True),
        default=0,
        metavar="N",
        help="line noise after every Nth frame",
    )
    g.add_argument(
        "--fault-corrupt",
        type=number("--fault-corrupt", -1, 1e9, integer=True),
        default=0,
        metavar="N",
        help="flip a bit in every Nth frame",
    )
    g.add_argument(
        "--fault-drop",
        type=number("--fault-drop", -1, 1e9, integer=True),
        default=0,
        metavar="N",
        help="do not send every Nth frame",
    )
    g.add_argument("--fault-split", action="store_true", help="send every frame in two writes")
    g.add_argument(
        "--fault-unplug-after",
        type=number("--fault-unplug-after", -1, 1e9, integer=True),
        default=-1,
        metavar="N",
        help="hang up after N frames",
    )
    g.add_argument(
        "--fault-silence-after",
        type=number("--fault-silence-after", -1, 1e9, integer=True),
        default=-1,
        metavar="N",
        help="go silent after N frames",
    )


def add_record_args(q: argparse.ArgumentParser) -> None:
    q.add_argument(
        "--port",
        required=True,
        help="serial port, e.g. /dev/ttyUSB0, /dev/serial/by-id/..., /dev/pts/N",
    )
    q.add_argument(
        "--silence",
        type=number("--silence", 0.0, 3600.0, "s", lo_open=True),
        default=3.0,
        help="stop after this many seconds without data or without a reply to a command",
    )
    q.add_argument("--no-progress", action="store_true", help="no progress bar")
    q.add_argument("--json", action="store_true", help="print the recording summary as JSON")
    q.add_argument("-o", "--output", required=True, type=path("--output"))
