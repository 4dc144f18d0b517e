#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Builds the documentation (docs/: Sphinx with myst-parser, autodoc, sphinx-argparse, and breathe
# over Doxygen's XML of the public headers) into build/docs/html, warnings as errors: a broken
# internal link, a reference that does not resolve or a docstring Sphinx cannot read fails it.
# External links are not checked (CI has no network). Installs nothing: scripts/setup.sh puts
# Sphinx, myst-parser, breathe, sphinx-argparse and doxygen there, and rotacal must be importable,
# either installed (scripts/test.sh runs this after its pip install) or a build's staged package:
#   PYTHONPATH=$PWD/build/release/python bash scripts/docs.sh
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
OUT=build/docs
rm -rf "$OUT"  # a fresh build each time: an incremental one reports only the pages it rereads
ROTACAL_DOXYGEN_DIR=$PWD/$OUT/doxygen "$PY" -m sphinx -W --keep-going -n -q -b html \
  -d "$OUT/doctrees" docs "$OUT/html"
echo "docs: $OUT/html/index.html"
