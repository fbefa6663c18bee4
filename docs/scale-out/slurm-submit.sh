#!/bin/bash
# Submits the 64 render tasks and a merge that runs once all of them succeeded.
set -euo pipefail
cd "$(dirname "$0")"
render=$(sbatch --parsable --array=0-63 slurm-render.sh)
sbatch --dependency=afterok:"${render%%;*}" --export=ALL,TASKS=64 slurm-merge.sh
