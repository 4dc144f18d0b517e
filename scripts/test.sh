#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# The whole test suite: C++ tests (ctest), the installed CMake package used from a separate
# project, the Python package built by pip and its tests (pytest), the benchmarks once each
# as a smoke check, the decoders under libFuzzer for a bounded time, and the C++ tests again
# under AddressSanitizer + UBSan.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
PY=${PYTHON:-python3}
export CMAKE_BUILD_PARALLEL_LEVEL=${CMAKE_BUILD_PARALLEL_LEVEL:-$(nproc)}

# Each step, and the end of each background job, with the seconds since the start: a CI log
# shows where the time goes.
export ROTACAL_TEST_START=$(date +%s)
elapsed() { echo "$(( $(date +%s) - ROTACAL_TEST_START )) s"; }
export -f elapsed
# The CPU seconds (user + sys) of the finished children of this shell, from /proc: each step
# prints the foreground's CPU so far, the background jobs print their own when they end. The
# run is CPU-bound on 2 cores (3303 CPU-s in 1684 s, 12-06), so CPU is what a cut must save.
CLK_TCK=$(getconf CLK_TCK)
foreground_cpu() { awk -v hz="$CLK_TCK" '{printf "%.0f", ($16 + $17) / hz}' "/proc/$$/stat"; }
step() { printf '\n==== [%s, foreground %s CPU-s] %s\n' "$(elapsed)" "$(foreground_cpu)" "$*"; }

step "set-up"
bash scripts/setup.sh

step "Formatting and lint: clang-format and ruff at the pinned versions (scripts/format.sh)"
bash scripts/format.sh --check

step "Configure the Release build, the AddressSanitizer + UBSan build and the fuzz build"
# Every C++ test runs once: under the sanitizers (the same assertions, plus ASan and UBSan),
# except the two Monte Carlo studies (hundreds of refits of code the other tests run too), which
# run in the Release build alone: under ASan they took 219 s and 122 s of a 694 s run. Running
# the other 73 in Release as well cost about 6 CPU-minutes of compiling and 5 minutes of
# testing (ctest -j1, at load 6-19). Finer, by Catch2 tag: the cases tagged [statistical] (the
# catalogue sweeps and the null-session rates of three diagnosis tests: 292 of their 407 CPU-s
# under ASan, 22 in Release; the separation design's Monte Carlo in test_ballbar_design: 158 of
# its 166, 11 in Release, one draw of the same fits, 18, in its place; the probe separation's
# Monte Carlo in test_probe_design: 12 of 27, 1 in Release) run in the Release build
# as test_<header>_statistical; the other cases of those executables, which run the same code
# on fewer sessions, under the sanitizers (ROTACAL_TEST_HALVES, tests/CMakeLists.txt).
# The sanitizer build at -O1 with line tables only: what ASan recommends, and far quicker to
# compile than -O2 -g. With clang (the fuzzers' compiler too; setup.sh installs it and its
# sanitizer runtimes): 27 % less compiler CPU per file than GCC, its tests faster, and its UBSan
# checks pointer arithmetic on null, which GCC's does not (it found one fault, d8586b5).
MONTE_CARLO_TESTS="test_rtest_design;test_joint_noise_fit"
# The sanitizer build's test files at -O0 (the library stays at -O1): a test file's compile is
# mostly Eigen and Catch2 code of its own, its run mostly library code. Measured (12-07, load
# 5-10, the two ways side by side, CPU-s): the 73 test files 798 -> 385 to compile, their run
# 284 -> 520. Likely why: a test object defines -O0 copies of inline and template functions
# the library uses too (Eigen's, rotacal's; 129 in test_circular_diagnosis), and the linker keeps
# the first copy, the test's, so library code runs them unoptimised (test_rtest_any_machine
# 17 -> 121 s). The eight tests below, which got slower by more than
# their compile saved, keep -O1 (with a precompiled header of their own, 3.5 CPU-s). The other
# 65: compiling 551 -> 208 (8 of them again: 224 -> 103), running 109 -> 125 and 102 -> 131.
SANITIZE_TESTS_O1="test_rtest_any_machine;test_circular_diagnosis;test_ballbar_nc_program;test_diagnose_ballbar"
SANITIZE_TESTS_O1+=";test_ballbar_plan;test_ballbar_monte_carlo;test_probe_design;test_diagnose_realistic"
# The closed-source vendor build (docs/licensing.md): the sanitizer build is configured with
# -DROTACAL_CERES_SOLVER=OFF, so that every C++ test runs on the library that links no Ceres
# library (the circle and sphere fits refined by rotacal's joint-fit driver; checked below on its
# link lines). The Release build keeps Ceres' solver, and runs the test that compares the two
# solvers, which costs it one more small test file.
CERES_SOLVER_TESTS="test_fit_orthogonal_distance"
# The clang builds link with LLVM's lld: the sanitizer build's 74 links took 28 CPU-s instead of
# GNU ld's 124 (a relink of one build directory, each linker in turn, load 7-10, 12-06).
CLANG_LINK=-fuse-ld=lld
# The Release build with clang as well: its library, benchmarks and tests took 544 CPU-s to
# compile against GCC 12's about 850 (one unity batch: 38.9 against 61.9 CPU-s, 12-08), and the
# run is CPU-bound. GCC still compiles the Python extension (pip, below), the CMake consumer and
# the C++ example against this library: the installed package is checked with the compiler a
# user's build picks by default.
cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release -DROTACAL_BUILD_BENCH=ON \
      -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_EXE_LINKER_FLAGS="$CLANG_LINK" \
      -DCMAKE_SHARED_LINKER_FLAGS="$CLANG_LINK" \
      -DROTACAL_ONLY_TESTS="$MONTE_CARLO_TESTS;$CERES_SOLVER_TESTS" -DROTACAL_TEST_HALVES=statistical
