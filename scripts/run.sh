#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# The main job on the embedded default: plan a single set-up ballbar test, simulate a machine
# with location errors, a pivot set-up error and one hidden effect, identify, diagnose,
# verify compensation, and write an HTML report. Usage: bash scripts/run.sh [OUTPUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
bash scripts/setup.sh --main
echo "run: building and installing the rotacal Python package (pip install .)" >&2
"$PY" -m pip install -q --disable-pip-version-check --no-build-isolation .
"$PY" -m rotacal demo -o "${1:-out/demo}"
