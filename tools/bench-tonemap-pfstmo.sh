#!/usr/bin/env bash
# Whole-process timing of pfstmo's operators on the same 3840×2160 float EXR that
# bench-post uses, in the same run as bench-post, printing one JSON object:
#   pfsin in.exr | pfstmo_X | pfsout out.png      (X = reinhard02, drago03, durand02)
# plus, when Python's cv2 is importable (or installable from PyPI), OpenCV's
# createTonemapDrago / createTonemapReinhard (Reinhard & Devlin 2005, not 2002) compute
# time on the same pixels. Installs pfstools + pfstmo (Debian) if missing; where that is not
# possible the peers are skipped and Prism is still measured.
#
# usage: [PFS_RUNS=N] tools/bench-tonemap-pfstmo.sh [RUNS] [--with-prism]
#   PFS_RUNS (default RUNS) repeats of each pfstmo pipeline (durand02 takes ~1 min).
#   --with-prism also runs `bench-post` (compute + in-process tonemap_file) first and nests
#   its JSON under "prism", so both sides share the machine state.
# The latest run is kept as tools/bench-results/bench-tonemap-pfstmo.json (redirect stdout).
set -euo pipefail
RUNS=${1:-3}
PFS_RUNS=${PFS_RUNS:-$RUNS}
WITH_PRISM=${2:-}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT

if ! command -v pfstmo_reinhard02 >/dev/null || ! command -v pfsin >/dev/null; then
    export DEBIAN_FRONTEND=noninteractive
    apt-get install -y --no-install-recommends pfstools pfstmo >/dev/null 2>&1 ||
        { apt-get update >/dev/null 2>&1 &&
            apt-get install -y --no-install-recommends pfstools pfstmo >/dev/null 2>&1; } || true
fi
# Without pfstools (no apt, no network) the peers are skipped ("pfstmo": {}, "opencv": null)
# and Prism is still measured.
HAVE_PFS=0
if command -v pfstmo_reinhard02 >/dev/null && command -v pfsin >/dev/null; then HAVE_PFS=1; fi

cd "$ROOT"
cargo build --release -q -p bench-post
BENCH="$ROOT/target/release/bench-post"
"$BENCH" --write-input "$WORK/in.exr" 3840 2160

median() { sort -g | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
now() { date +%s.%N; }

PFS_JSON=""
for op in reinhard02 drago03 durand02; do
    [ "$HAVE_PFS" = 1 ] || { echo "pfstools not available: pfstmo skipped" >&2; break; }
    times=()
    for _ in $(seq "$PFS_RUNS"); do
        t0=$(now)
        pfsin "$WORK/in.exr" 2>/dev/null | "pfstmo_$op" 2>/dev/null | pfsout "$WORK/out_$op.png"
        t1=$(now)
        times+=("$(echo "$t1 - $t0" | bc -l)")
    done
    m=$(printf '%s\n' "${times[@]}" | median)
    PFS_JSON+="${PFS_JSON:+, }\"$op\": {\"whole_process_s\": $m, \"runs_s\": [$(IFS=,; echo "${times[*]}")]}"
done

# OpenCV's PyPI wheels may lack an EXR reader: hand it the same pixels as PFM.
CV_JSON="null"
[ "$HAVE_PFS" = 1 ] && pfsin "$WORK/in.exr" 2>/dev/null | pfsout "$WORK/in.pfm"
if [ "$HAVE_PFS" = 1 ] && { python3 -c "import cv2" 2>/dev/null || python3 -m pip install -q opencv-python-headless >/dev/null 2>&1; }; then
    CV_JSON=$(python3 - "$WORK/in.pfm" "$RUNS" <<'PY' 2>/dev/null || echo null
import sys, time, json
import cv2
cv2.setNumThreads(2)
path, runs = sys.argv[1], int(sys.argv[2])
img = cv2.imread(path, cv2.IMREAD_UNCHANGED)
out = {"version": cv2.__version__, "threads": cv2.getNumThreads()}
for name, make in [("drago03", lambda: cv2.createTonemapDrago(1.0, 1.0, 0.85)),
                   ("reinhard05", lambda: cv2.createTonemapReinhard(1.0, 0.0, 0.0, 0.0))]:
    op = make(); ts = []
    for _ in range(runs):
        t = time.perf_counter(); op.process(img); ts.append(time.perf_counter() - t)
    out[name] = {"compute_s": sorted(ts)[len(ts) // 2]}
print(json.dumps(out))
PY
)
fi

PRISM_JSON="null"
if [ "$WITH_PRISM" = "--with-prism" ]; then
    PRISM_JSON=$(RAYON_NUM_THREADS=2 "$BENCH" 3840 2160 "$RUNS")
fi

cat <<JSON
{
  "width": 3840, "height": 2160, "runs": $RUNS,
  "pfstmo_version": "$(dpkg-query -W -f='${Version}' pfstmo 2>/dev/null || echo unknown)",
  "pfstmo": {$PFS_JSON},
  "opencv": $CV_JSON,
  "prism": $PRISM_JSON
}
JSON