cmake -S . -B build/asan -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=Debug \
      -DCMAKE_EXE_LINKER_FLAGS="$CLANG_LINK" -DCMAKE_SHARED_LINKER_FLAGS="$CLANG_LINK" \
      -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" -DROTACAL_SANITIZE=ON -DROTACAL_BUILD_BENCH=OFF \
      -DROTACAL_CERES_SOLVER=OFF \
      -DROTACAL_SKIP_TESTS="$MONTE_CARLO_TESTS" -DROTACAL_TEST_HALVES=other \
      -DROTACAL_TEST_COMPILE_OPTIONS=-O0 -DROTACAL_TEST_COMPILE_OPTIONS_EXCEPT="$SANITIZE_TESTS_O1"
# -DROTACAL_CERES_SOLVER=OFF: no link line of the sanitizer build names Ceres or SuiteSparse (the
# Release build's name Debian's libceres.a, libcholmod.so and libspqr.so).
if grep -n -E 'libceres|libcholmod|libspqr' build/asan/build.ninja; then
  echo "the -DROTACAL_CERES_SOLVER=OFF build links Ceres or SuiteSparse" >&2
  exit 1
fi
cmake -S fuzz -B build/fuzz -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_EXE_LINKER_FLAGS="$CLANG_LINK" \
      -DROTACAL_FUZZ_SECONDS=20

