#!/usr/bin/env bash
# Builds everything and runs the whole test suite with ctest: every test under AddressSanitizer +
# UndefinedBehaviorSanitizer, the tests where threads meet (ctest label `threads`: the rings, the
# replay, serial and hidraw drivers, the daemon pipeline, posefaird end to end) under
# ThreadSanitizer, and on the Release build, as it ships, the programs posefaird and posefair end
# to end (label e2e), the soak and the kernel tests.
# The CAN, HID and GPIO tests (ctest label hw) need kernel interfaces this machine may lack:
# they run once, on the Release build, inside Debian's kernel under qemu (tests/hw/README.md).
# Installs missing Debian packages first. Prints each stage's wall time at the end.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup-debian.sh --tests
jobs=$(nproc 2>/dev/null || echo 2)

stage_names=()
stage_seconds=()
stage_start=$SECONDS
# end_stage NAME: records the wall time since the previous stage ended.
end_stage() {
  stage_names+=("$1")
  stage_seconds+=($((SECONDS - stage_start)))
  stage_start=$SECONDS
}
report_stages() {
  echo "test.sh: wall time per stage"
  for i in "${!stage_names[@]}"; do
    printf '  %-44s %4d:%02d\n' "${stage_names[$i]}" $((stage_seconds[i] / 60)) $((stage_seconds[i] % 60))
  done
  printf '  %-44s %4d:%02d\n' total $((SECONDS / 60)) $((SECONDS % 60))
}

# A sanitizer build runs in the background while the stage before it runs its tests: the tests
# wait on child processes, sockets, timers and the emulated kernel much of the time, and the
# build, at the idle scheduling class (chrt --idle), takes only the CPU they leave. Its output
# goes to a log that is printed when it is waited for.
background_pid=""
background_log=""
low_priority=(chrt --idle 0)
chrt --idle 0 true 2>/dev/null || low_priority=(nice -n 19)  # where SCHED_IDLE is not allowed
start_background_build() {  # LOG CMAKE-BUILD-ARGS...
  background_log=$1
  shift
  "${low_priority[@]}" cmake --build "$@" >"$background_log" 2>&1 &
  background_pid=$!
}
wait_background_build() {
  local status=0
  wait "$background_pid" || status=$?
  background_pid=""
  if ((status != 0)); then
    cat "$background_log"
    echo "test.sh: the build in the background failed (log: $background_log)" >&2
    exit "$status"
  fi
  tail -n 1 "$background_log"
}
on_exit() {
  [[ -n $background_pid ]] && kill -- "$background_pid" 2>/dev/null
  report_stages
}
trap on_exit EXIT
end_stage setup

# Unity builds (CMakeLists.txt, POSEFAIR_UNITY_BUILD): a third less compile time for a build
# from scratch, which is what this script does on a fresh clone.
# The Release build compiles what ships (posefaird, posefair and their libraries, with -Werror at
# -O3), every benchmark, and the test programs that the Release build runs: the binaries end to
# end (label e2e), the soak and the kernel tests (hw). Every other test runs under the sanitizers
# below; their programs are not compiled a third time. (Floating-point results do not depend on
# the optimisation level here: ISO C++ mode contracts no multiply-adds, and the golden replays
# pass bit for bit in both builds.)
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DPOSEFAIR_UNITY_BUILD=ON >/dev/null
cmake --build build -j "$jobs" --target posefaird posefair benchmarks e2e_tests hw_tests
end_stage "release build"

# The sanitizer builds compile at -O1 with line tables only (-g1): what ASan's own documentation
# recommends, and about half the compile time of -O2 -g; reports still name file and line. They
# build no benchmarks and no hw tests (those run only in the VM, below). The test programs' own
# code (not the libraries under test) compiles at -O0 there: their checks run in a few seconds
# either way, and code generation is most of a sanitizer build's time.
sanitizer_flags=(-DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG"
                 -DPOSEFAIR_BUILD_BENCHMARKS=OFF -DPOSEFAIR_BUILD_HW_TESTS=OFF
                 -DPOSEFAIR_UNITY_BUILD=ON -DPOSEFAIR_TEST_OPTIMIZATION=-O0)
cmake -S . -B build-asan -G Ninja "${sanitizer_flags[@]}" -DPOSEFAIR_SANITIZE_ADDRESS=ON >/dev/null
start_background_build build-asan/background-build.log build-asan -j "$jobs"

# The end-to-end tests wait on child processes, sockets and timers more than they compute: twice
# as many at once as there are cores. (The soak runs alone: RUN_SERIAL.) The sanitizer runs below
# are bound by computation, and their timed tests by how fast it goes: one per core there.
ctest --test-dir build --output-on-failure -j "$((2 * jobs))" -L 'e2e|soak'
end_stage "release tests (e2e, soak), asan build beside"
# The CAN, HID and GPIO tests (label hw) against Debian's real kernel, in one qemu boot.
tests/hw/vm/run_hw_tests.sh build
end_stage "kernel VM tests (hw), asan build beside"
wait_background_build
end_stage "asan+ubsan build (the rest)"

# ThreadSanitizer: the test programs labelled `threads` (target threads_tests, which also builds
# posefaird, which they start), and only those; core and the `posefair` client come from the
# Release build (POSEFAIR_PLAIN_BUILD, CMakeLists.txt says why). Built beside the ASan tests.
cmake -S . -B build-tsan -G Ninja "${sanitizer_flags[@]}" -DPOSEFAIR_SANITIZE_THREAD=ON \
  -DPOSEFAIR_PLAIN_BUILD="$PWD/build" >/dev/null
start_background_build build-tsan/background-build.log build-tsan -j "$jobs" --target threads_tests
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-asan --output-on-failure -j "$jobs"
end_stage "asan+ubsan tests, tsan build beside"
wait_background_build
end_stage "tsan build (the rest)"
TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1 \
  ctest --test-dir build-tsan --output-on-failure -j "$jobs" -L threads
end_stage "tsan tests"
