#!/bin/bash
# One sample range of a Prism render per array task (docs/scale-out.md).
# Submit with slurm-submit.sh, which makes the merge job depend on this array.
#SBATCH --job-name=prism-part
#SBATCH --array=0-63
#SBATCH --cpus-per-task=16
#SBATCH --time=04:00:00
#SBATCH --requeue
#SBATCH --signal=B:TERM@300
#SBATCH --output=prism-part-%a.log
set -euo pipefail

# What to render; override on the sbatch line with --export=ALL,SCENE=…,SPP=…
SCENE=${SCENE:-scene.json}
SPP=${SPP:-4096}
OUT=${OUT:-parts}
PRISM=${PRISM:-prism}
# Extra options every part passes alike (they must not change between parts).
PRISM_ARGS=${PRISM_ARGS:-}

task=${SLURM_ARRAY_TASK_ID:?run as a Slurm array task}
tasks=${SLURM_ARRAY_TASK_COUNT:?run as a Slurm array task}
# Task i renders [⌊i·SPP/n⌋, ⌊(i+1)·SPP/n⌋): the ranges tile [0, SPP) exactly.
first=$(( task * SPP / tasks ))
end=$(( (task + 1) * SPP / tasks ))
mkdir -p "$OUT"
part="$OUT/part-$task.exr"
checkpoint="$OUT/part-$task.partial.exr"

# A requeued or pre-empted task continues from its checkpoint.
resume=()
if [ -f "$checkpoint" ]; then
  resume=(--resume "$checkpoint")
fi
threads=()
if [ -n "${SLURM_CPUS_PER_TASK:-}" ]; then
  threads=(--threads "$SLURM_CPUS_PER_TASK")
fi

# exec: Slurm's SIGTERM (time limit, pre-emption) reaches prism, which writes the
# checkpoint and exits; a requeued task then resumes.
# shellcheck disable=SC2086
exec "$PRISM" render "$SCENE" --spp "$SPP" --samples "$first..$end" -o "$part" \
  "${threads[@]}" "${resume[@]}" --checkpoint-every 10m \
  --progress plain --progress-every 60s --stats-json "$OUT/part-$task.stats.json" $PRISM_ARGS
