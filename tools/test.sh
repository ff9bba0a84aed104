#!/usr/bin/env bash
# Builds everything and runs the whole test suite with ctest: once in Release, once under
# AddressSanitizer + UndefinedBehaviorSanitizer, and the tests where threads meet (label
# "threads": the rings, the daemon pipeline, posefaird end to end) under ThreadSanitizer.
# Installs missing Debian packages first.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup-debian.sh
jobs=$(nproc 2>/dev/null || echo 2)

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j "$jobs"
ctest --test-dir build --output-on-failure -j "$jobs"

cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPOSEFAIR_SANITIZE_ADDRESS=ON \
  -DPOSEFAIR_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build-asan -j "$jobs"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-asan --output-on-failure -j "$jobs"

cmake -S . -B build-tsan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPOSEFAIR_SANITIZE_THREAD=ON \
  -DPOSEFAIR_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build-tsan -j "$jobs" --target ring_tests pipeline_tests daemon_e2e_tests replaylog_tests posefaird posefair
TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1 ctest --test-dir build-tsan --output-on-failure -j "$jobs" -L threads
