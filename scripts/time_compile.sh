#!/bin/bash
# SPDX-License-Identifier: BSD-3-Clause
# Compiler launcher that appends "user_s sys_s output" of each compile or link to $ROTACAL_TIME_LOG
# (default build_times.txt in the working directory): the per-translation-unit CPU that build-time
# changes quote in their commit messages. Configure with
#   CCACHE_DISABLE=1 cmake ... -DCMAKE_CXX_COMPILER_LAUNCHER=$PWD/scripts/time_compile.sh \
#                              -DCMAKE_CXX_LINKER_LAUNCHER=$PWD/scripts/time_compile.sh
out=unknown
prev=
for a in "$@"; do
  if [ "$prev" = "-o" ]; then out=$a; fi
  prev=$a
done
exec /usr/bin/time -a -o "${ROTACAL_TIME_LOG:-build_times.txt}" -f "%U %S $out" "$@"