step "In the background at nice 19, started now: the fuzz build; the AddressSanitizer + UBSan build and tests"
# The machine is CPU-bound throughout: these jobs fill the gaps of the foreground (the
# single-threaded pytest, benchmark and fuzzer steps). Their nice 19 does not make them yield to
# the foreground where the kernel groups by session (sched_autogroup_enabled=1 here): setsid
# puts each in a group of its own, which gets an equal share of the CPU. The order does not
# change the total: on 2 cores the run cannot end before its CPU seconds / 2. The
# sanitizer tests run as soon as they are built instead of after the fuzzers; the fuzz targets
# are built in those gaps instead of in a step of their own (3 minutes of the foreground, which
# otherwise ends after the sanitizer job). Each job its own process group, so that a failed step
# stops it whole (ninja and ctest stop their children on TERM). A temporary directory of its own:
# two tests name fixed files there. tests/CMakeLists.txt gives the slowest sanitizer tests a
# COST, so they start first, not one of them last alone on a core. Not more tests at a time than
# cores: test_hw_recorder's unplug case needs its reader scheduled within 50 frames of the
# virtual ballbar, and lost 281 of 500 rows once at load 11 (ctest -j2 beside other jobs). That
# test now runs in a session of its own (below), beside the compilers or the last tests: so it
# passed in CI (12-06) and in the Release build under stress-ng --cpu 2 (115.7 s, 12-07).
FUZZ_LOG=$ROOT/build/fuzz-build.log
setsid -w nice -n 19 bash -c 'cmake --build build/fuzz && echo "finished at $(elapsed)" && times' > "$FUZZ_LOG" 2>&1 &
FUZZ_PID=$!
# test_hw_recorder waits on its virtual instruments in real time (124 s, 12 CPU-s under ASan):
# run among the last tests it held a ctest slot while the other core had nothing left to do
# (about 60 s of the run's end, 12-06). It starts as soon as it is built, while the other tests
# compile, in a session of its own: a group that gets its share of the CPU beside the
# compilers (it passed so at load 8, 12-06). The other tests run when all are built.
asan_job() {
  export TMPDIR=$PWD/build/asan-tmp ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1
  local hw_log=build/asan-hw-recorder.log hw_pid
  cmake --build build/asan --target test_hw_recorder || return 1
  echo "test_hw_recorder built at $(elapsed)"
  setsid -w ctest --test-dir build/asan --output-on-failure -R '^test_hw_recorder$' > "$hw_log" 2>&1 &
  hw_pid=$!
  trap 'kill -TERM -- "-$hw_pid" 2>/dev/null || true' EXIT
  trap 'exit 143' TERM
  cmake --build build/asan || return 1
  echo "built at $(elapsed)"
  ctest --test-dir build/asan --output-on-failure -j "$(nproc)" -E '^test_hw_recorder$' || return 1
  if ! wait "$hw_pid"; then cat "$hw_log"; return 1; fi
  grep -E "tests passed|Total Test time" "$hw_log"
  echo "finished at $(elapsed)"
  times
}
export -f asan_job
ASAN_LOG=$ROOT/build/asan.log
mkdir -p build/asan-tmp
setsid -w nice -n 19 bash -c asan_job > "$ASAN_LOG" 2>&1 &
ASAN_PID=$!
trap 'kill -TERM -- "-$ASAN_PID" "-$FUZZ_PID" 2>/dev/null || true' EXIT

step "C++ build (Release: library, benchmarks, Monte Carlo and [statistical] tests) and those tests"
cmake --build build/release
ctest --test-dir build/release --output-on-failure -j "$(nproc)"

step "CMake package: find_package(rotacal CONFIG REQUIRED) from a separate project"
rm -rf build/install build/consumer
cmake --install build/release --prefix build/install --component dev
cmake -S tests/consumer -B build/consumer -G Ninja -DCMAKE_PREFIX_PATH="$ROOT/build/install"
cmake --build build/consumer
./build/consumer/rotacal_consumer
./build/consumer/rotacal_consumer_hw
./build/consumer/rotacal_consumer_realtime  # the real-time headers alone: Eigen, no exceptions, no library

step "C++ example (examples/cpp) against the installed package"
cmake -S examples/cpp -B build/example -G Ninja -DCMAKE_PREFIX_PATH="$ROOT/build/install"
cmake --build build/example
./build/example/quickstart examples/data/ballbar_ac_table2.csv

step "Python package (pip install .); beside pytest, the docs and the benchmarks' smoke runs"
# The extension only, linked against the library installed above: compiling the library again
# inside pip took about 4.5 of CI's 45 minutes. A plain `pip install .` builds everything.
"$PY" -m pip install -q --disable-pip-version-check --no-build-isolation \
  -C cmake.define.ROTACAL_PYTHON_FROM_INSTALLED=ON -C cmake.define.CMAKE_PREFIX_PATH="$ROOT/build/install" .
