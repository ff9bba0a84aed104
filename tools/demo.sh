#!/usr/bin/env bash
# Builds posefair and fairs the bundled recording (data/demo/broad-07-excerpt.csv: 7 s of a
# real optical tracker at 285.7 Hz), printing a summary and writing build/demo/faired.csv.
set -euo pipefail
cd "$(dirname "$0")/.."
tools/setup-debian.sh
jobs=$(nproc 2>/dev/null || echo 2)
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j "$jobs" --target posefair
mkdir -p build/demo
build/tools/posefair fair data/demo/broad-07-excerpt.csv -o build/demo/faired.csv \
  --order 3 --lambda-r 0.1 --lambda-t 0.5 --eps-r 0.02 --eps-t 0.002 --iterations 100 "$@"
