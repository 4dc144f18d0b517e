# SPDX-License-Identifier: BSD-3-Clause
"""Flynn et al. (2016) Table 2 as a real-data case: what the simulation of the paper's
measure -> compensate -> measure-again chain predicts, which measured post-compensation values
it misses, and which effects (constant in both runs, or changed between the runs) of which
sizes explain them.

The experiment is modelled as it was run (Sec. 4): run 1 measures the machine with the nominal
program and identifies the 8 location errors by the paper's chain; the NC program is
compensated for them; run 2, some time later, runs the compensated program on the same machine
while the ballbar software holds the nominal one, and identifies again. A cause is a change of
the simulated machine in both runs ("constant") or in run 2 only ("between_runs"). Nothing of
the paper is used but Table 2 (data/flynn2016_table2.json); every other number is simulated.

Modules: table (Table 2 as printed), causes (the assumptions and the causes tried), chain
(the simulated experiment), scenario (prediction, responses, fits), analysis (analyse),
render (conclusions and text).
"""

from .analysis import DEFAULT_SWEEP, analyse  # noqa: F401
from .causes import PLAUSIBLE_CHANGE, PLAUSIBLE_CONSTANT, Assumptions, Candidate, candidates  # noqa: F401
from .render import render  # noqa: F401
from .table import NAMES, TABLE2_PATH, load_table2  # noqa: F401
