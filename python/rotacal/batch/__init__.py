# SPDX-License-Identifier: BSD-3-Clause
"""Batches of independent calls of the C++ core (a fleet's sessions, a benchmark grid) on local
threads, a Dask cluster or any concurrent.futures.Executor, with results that do not depend on
where they ran (docs/batch.md).

Modules: executor (where the work runs, chunks, seeds), results (the results file a rerun
resumes), items (one session file identified or diagnosed).
"""

from .executor import ENV_SCHEDULER, BatchError, chunk_size, opened, run, seeds, stream
from .results import ResultsFile
