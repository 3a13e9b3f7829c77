#!/usr/bin/env bash
# Peak memory of pis-pack in memory and streamed under a budget (--memory), at demo1's paper
# preset and at a 16 × 16-point space at 640×480 (docs/benchmarks/scale.md, "Bounded memory").
#
# Usage: docs/cluster/memory.sh WORK_DIR [paper|grid|points|all]
#   WORK_DIR  scratch folder (sets of several GB)
#   paper     demo1 --preset paper (64 points at 640×480), packed in memory and with
#             --memory 2; the two files must be the same bytes
#   grid      demo1 at 4 × 4, 8 × 8 and 16 × 16 points at 640×480, packed with --memory 2
#             (and the 4 × 4 also in memory, the same bytes): the streamed peak against
#             the points at a fixed budget
#   points    demo1 at 4 × 4, 8 × 8, 16 × 16 and 24 × 24 points at 320×240, packed with
#             --memory 0.5 (every one of them streams): the streamed peak once the
#             parameter blocks are whole (8 × 8 samples), past 256 points
#
# Runs from the repository root with the release binaries built (cargo build --release);
# PIS_BIN names another folder of them. Sets are traced at 1 sample per pixel: memory does
# not depend on the samples per pixel. Every pack is timed by /usr/bin/time (wall seconds,
# peak resident memory); a streamed pack's report, with each stage's peak, is kept beside
# its file (WORK_DIR/*-streamed.txt).
set -euo pipefail

work=${1:?usage: docs/cluster/memory.sh WORK_DIR [paper|grid|points|all]}
what=${2:-all}
bin=${PIS_BIN:-target/release}
src=samples/demo1
[ -f "$src/scene.toml" ] || { echo "memory.sh: run from the repository root" >&2; exit 1; }
[ -x "$bin/pis-trace" ] && [ -x "$bin/pis-pack" ] || { echo "memory.sh: no pis-trace and pis-pack in $bin (cargo build --release)" >&2; exit 1; }
mkdir -p "$work"

# shellcheck source=docs/cluster/measure.sh
. "$(dirname "$0")/measure.sh"

echo "| space | pack | budget | wall s | peak MiB |"
echo "|---|---|---|---|---|"

if [ "$what" = paper ] || [ "$what" = all ]; then
    set="$work/paper-set"
    [ -f "$set/set.json" ] || "$bin/pis-trace" "$src/scene.toml" -o "$set" --preset paper --spp 1 > /dev/null 2>> "$work/log.txt"
    read -r s m < <(timed "$bin/pis-pack" "$set" -o "$work/paper-held.pis")
    row "paper preset, 64 points at 640×480" "in memory" "-" "$s" "$m"
    read -r s m < <(REPORT="$work/paper-streamed.txt" timed "$bin/pis-pack" "$set" -o "$work/paper-streamed.pis" --memory 2)
    row "paper preset, 64 points at 640×480" "streamed" "2 GiB" "$s" "$m"
    cmp "$work/paper-held.pis" "$work/paper-streamed.pis" || { echo "memory.sh: the streamed pack differs from the pack in memory" >&2; exit 1; }
fi

# demo1 with N samples along each of its two dimensions, traced at 640×480 into $work/grid-N.
grid_set() {
    local n=$1 scene
    scene=$(scene_copy "$n")
    [ -f "$work/grid-$n/set.json" ] || "$bin/pis-trace" "$scene" -o "$work/grid-$n" --resolution 640x480 --spp 1 > /dev/null 2>> "$work/log.txt"
}

if [ "$what" = grid ] || [ "$what" = all ]; then
    grid_set 4
    read -r s m < <(timed "$bin/pis-pack" "$work/grid-4" -o "$work/grid-4-held.pis")
    row "4 × 4 points at 640×480" "in memory" "-" "$s" "$m"
    read -r s m < <(REPORT="$work/grid-4-streamed.txt" timed "$bin/pis-pack" "$work/grid-4" -o "$work/grid-4-streamed.pis" --memory 2)
    row "4 × 4 points at 640×480" "streamed" "2 GiB" "$s" "$m"
    cmp "$work/grid-4-held.pis" "$work/grid-4-streamed.pis" || { echo "memory.sh: the streamed pack differs from the pack in memory" >&2; exit 1; }
    for n in 8 16; do
        grid_set $n
        read -r s m < <(REPORT="$work/grid-$n-streamed.txt" timed "$bin/pis-pack" "$work/grid-$n" -o "$work/grid-$n-streamed.pis" --memory 2)
        row "$n × $n points at 640×480" "streamed" "2 GiB" "$s" "$m"
    done
fi

if [ "$what" = points ] || [ "$what" = all ]; then
    for n in 4 8 16 24; do
        scene=$(scene_copy "$n")
        [ -f "$work/small-$n/set.json" ] || "$bin/pis-trace" "$scene" -o "$work/small-$n" --resolution 320x240 --spp 1 > /dev/null 2>> "$work/log.txt"
        read -r s m < <(REPORT="$work/small-$n-streamed.txt" timed "$bin/pis-pack" "$work/small-$n" -o "$work/small-$n-streamed.pis" --memory 0.5)
        row "$n × $n points at 320×240" "streamed" "0.5 GiB" "$s" "$m"
    done
fi
