#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# The main job on the embedded default: plan a single set-up ballbar test, simulate a machine
# with location errors, a pivot set-up error and one hidden effect, identify, diagnose,
# verify compensation, and write an HTML report. Usage: bash scripts/run.sh [OUTPUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
bash scripts/setup.sh --main
# The package is built and installed from this tree unless the installed one already is this
# tree's (scripts/source_id.sh: the commit and any uncommitted change; the test command records
# it after its own install).
if [ -z "$(bash scripts/source_id.sh)" ] || [ "$(bash scripts/source_id.sh)" != "$(bash scripts/source_id.sh --installed)" ]; then
  echo "run: building and installing the rotacal Python package (pip install .)" >&2
  "$PY" -m pip install -q --disable-pip-version-check --no-build-isolation .
  bash scripts/source_id.sh --record
fi
"$PY" -m rotacal demo -o "${1:-out/demo}"
