#!/usr/bin/env bash
# How pis-trace and pis-pack scale with the number of parameter points and the resolution,
# and what splitting them over two local processes gains (docs/benchmarks/scale.md, "Scale").
#
# Usage: docs/cluster/scaling.sh WORK_DIR [SIDES]
#   WORK_DIR  scratch folder (scene copies, sets, files; several GB at the largest sizes)
#   SIDES     samples per dimension of demo1's light × view space to measure, default
#             "4 8 16" (16, 64 and 256 points)
#
# Runs from the repository root with the release binaries built (cargo build --release);
# PIS_BIN names another folder of them. Every run is timed by /usr/bin/time: wall seconds and
# peak resident memory. demo1 is traced at 1 sample per pixel: the figures are of the
# toolchain's work, and tracing cost grows with the samples per pixel on top.
set -euo pipefail

work=${1:?usage: docs/cluster/scaling.sh WORK_DIR [SIDES]}
sides=${2:-4 8 16}
bin=${PIS_BIN:-target/release}
src=samples/demo1
[ -f "$src/scene.toml" ] || { echo "scaling.sh: run from the repository root" >&2; exit 1; }
[ -x "$bin/pis-trace" ] && [ -x "$bin/pis-pack" ] || { echo "scaling.sh: no pis-trace and pis-pack in $bin (cargo build --release)" >&2; exit 1; }
mkdir -p "$work"

# shellcheck source=docs/cluster/measure.sh
. "$(dirname "$0")/measure.sh"

echo "| run | points | resolution | wall s | peak MiB |"
echo "|---|---|---|---|---|"
measure() { # side resolution
    local n=$1 res=$2 scene set
    scene=$(scene_copy "$n")
    set="$work/set-$n-$res"
    rm -rf "$set"
    read -r s m < <(timed "$bin/pis-trace" "$scene" -o "$set" --resolution "$res" --shading-cells 4096 --spp 1)
    row "pis-trace" $((n * n)) "$res" "$s" "$m"
    read -r s m < <(timed "$bin/pis-pack" "$set" -o "$work/demo1-$n-$res.pis")
    row "pis-pack" $((n * n)) "$res" "$s" "$m"
}
for n in $sides; do
    measure "$n" 320x240
done
for res in 640x480 1280x960; do
    measure 4 "$res"
done

# Two local processes against one: the trace and the pack of the 64-point set at 320x240.
n=8 res=320x240
scene=$(scene_copy $n)
set="$work/shards-$n-$res"
rm -rf "$set" "$work/solved"
read -r s m < <(timed "$bin/pis-trace" "$scene" -o "$set" --resolution $res --shading-cells 4096 --spp 1 --threads 1)
row "pis-trace, 1 process, 1 thread" 64 $res "$s" "$m"
start=$(date +%s.%N)
"$bin/pis-trace" "$scene" -o "$set" --resolution $res --shading-cells 4096 --spp 1 --threads 1 --shard 0/2 > /dev/null 2>> "$work/log.txt" &
"$bin/pis-trace" "$scene" -o "$set" --resolution $res --shading-cells 4096 --spp 1 --threads 1 --shard 1/2 > /dev/null 2>> "$work/log.txt" &
wait
row "pis-trace --shard I/2, 2 processes of 1 thread" 64 $res "$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.2f", b - a }')" "-"
read -r s m < <(RAYON_NUM_THREADS=1 timed "$bin/pis-pack" "$set" -o "$work/one.pis")
row "pis-pack, 1 process, 1 thread" 64 $res "$s" "$m"
start=$(date +%s.%N)
RAYON_NUM_THREADS=1 "$bin/pis-pack" solve "$set" --shard 0/2 --fragments "$work/solved" > /dev/null 2>> "$work/log.txt" &
RAYON_NUM_THREADS=1 "$bin/pis-pack" solve "$set" --shard 1/2 --fragments "$work/solved" > /dev/null 2>> "$work/log.txt" &
wait
solve=$(awk -v a="$start" -v b="$(date +%s.%N)" 'BEGIN { printf "%.2f", b - a }')
row "pis-pack solve --shard I/2, 2 processes of 1 thread" 64 $res "$solve" "-"
read -r s m < <(RAYON_NUM_THREADS=1 timed "$bin/pis-pack" merge "$set" --fragments "$work/solved" -o "$work/merged.pis")
row "pis-pack merge, 1 thread" 64 $res "$s" "$m"
cmp -s "$work/one.pis" "$work/merged.pis" && echo "(the merged file is the single process's, byte for byte)" || { echo "scaling.sh: the merged file differs from the single process's" >&2; exit 1; }
