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

# Cross-references must resolve (-n) inside rotacal; types of other packages (numpy, the
# standard library, Eigen, std) are not documented here and no inventory is fetched (no
# network in CI), so those are the only ones let through.
nitpick_ignore_regex = [
    (r"py:(class|obj|data|exc)", r"(numpy|np|pathlib|typing|collections|os|datetime|io|argparse)\..*"),
    (r"py:(class|obj|data)", r"(Any|Path|Sequence|Mapping|Iterable|Iterator|Callable|ndarray|NDArray|float|int|str|bool|bytes|dict|list|tuple|None|object|optional)"),
    (r"cpp:identifier", r"(std|Eigen|ceres|nlohmann)(::.*)?"),
]

# Doxygen's XML of the public headers, written once per build; breathe reads it.
DOXYGEN_XML = Path(os.environ.get("ROTACAL_DOXYGEN_DIR", ROOT / "build" / "docs" / "doxygen")) / "xml"
breathe_projects = {"rotacal": str(DOXYGEN_XML)}
breathe_default_project = "rotacal"
breathe_default_members = ("members", "undoc-members")
breathe_domain_by_extension = {"hpp": "cpp"}


def _run_doxygen() -> None:
    out = DOXYGEN_XML.parent
    out.mkdir(parents=True, exist_ok=True)
    doxyfile = (DOCS / "Doxyfile").read_text() + f'\nOUTPUT_DIRECTORY = "{out}"\n'
    subprocess.run(["doxygen", "-"], input=doxyfile, text=True, cwd=ROOT, check=True)


def setup(app):
    # docs/json_schema.md's ```schema NAME blocks are JSON (tests/python/test_json_schema.py
    # reads them by that tag).
    app.add_lexer("schema", JsonLexer)
    _run_doxygen()
