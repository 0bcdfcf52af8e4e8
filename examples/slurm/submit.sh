#!/bin/bash
# Renders SCENE on a Slurm cluster in SHARDS shards of SPP samples per pixel each (SHARDS·SPP
# in all) and merges them:
#   bash examples/slurm/submit.sh SCENE OUT SHARDS SPP [extra sbatch options]
# Run it in the directory the outputs go to (shared by the nodes). Prints the two job ids.
set -euo pipefail
if [ $# -lt 4 ]; then
    echo "usage: $0 SCENE OUT SHARDS SPP [sbatch options]" >&2
    exit 2
fi
scene=$1 out=$2 shards=$3 spp=$4
shift 4
here=$(cd "$(dirname "$0")" && pwd)
export SCENE=$scene OUT=$out SPP=$spp SHARDS=$shards
array=$(sbatch --parsable "$@" --array=0-$((shards - 1)) --export=ALL "$here/render.sbatch")
array=${array%%;*}
merge=$(sbatch --parsable "$@" --dependency=afterok:"$array" --kill-on-invalid-dep=yes \
    --export=ALL "$here/merge.sbatch")
merge=${merge%%;*}
echo "$array $merge"
