#!/usr/bin/env bash
# Line coverage of the parsers reached by the stable fuzz loop (tests/fuzz_parsers.rs, every
# target at its default budget: min(10^4 inputs, 15 s)). Builds the test with
# -Cinstrument-coverage into its own target directory, runs each target with its own
# profile, merges them with llvm-profdata and reports with llvm-cov (both from the
# toolchain's llvm-tools component: `rustup component add llvm-tools`).
#
#   tools/fuzz_coverage.sh            # writes tools/bench-results/fuzz-coverage.json
#
# Environment: PRISM_COVERAGE_DIR (default /tmp/prism-fuzz-coverage) holds the build and
# the profiles.
set -euo pipefail
cd "$(dirname "$0")/.."
work="${PRISM_COVERAGE_DIR:-/tmp/prism-fuzz-coverage}"
mkdir -p "$work/profiles"
rm -f "$work"/profiles/*.profraw
sysroot="$(rustc --print sysroot)"
tools="$sysroot/lib/rustlib/$(rustc -vV | sed -n 's/^host: //p')/bin"
[ -x "$tools/llvm-cov" ] || { echo "llvm-cov missing: rustup component add llvm-tools" >&2; exit 1; }
# Build scripts are instrumented too: their profiles go aside, not into the checkout.
binary="$(CARGO_TARGET_DIR="$work/target" RUSTFLAGS="-Cinstrument-coverage" \
    LLVM_PROFILE_FILE="$work/build-profiles/%p.profraw" \
    cargo test --release --test fuzz_parsers --no-run --message-format=json 2>/dev/null \
    | python3 -c 'import json,sys
for line in sys.stdin:
    m = json.loads(line)
    if m.get("reason") == "compiler-artifact" and m.get("executable") and m["target"]["name"] == "fuzz_parsers":
        print(m["executable"])')"
targets="$("$binary" --list 2>/dev/null | sed -n 's/: test$//p')"
for t in $targets; do
    LLVM_PROFILE_FILE="$work/profiles/$t-%p.profraw" "$binary" --exact "$t" --test-threads 1 >/dev/null
done
"$tools/llvm-profdata" merge -sparse "$work"/profiles/*.profraw -o "$work/all.profdata"
"$tools/llvm-cov" report "$binary" -instr-profile="$work/all.profdata" \
    --ignore-filename-regex='(\.cargo|rustc|/tests/|target)' 2>/dev/null \
    | python3 -c 'import json,sys,datetime,os
rows = {}
for line in sys.stdin:
    f = line.split()
    if len(f) >= 13 and f[0] != "Filename" and not f[0].startswith("-"):
        rows[f[0]] = {"lines": int(f[7]), "missed_lines": int(f[8]), "line_cover_percent": float(f[9].rstrip("%"))}
out = {
    "tool": "tools/fuzz_coverage.sh",
    "date_utc": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M"),
    "what": "line coverage of the workspace sources reached by tests/fuzz_parsers.rs at its default budget (every target), llvm-cov of -Cinstrument-coverage",
    "files": rows,
}
os.makedirs("tools/bench-results", exist_ok=True)
json.dump(out, open("tools/bench-results/fuzz-coverage.json", "w"), indent=1, sort_keys=True)
print(json.dumps({k: v for k, v in rows.items() if k == "TOTAL"}))'
