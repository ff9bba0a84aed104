#!/usr/bin/env bash
# Builds everything and runs the whole test suite with ctest: once in Release, once under
# AddressSanitizer + UndefinedBehaviorSanitizer, and the tests where threads meet (the rings,
# the replay and serial drivers, the daemon pipeline, posefaird end to end) under ThreadSanitizer.
# The CAN, HID and GPIO tests (ctest label hw) need kernel interfaces this machine may lack:
# they run once, on the Release build, inside Debian's kernel under qemu (tests/hw/README.md).
# Installs missing Debian packages first.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup-debian.sh --tests
jobs=$(nproc 2>/dev/null || echo 2)

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j "$jobs"
ctest --test-dir build --output-on-failure -j "$jobs" -LE hw
# The CAN, HID and GPIO tests (label hw) against Debian's real kernel, in one qemu boot.
tests/hw/vm/run_hw_tests.sh build

cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPOSEFAIR_SANITIZE_ADDRESS=ON \
  -DPOSEFAIR_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build build-asan -j "$jobs"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-asan --output-on-failure -j "$jobs" -LE hw

cmake -S . -B build-tsan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPOSEFAIR_SANITIZE_THREAD=ON \
  -DPOSEFAIR_BUILD_BENCHMARKS=OFF >/dev/null
threaded=(tests/daemon/ring_tests tests/daemon/pipeline_tests tests/daemon/daemon_e2e_tests tests/replaylog/replaylog_tests
          tests/drivers/serial_tests tests/drivers/hidraw_tests tests/daemon/daemon_can_e2e_tests)
cmake --build build-tsan -j "$jobs" --target posefaird posefair "${threaded[@]##*/}"
# Each binary runs whole (ctest's per-test labels cannot carry a list through gtest discovery).
for t in "${threaded[@]}"; do
  echo "ThreadSanitizer: $t"
  TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1 "build-tsan/$t" --gtest_brief=1
done
