#!/usr/bin/env bash
# Installs what rotacal needs on a fresh Debian machine (run as root): the C++ toolchain and
# libraries from Debian packages, the Python build and test tools from PyPI. Idempotent: it
# skips apt-get when every package is already there.
set -euo pipefail

APT_PACKAGES=(build-essential cmake ninja-build pkg-config libeigen3-dev libceres-dev catch2
              libserialport-dev clang libclang-rt-14-dev linuxcnc-uspace chromium
              nlohmann-json3-dev stress-ng postgresql)
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

PY=${PYTHON:-python3}
"$PY" -m pip install -q --disable-pip-version-check \
  "numpy>=1.22" "matplotlib>=3.5" "scipy>=1.9" "pytest>=7" \
  "pybind11>=2.11" "scikit-build-core>=0.10" "pybind11-stubgen==2.5.5" "psycopg[binary]>=3.1"
