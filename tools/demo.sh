#!/usr/bin/env bash
# The daemon demo: builds posefaird and posefair, starts a subscriber on 127.0.0.1:5700, runs
# posefaird on its bundled default config (data/demo/posefaird.toml: 7 s of a real optical
# tracker, data/demo/broad-07-excerpt.csv, replayed in real time through the replay driver,
# faired and published as wire protocol v1), prints every 100th smoothed pose and the
# statistics of both ends, and exits by itself (about 10 s after the build).
# Extra arguments go to `posefair sub` (e.g. --format csv, --every 1).
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup-debian.sh
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j "$jobs" --target posefaird posefair

build/tools/posefair sub --listen 127.0.0.1:5700 --idle 2 --duration 50 --every 100 --stats "$@" &
sub=$!
trap 'kill $sub 2>/dev/null || true' EXIT
sleep 0.5  # let the subscriber bind before the first datagram
timeout 50 build/daemon/posefaird --config data/demo/posefaird.toml --log-target stderr
wait $sub
trap - EXIT
