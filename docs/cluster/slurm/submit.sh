#!/usr/bin/env bash
# Submit the three stages of a sharded PIS run to Slurm: trace (array), solve (array, after
# the trace array succeeded), merge (after the solve array succeeded). See docs/CLUSTER.md.
#
# Usage:
#   PIS_SCENE=/shared/scenes/demo1/scene.toml PIS_WORK=/shared/runs/demo1 PIS_SHARDS=32 \
#       [PIS_PRESET=paper] [PIS_PACK_FLAGS='--ratio 384 --representation auto'] \
#       [PIS_NAME=demo1] [PIS_BIN=/shared/pis/bin] docs/cluster/slurm/submit.sh
#
# PIS_SCENE, PIS_WORK and PIS_BIN must be paths every node sees. The jobs inherit this
# environment (--export=ALL). Running it again with the same variables resumes: traced points
# and solved fragments are kept, the merges are idempotent. Prints the three job ids.
set -euo pipefail

: "${PIS_SCENE:?set PIS_SCENE to the scene.toml on shared storage}"
: "${PIS_WORK:?set PIS_WORK to a shared directory}"
: "${PIS_SHARDS:?set PIS_SHARDS to the number of shards}"
case "$PIS_SHARDS" in
    '' | *[!0-9]* | 0*) echo "submit.sh: PIS_SHARDS must be a positive integer, not '$PIS_SHARDS'" >&2; exit 1 ;;
esac
if [ ! -f "$PIS_SCENE" ]; then
    echo "submit.sh: PIS_SCENE: no such file: $PIS_SCENE" >&2
    exit 1
fi
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$PIS_WORK"

trace_job=$(sbatch --parsable --array=0-$((PIS_SHARDS-1)) --export=ALL "$here/trace.sbatch")
trace_job=${trace_job%%;*}  # --parsable prints "id" or "id;cluster"
solve_job=$(sbatch --parsable --array=0-$((PIS_SHARDS-1)) --dependency=afterok:$trace_job --export=ALL "$here/solve.sbatch")
solve_job=${solve_job%%;*}
merge_job=$(sbatch --parsable --dependency=afterok:$solve_job --export=ALL "$here/merge.sbatch")
merge_job=${merge_job%%;*}

echo "trace $trace_job"
echo "solve $solve_job"
echo "merge $merge_job"
