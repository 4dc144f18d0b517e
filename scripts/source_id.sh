#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Which source tree an installed rotacal package was built from, so that scripts/run.sh builds
# the package only when the installed one is not this tree's.
#   source_id.sh              this tree's id: a hash of the commit and of any uncommitted change
#                             to tracked files; empty outside a git checkout (always rebuild)
#   source_id.sh --installed  the id recorded in the installed package (empty if none)
#   source_id.sh --record     record this tree's id in the installed package
set -euo pipefail
cd "$(dirname "$0")/.."
PY=${PYTHON:-python3}
tree_id() {
  git rev-parse --is-inside-work-tree > /dev/null 2>&1 || return 0
  { git rev-parse HEAD; git diff HEAD; } | sha256sum | cut -d' ' -f1
}
package_dir() {
  # Where the installed package lives, found without importing it (nor its extension).
  "$PY" -c 'import importlib.util, os; s = importlib.util.find_spec("rotacal"); print(os.path.dirname(s.origin) if s else "")' 2>/dev/null || true
}
case "${1:-}" in
  "") tree_id ;;
  --installed)
    d=$(cd / && package_dir)
    [ -n "$d" ] && [ -f "$d/.source-id" ] && cat "$d/.source-id" || true ;;
  --record)
    d=$(cd / && package_dir)
    [ -n "$d" ] || { echo "source_id: no installed rotacal package" >&2; exit 1; }
    tree_id > "$d/.source-id" ;;
  *) echo "source_id: unknown option '$1'" >&2; exit 2 ;;
esac
