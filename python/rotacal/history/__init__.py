# SPDX-License-Identifier: BSD-3-Clause
"""Calibration history: every identification of a physical machine, and every correction
loaded into its controller, kept in a store, so that the drift of each location error can be
followed over months (docs/history.md).

The store is an embedded SQLite file by default (standard library) or a PostgreSQL database
given by a ``postgresql://`` URL (through psycopg 3), for a shop or a vendor that collects the
calibrations of many machines. One code path serves both: the SQL is the common subset, with
the placeholders and two column types set by a small dialect. The schema is versioned
(table ``rotacal_history_schema``); an older store is migrated when opened, a newer one refused.

Every write is one transaction: two writers at once lose nothing (SQLite: WAL and BEGIN
IMMEDIATE, waiting up to ``BUSY_TIMEOUT_S``; PostgreSQL: its own locking), and a writer killed
mid-write leaves the store as it was before that write.

Modules: entries (what is stored, checked), store (schema, reads and writes), opening (SQLite
file or PostgreSQL URL), drift (the history of each location error), figures (plots, HTML).
"""

from .drift import (
    DAYS_PER_MONTH,
    DRIFT_SPAN_WHY,
    K_EXPANDED,
    MIN_DRIFT_SPAN_DAYS,
    drift_fit,  # noqa: F401
    expand_tolerances,
    summarize,
)
from .entries import (
    CORRECTION,
    IDENTIFICATION,
    MAX_ERROR,
    MAX_MACHINE_ID,
    MAX_NOTE,
    Entry,
    Estimate,  # noqa: F401
    check_machine_id,
    correction_amounts,
    now_utc,
    parse_date,
    sha256_of_json,
    unit_of,
)
from .figures import history_section, write_plot  # noqa: F401
from .opening import ENV_STORE, default_location, open_history, refuse_before_storing  # noqa: F401
from .store import (
    BUSY_TIMEOUT_S,
    MIGRATIONS,
    POSTGRESQL,
    SCHEMA_VERSION,
    SQLITE,
    CalibrationHistory,  # noqa: F401
    redact,
)
