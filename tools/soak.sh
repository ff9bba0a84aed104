#!/usr/bin/env bash
# The soak with injected faults (docs/reliability.md): runs the real posefaird for DURATION
# seconds (at least 60) with 16 streams at 1 kHz and injects SIGHUP with good and bad configs, a
# serial unplug, a full recording volume, SIGKILL and a restart, subscriber churn, a CLOCK_REALTIME
# step and CPU starvation; checks the accounting, leaks, the watchdog and every sequence number,
# and prints latency per fault. Exit status 1 when a check fails.
#
#   tools/soak.sh DURATION [BUILD_DIR]     (BUILD_DIR default: build; builds posefaird and posefair)
#   POSEFAIR_SOAK_NO_BUILD=1 tools/soak.sh 60 build-asan    (use the binaries as they are: ctest)
#
# Needs root: the recordings go to a 48 MiB tmpfs in a mount namespace of the soak's own
# (unshare -m), so filling it touches nothing else. The daemon's CLOCK_REALTIME is stepped with
# libfaketime (LD_PRELOAD, a timestamp file changed at run time; the monotonic clock is not
# faked); the host's clock is never touched.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(dirname "$here")"
duration="${1:?usage: tools/soak.sh DURATION [BUILD_DIR]}"
build="${2:-$repo/build}"
[[ "$build" = /* ]] || build="$PWD/$build"

if [[ -z "${POSEFAIR_SOAK_IN_NAMESPACE:-}" ]]; then
  if [[ $(id -u) -ne 0 ]]; then
    echo "soak: needs root (a mount namespace with a small tmpfs for the recording volume)" >&2
    exit 77
  fi
  if [[ -z "${POSEFAIR_SOAK_NO_BUILD:-}" ]]; then
    "$repo/tools/setup-debian.sh" --tests
    cmake -S "$repo" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
    cmake --build "$build" -j "$(nproc 2>/dev/null || echo 2)" --target posefaird posefair
  fi
  # A private mount namespace: the tmpfs mounted below is seen by nothing outside this soak.
  exec env POSEFAIR_SOAK_IN_NAMESPACE=1 unshare -m --propagation private "$0" "$@"
fi

work="$(mktemp -d /tmp/posefair-soak.XXXXXX)"
cleanup() {
  umount "$work/recordings" 2>/dev/null || true
  [[ -n "${POSEFAIR_SOAK_KEEP:-}" ]] || rm -rf "$work"
}
trap cleanup EXIT
mkdir "$work/recordings"
mount -t tmpfs -o size=48m,mode=0755 posefair-soak "$work/recordings"

faketime_lib=$(ls /usr/lib/*/faketime/libfaketimeMT.so.1 2>/dev/null | head -n 1 || true)
if [[ -z "$faketime_lib" ]]; then
  echo "soak: libfaketime is missing (tools/setup-debian.sh --tests installs it)" >&2
  exit 1
fi
asan=()
# Not `ldd | grep -q`: grep -q leaves at the first match, ldd may then die of SIGPIPE, and with
# pipefail the test is false: the ASan daemon's RSS was judged like a plain one's (and failed).
if [[ "$(ldd "$build/daemon/posefaird")" == *libasan* ]]; then asan=(--asan); fi

echo "soak: $duration s, binaries from $build, work in $work (POSEFAIR_SOAK_KEEP=1 keeps it)"
python3 "$here/soak.py" --duration "$duration" --posefaird "$build/daemon/posefaird" \
  --posefair "$build/tools/posefair" --work "$work" --recordings "$work/recordings" \
  --faketime-lib "$faketime_lib" "${asan[@]}"
