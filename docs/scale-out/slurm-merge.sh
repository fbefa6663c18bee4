#!/bin/bash
# Adds the parts of slurm-render.sh into the final image (docs/scale-out.md).
#SBATCH --job-name=prism-merge
#SBATCH --cpus-per-task=1
#SBATCH --mem=8G
#SBATCH --time=01:00:00
#SBATCH --output=prism-merge.log
set -euo pipefail

OUT=${OUT:-parts}
TASKS=${TASKS:-64}
FINAL=${FINAL:-final.exr}
PRISM=${PRISM:-prism}

# Every part by name: a missing one is an error of the shell, not a silent gap.
parts=()
for ((i = 0; i < TASKS; i++)); do
  parts+=("$OUT/part-$i.exr")
done
exec "$PRISM" merge "${parts[@]}" -o "$FINAL"