# The installed package is this tree's: the README's main job (run by test_readme.py) need not
# build it again (scripts/source_id.sh).
bash scripts/source_id.sh --record
# The docs build and the benchmarks' smoke runs need only the installed package and the Release
# build: they run beside the single-threaded pytest rather than after it (they took 16 + 29 s of
# the foreground in a fresh-clone run of 12-07), in a session of their own like the jobs above.
side_job() {
  set -euo pipefail
  echo "docs (scripts/docs.sh)"
  bash scripts/docs.sh
  echo "benchmarks, once each as a smoke check (figures: bench/report.py runs them in full)"
  ./build/release/bench/ballbar_accuracy --smoke
  ./build/release/bench/diagnose_bench --smoke
  ./build/release/bench/diagnose_realistic_bench --smoke
  ./build/release/bench/ballbar_long --smoke
  ./build/release/bench/rtest_bench
  ./build/release/bench/probe_accuracy --smoke
  ./build/release/bench/hw_stream --smoke
  "$PY" bench/ballbar_speed.py --smoke
  "$PY" bench/diagnosis_confusion.py --smoke
  "$PY" bench/history_bench.py --smoke
  "$PY" bench/design_bench.py --smoke
  ./build/release/bench/noise_mc_bench --smoke
  ./build/release/bench/any_machine_bench --smoke
  ./build/release/bench/realtime_bench --smoke
  ./build/release/bench/multi_bench --smoke
  "$PY" bench/multi_diagnosis_pairs.py --smoke
  "$PY" bench/table_residual_bench.py --smoke
  "$PY" bench/structure_null.py --smoke
  "$PY" bench/thermal_bench.py --smoke
  "$PY" bench/diagnosis_loop.py --smoke
  echo "finished at $(elapsed)"
}
export -f side_job
export PY
SIDE_LOG=$ROOT/build/side.log
setsid -w bash -c side_job > "$SIDE_LOG" 2>&1 &
SIDE_PID=$!
trap 'kill -TERM -- "-$ASAN_PID" "-$FUZZ_PID" "-$SIDE_PID" 2>/dev/null || true' EXIT
# The virtual instruments' tests pace on the wall clock (their programs at 50 Hz, polled poses):
# 182 s wall for 17 CPU-s (12-07). Run in the one pytest they held its single thread for that
# time; in a pytest of their own beside it, their waits overlap the other tests' work.
WALLCLOCK_TESTS=(test_instruments.py test_circular_instruments.py)
WALLCLOCK_LOG=$ROOT/build/pytest-wallclock.log
(cd tests/python && exec setsid -w "$PY" -m pytest -q -p no:cacheprovider --durations=5 \
  --basetemp="$ROOT/build/pytest-wallclock-tmp" \
  "${WALLCLOCK_TESTS[@]}") > "$WALLCLOCK_LOG" 2>&1 &
WALLCLOCK_PID=$!
trap 'kill -TERM -- "-$ASAN_PID" "-$FUZZ_PID" "-$SIDE_PID" "-$WALLCLOCK_PID" 2>/dev/null || true' EXIT
# test_readme.py builds the README's C++ quick start against the installed CMake package.
(cd tests/python && ROTACAL_PREFIX="$ROOT/build/install" "$PY" -m pytest -q -p no:cacheprovider \
  --durations=15 "${WALLCLOCK_TESTS[@]/#/--ignore=}" .)
step "The virtual instruments' tests (the wall-clock pytest's output)"
if ! wait "$WALLCLOCK_PID"; then
  cat "$WALLCLOCK_LOG"
  echo "the virtual instruments' tests failed: $WALLCLOCK_LOG" >&2
  exit 1
fi
cat "$WALLCLOCK_LOG"

step "C++ example: a model file written by the Python CLI, read by C++ to compensate a point"
"$PY" -m rotacal identify examples/data/ballbar_ac_table2.csv --save-model build/example/model.json > /dev/null
./build/example/compensate_point build/example/model.json 30 45 10 20 30

step "The docs and the benchmarks' smoke runs (the side job's output)"
if ! wait "$SIDE_PID"; then
  tail -n 80 "$SIDE_LOG"
  echo "the docs build or a benchmark's smoke run failed: $SIDE_LOG" >&2
  exit 1
fi
cat "$SIDE_LOG"

step "libFuzzer targets of the instrument decoders, 20 s each (clang; built in the background)"
if ! wait "$FUZZ_PID"; then
  tail -n 80 "$FUZZ_LOG"
  echo "the fuzz build failed: $FUZZ_LOG" >&2
  exit 1
fi
tail -n 3 "$FUZZ_LOG"
ctest --test-dir build/fuzz --output-on-failure -j "$(nproc)"  # time-bound: one core each

step "C++ tests under AddressSanitizer + UBSan (the background job's output)"
if ! wait "$ASAN_PID"; then
  tail -n 80 "$ASAN_LOG"
  echo "the AddressSanitizer build or tests failed: $ASAN_LOG" >&2
  exit 1
fi
trap - EXIT
grep -E "built at|tests passed|Total Test time|finished at" "$ASAN_LOG"
echo "the sanitizer job's CPU (bash's times: its own, then its children's user and sys):"
tail -n 2 "$ASAN_LOG"
step done
