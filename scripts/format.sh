#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Formatting and lint by the tools, at the versions scripts/setup.sh pins: clang-format over the
# C++ (.clang-format), ruff format and ruff check over the Python (pyproject.toml).
#   bash scripts/format.sh            reformat the tree in place
#   bash scripts/format.sh --check    fail, naming the files, where anything is not as the tools
#                                     would write it (the test command runs this)
#   bash scripts/format.sh --check FILE...   the same for the given files only
set -euo pipefail
cd "$(dirname "$0")/.."
check=0
if [ "${1:-}" = "--check" ]; then check=1; shift; fi
if [ $# -gt 0 ]; then
  cxx=(); py=()
  for f in "$@"; do
    case "$f" in
      *.cpp|*.hpp|*.h|*.cc) cxx+=("$f") ;;
      *.py|*.pyi) py+=("$f") ;;
      *) echo "format: not a C++ or Python file: $f" >&2; exit 2 ;;
    esac
  done
else
  mapfile -t cxx < <(git ls-files '*.cpp' '*.hpp' '*.h' '*.cc')
  mapfile -t py < <(git ls-files '*.py')
fi
status=0
if [ ${#cxx[@]} -gt 0 ]; then
  if [ $check = 1 ]; then
    clang-format --style=file:.clang-format --dry-run --Werror "${cxx[@]}" || status=1
  else
    clang-format --style=file:.clang-format -i "${cxx[@]}"
  fi
fi
if [ ${#py[@]} -gt 0 ]; then
  if [ $check = 1 ]; then
    ruff format --config pyproject.toml --check "${py[@]}" || status=1
    ruff check --config pyproject.toml --no-cache "${py[@]}" || status=1
  else
    ruff format --config pyproject.toml "${py[@]}"
    ruff check --config pyproject.toml --fix "${py[@]}"
  fi
fi
[ $status = 0 ] || echo "format: run 'bash scripts/format.sh' and commit the result" >&2
exit $status
