# SPDX-License-Identifier: BSD-3-Clause
"""The ``rotacal`` command line (``python -m rotacal``, the ``rotacal`` console script): a
package of one module per command group over the library; the library never imports it.

- options: exit codes, the epilog, option value types shared by every command;
- setups: argument groups several commands share (ballbar set-up, simulated machine,
  R-test pattern, the session analysed, the history store);
- serial_link: the two ends of a serial line (virtual instruments and recorders);
- plan, machines, simulate, identify (and predict), diagnose (and report), history, design,
  controller (export, compensate), instruments (virtual, record), demo (and table2),
  circular: the commands;
- parser: the parser built from those modules, and main.
"""

from .options import EXIT_ERROR, EXIT_INPUT, EXIT_IO, EXIT_OK, EXIT_USAGE  # noqa: F401
from .parser import build_parser, main  # noqa: F401
