# SPDX-License-Identifier: BSD-3-Clause
"""The calibration history's schema: its version and the migrations that reach it."""

SCHEMA_VERSION = 2

# Migrations: version -> statements. {id} and {real} are filled in by the dialect. A store of
# version v gets every statement of v+1.. applied in one transaction. Never edit a released
# version: add one.
MIGRATIONS: dict[int, list[str]] = {
    1: [
        # The machine id names the physical machine (e.g. its serial number); its kinematic
        # type is fixed by the first calibration stored.
        "CREATE TABLE machines (machine_id TEXT PRIMARY KEY, machine_type TEXT NOT NULL, "
        "first_stored_at TEXT NOT NULL)",
        # One row per identification or correction. source_sha256: the session's SHA-256 for
        # an identification, the export file's for a correction; a second store is refused.
        "CREATE TABLE calibrations (id {id}, machine_id TEXT NOT NULL REFERENCES machines (machine_id), "
        "kind TEXT NOT NULL, test TEXT NOT NULL, measured_at TEXT NOT NULL, stored_at TEXT NOT NULL, "
        "session TEXT, source_sha256 TEXT NOT NULL, note TEXT, document TEXT NOT NULL, "
        "UNIQUE (kind, source_sha256))",
        # The estimates, one row each, so that a shop can query them in SQL across machines.
        # part: location_errors, map_coefficients (R-test) or correction (amounts loaded).
        "CREATE TABLE estimates (calibration_id BIGINT NOT NULL REFERENCES calibrations (id), "
        "part TEXT NOT NULL, name TEXT NOT NULL, value {real}, std {real}, unit TEXT, "
        "PRIMARY KEY (calibration_id, part, name))",
        "CREATE INDEX calibrations_by_machine ON calibrations (machine_id, measured_at, id)",
    ],
    2: [
        # What the identification said besides the model (noise model, uncertainty budget,
        # diagnosis findings) and the controller parameters active during the test.
        "ALTER TABLE calibrations ADD COLUMN details TEXT",
        "ALTER TABLE calibrations ADD COLUMN controller TEXT",
    ],
}
assert max(MIGRATIONS) == SCHEMA_VERSION
