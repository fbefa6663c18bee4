#!/bin/bash
# Measures `prism merge` of N sample-range parts of one render (docs/scale-out.md):
# renders N one-sample parts of the Cornell box at WIDTHxHEIGHT, then times the merge.
# Prints JSON (with the merge's peak resident memory, from GNU time); writes it to
# tools/bench-results/merge.json when RECORD=1.
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
/usr/bin/time -f %M -o "$work/rss_kb" "$prism" merge "${list[@]}" -o "$work/final.exr" 2>/dev/null
end=$(date +%s.%N)
rss_mb=$(( $(tail -1 "$work/rss_kb") / 1024 ))
load=$(cut -d' ' -f1 /proc/loadavg)
final_bytes=$(stat -c %s "$work/final.exr")
json=$(printf '{"parts": %d, "resolution": "%s", "merge_s": %.3f, "merge_peak_rss_mb": %d, "part_bytes": %d, "final_bytes": %d, "cpus": %d, "load_1min_after": %s, "binary": "%s"}' \
  "$parts" "$resolution" "$(echo "$end - $start" | bc -l)" "$rss_mb" "$part_bytes" "$final_bytes" "$(nproc)" "$load" "$prism")
echo "$json"
if [ "${RECORD:-0}" = 1 ]; then
  echo "$json" > tools/bench-results/merge.json
fi
