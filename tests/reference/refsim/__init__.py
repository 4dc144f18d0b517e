# SPDX-License-Identifier: BSD-3-Clause
"""refsim: an independent reference simulator of shared/spec/formats.md and effects.md.

numpy only; written from the spec text, docs/machines.md, docs/effects.md, docs/noise_model.md.
It never imports rotacal. Modules: machines, effects, kinematics, instruments, poses, noise, writers.
"""

from .kinematics import Model  # noqa: F401
from .machines import BUILTIN_NAMES, builtin, load_machine, machine_from_dict  # noqa: F401
from .instruments import ballbar_lengths, probe_touches, rtest_displacements  # noqa: F401
from . import effects, noise, poses, writers  # noqa: F401
