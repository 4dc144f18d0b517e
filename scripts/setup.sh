#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Installs what rotacal needs on a fresh Debian machine (run as root): the C++ toolchain and
# libraries from Debian packages, the Python build tools from PyPI. Idempotent: it skips
# apt-get when every package is already there.
#   bash scripts/setup.sh          everything the test suite needs (scripts/test.sh)
#   bash scripts/setup.sh --main   only what the main job needs (scripts/run.sh): the library,
#                                  the extension and the demo's report, without the tests' tools
#                                  (clang's sanitizers and linker, a headless LinuxCNC, Chromium,
#                                  PostgreSQL, stress-ng, Catch2, SciPy, pytest)
set -euo pipefail

MAIN_APT=(build-essential cmake ninja-build pkg-config libeigen3-dev libceres-dev
          libserialport-dev nlohmann-json3-dev)
TEST_APT=(catch2 clang libclang-rt-14-dev lld-14 linuxcnc-uspace linuxcnc-uspace-dev chromium stress-ng postgresql doxygen)
MAIN_PIP=("numpy>=1.22" "matplotlib>=3.5" "pybind11>=2.11" "scikit-build-core>=0.11")
TEST_PIP=("scipy>=1.9" "pytest>=7" "pybind11-stubgen==2.5.5" "psycopg[binary]>=3.1"
          "clang-format==23.1.5" "ruff==0.17.6" "dask[distributed]>=2023.1"
          "sphinx>=9.0" "myst-parser>=5.2" "breathe>=5.1" "sphinx-argparse>=0.6")

case "${1:-}" in
  --main) APT_PACKAGES=("${MAIN_APT[@]}"); PIP_PACKAGES=("${MAIN_PIP[@]}") ;;
  "") APT_PACKAGES=("${MAIN_APT[@]}" "${TEST_APT[@]}"); PIP_PACKAGES=("${MAIN_PIP[@]}" "${TEST_PIP[@]}") ;;
  *) echo "setup: unknown option '$1' (use --main or nothing)" >&2; exit 2 ;;
esac

# pip's wheels need nothing from apt: they download and unpack beside apt-get instead of after it
# (on a fresh machine, 61 s of apt and 48 s of pip for the main job, each mostly waiting on the
# network, 12-06).
PY=${PYTHON:-python3}
pip_log=$(mktemp)
"$PY" -m pip install -q --disable-pip-version-check "${PIP_PACKAGES[@]}" >"$pip_log" 2>&1 &
pip_pid=$!

missing=()
for p in "${APT_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing Debian packages: ${missing[*]}"
  SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

if ! wait "$pip_pid"; then
  cat "$pip_log" >&2; rm -f "$pip_log"
  echo "setup: pip install ${PIP_PACKAGES[*]} failed" >&2; exit 1
fi
grep -v "Running pip as the 'root' user" "$pip_log" >&2 || true
rm -f "$pip_log"
