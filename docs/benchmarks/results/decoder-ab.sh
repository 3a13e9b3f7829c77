#!/bin/bash
# The decoding threads' CPU time a frame under two builds of pis-play, runs interleaved so
# that both see the same machine (docs/benchmarks/play.md, "The decoding threads"): FILE.pis
# played along the diagonal, 48 frames, multilinear, 4 rounds of: BEFORE with the workers'
# rebuild and no prefetch, AFTER with the GPU rebuild and prefetch 1 and 0, BEFORE with the
# GPU rebuild and prefetch 1. perf samples the task clock at 1 kHz: a thread's samples are
# its CPU milliseconds.
# Usage: decoder-ab.sh FILE.pis BEFORE_PIS_PLAY AFTER_PIS_PLAY
set -euo pipefail
file=$1 before=$2 after=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
run() {
  perf record -q -F 1000 -e task-clock -o "$tmp/p.data" "$1" "$file" --headless --path diagonal \
    --frames 48 --blend multilinear --rebuild "$2" --prefetch "$3" --texture-precision full --json > /dev/null 2>&1
  perf report -i "$tmp/p.data" -n --sort comm --stdio 2>/dev/null | awk '/pis-decode/ {d += $2} END {printf "%.1f", d / 48}'
}
echo "decoding threads' CPU ms a frame: before (workers, 0) | after (gpu, 1) | after (gpu, 0) | before (gpu, 1)"
for round in 1 2 3 4; do
  echo "$(run "$before" workers 0) | $(run "$after" gpu 1) | $(run "$after" gpu 0) | $(run "$before" gpu 1)"
done
