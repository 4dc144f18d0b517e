# SPDX-License-Identifier: BSD-3-Clause
"""Sphinx configuration of rotacal's documentation (scripts/docs.sh builds it with -W -n).

The reference pages are the Markdown files beside this one (myst-parser); the Python API is
autodoc over the importable package (installed, or PYTHONPATH=build/release/python); the CLI
reference is sphinx-argparse over the real parser; the C++ API is breathe over Doxygen's XML
of the public headers, which this file runs Doxygen to write (Doxyfile beside it).
"""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

from pygments.lexers.data import JsonLexer

DOCS = Path(__file__).resolve().parent
ROOT = DOCS.parent

project = "rotacal"
author = "rotacal developers"
copyright = "rotacal developers, BSD-3-Clause"
# The version from the package's leaf module, read as text: the extension is imported by autodoc
# only, where an import failure is reported as such.
_version: dict = {}
exec((ROOT / "python" / "rotacal" / "version.py").read_text(), _version)
release = version = _version["__version__"]

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinxarg.ext",
    "breathe",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build"]
html_theme = "alabaster"
html_static_path: list[str] = []

# Headings become link targets (`page.md#section`) down to level 3.
myst_heading_anchors = 3

autodoc_member_order = "bysource"
autodoc_typehints = "signature"
napoleon_numpy_docstring = True
napoleon_google_docstring = False
# The docstrings' "type" slots say shape and units in words ("R : (N, K) array", "Returns
# BallbarPlan: labels, time (N,), ..."): shown as text, not as types whose every word would be
# looked up as a Python name.
napoleon_use_param = False
napoleon_use_rtype = False

# Cross-references must resolve (-n) inside rotacal: every rotacal.* Python name, C++ rotacal
# type, page, heading and label. Let through: a Python type in a signature that is not a rotacal
# name (numpy, typing, the standard library: no inventory is fetched, CI has no network), and
# std, Eigen, Ceres, nlohmann in C++ declarations.
nitpick_ignore_regex = [
    (r"py:(class|obj|data|exc)", r"(?!rotacal\.).*"),
    (r"cpp:identifier", r"(std|Eigen|ceres|nlohmann)(::.*)?"),
]

# Doxygen's XML of the public headers, written once per build; breathe reads it.
DOXYGEN_XML = (
    Path(os.environ.get("ROTACAL_DOXYGEN_DIR", ROOT / "build" / "docs" / "doxygen")) / "xml"
)
breathe_projects = {"rotacal": str(DOXYGEN_XML)}
breathe_default_project = "rotacal"
breathe_default_members = ("members", "undoc-members")
breathe_domain_by_extension = {"hpp": "cpp"}


def _run_doxygen() -> None:
    out = DOXYGEN_XML.parent
    out.mkdir(parents=True, exist_ok=True)
    doxyfile = (DOCS / "Doxyfile").read_text() + f'\nOUTPUT_DIRECTORY = "{out}"\n'
    subprocess.run(["doxygen", "-"], input=doxyfile, text=True, cwd=ROOT, check=True)


def _napoleon_except_attributes(app) -> None:
    """Napoleon reads the numpy-style sections of the functions' docstrings, but would read an
    attribute's first line as Google's "type: description": rotacal's attribute docstrings are
    prose ("0: the default set-up's run time", "(8,) errors ... (mm, rad): ..."), so napoleon's
    handler is kept for everything else."""
    from sphinx.ext.napoleon import _process_docstring

    listeners = app.events.listeners["autodoc-process-docstring"]
    ours = [listener for listener in listeners if listener.handler is _process_docstring]
    if len(ours) != 1:
        raise RuntimeError("conf.py: napoleon's docstring handler not found once")
    app.disconnect(ours[0].id)

    def process(app, what, name, obj, options, lines):
        if what not in ("attribute", "data", "property"):
            _process_docstring(app, what, name, obj, options, lines)

    app.connect("autodoc-process-docstring", process)


def setup(app):
    # docs/json_schema.md's ```schema NAME blocks are JSON (tests/python/test_json_schema.py
    # reads them by that tag).
    app.add_lexer("schema", JsonLexer)
    _napoleon_except_attributes(app)
    _run_doxygen()
