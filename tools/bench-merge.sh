#!/bin/bash
# Measures `prism merge` of N sample-range parts of one render (docs/scale-out.md):
# renders N one-sample parts of the Cornell box at WIDTHxHEIGHT, then times the merge.
# Prints JSON; writes it to tools/bench-results/merge.json when RECORD=1.
# Usage: tools/bench-merge.sh [PARTS] [WIDTHxHEIGHT]   (default 16 1920x1080)
set -euo pipefail
cd "$(dirname "$0")/.."
parts=${1:-16}
resolution=${2:-1920x1080}
prism=${PRISM:-target/release/prism}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
list=()
for ((i = 0; i < parts; i++)); do
  "$prism" render scenes/cornell-box.json --resolution "$resolution" --spp "$parts" \
    --samples "$i..$((i + 1))" -o "$work/part-$i.exr" --progress none 2>/dev/null
  list+=("$work/part-$i.exr")
done
part_bytes=$(stat -c %s "$work/part-0.exr")
start=$(date +%s.%N)
"$prism" merge "${list[@]}" -o "$work/final.exr" 2>/dev/null
end=$(date +%s.%N)
final_bytes=$(stat -c %s "$work/final.exr")
json=$(printf '{"parts": %d, "resolution": "%s", "merge_s": %.3f, "part_bytes": %d, "final_bytes": %d, "cpus": %d}' \
  "$parts" "$resolution" "$(echo "$end - $start" | bc -l)" "$part_bytes" "$final_bytes" "$(nproc)")
echo "$json"
if [ "${RECORD:-0}" = 1 ]; then
  echo "$json" > tools/bench-results/merge.json
fi
