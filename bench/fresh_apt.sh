#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# How long scripts/setup.sh's apt step takes on a fresh Debian 12 machine: debootstraps one
# (--variant=buildd: gcc, g++ and make present, as on a new machine here) and times apt-get
# update + install of the main job's packages (setup.sh --main) and, in a second copy, of the
# whole test set. Root, network and debootstrap needed; ~1.5 GB in DIR.
# Usage: bash bench/fresh_apt.sh DIR
set -euo pipefail
DIR=${1:?usage: bash bench/fresh_apt.sh DIR}
cd "$(dirname "$0")/.."
# The package lists, from setup.sh itself (one definition).
eval "$(sed -n '/^MAIN_APT=(/,/)/p; /^TEST_APT=(/,/)/p' scripts/setup.sh)"
[ -d "$DIR/main" ] || debootstrap --variant=buildd bookworm "$DIR/main" http://deb.debian.org/debian >/dev/null
[ -d "$DIR/full" ] || cp -a "$DIR/main" "$DIR/full"
for set in main full; do
  R=$DIR/$set
  if [ "$set" = main ]; then P="${MAIN_APT[*]}"; else P="${MAIN_APT[*]} ${TEST_APT[*]}"; fi
  cp /etc/resolv.conf "$R/etc/resolv.conf"
  printf '#!/bin/sh\nexit 101\n' > "$R/usr/sbin/policy-rc.d"; chmod +x "$R/usr/sbin/policy-rc.d"  # start no services
  mountpoint -q "$R/proc" || mount -t proc proc "$R/proc"
  echo "$set: load $(cut -d' ' -f1-3 /proc/loadavg)"
  /usr/bin/time -f "$set apt: %e s wall, %U+%S s CPU" chroot "$R" sh -c \
    "apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $P >/tmp/apt.log 2>&1"
  umount "$R/proc"
done
