#!/usr/bin/env bash
# Builds the `prism` Python package (crates/python) into a virtual environment and runs its
# pytest suite against the `prism` binary of the same target directory.
#
#   crates/python/run-tests.sh            # from anywhere; CARGO_TARGET_DIR is honoured
#   PYTHON=python3.9 crates/python/run-tests.sh
#   PRISM_BIN=target/debug/prism crates/python/run-tests.sh   # test this binary, built already
#
# Steps (each timed): a virtual environment under the target directory (kept between runs),
# maturin, NumPy and pytest from the package index (crates/python/requirements-test.txt),
# colour-science when it installs (the ColorChecker cross-check is skipped, with the reason
# printed, when it cannot be imported), the `prism` binary (dev profile) unless PRISM_BIN
# names one, the wheel (maturin, dev profile, sharing the target directory), then pytest.
# .ci/run passes the binary its `cargo test --workspace` built for the CLI tests: `cargo
# build --bin prism` after it compiled prism-image, prism-post, prism-import, prism-render
# and the binary again (63–82 s in clean-clone runs on the 2-core development machine),
# since a test build unifies the dev-dependencies' features into theirs; neither the test
# profile nor --workspace avoided that (measured 2026-12-06).
set -euo pipefail
cd "$(dirname "$0")/../.."
TARGET="${CARGO_TARGET_DIR:-$PWD/target}"
export CARGO_TARGET_DIR="$TARGET"
VENV="$TARGET/python-venv"
PYTHON="${PYTHON:-python3}"

step_start=$SECONDS
step() {
    echo "python-tests: $1 ($((SECONDS - step_start)) s)"
    step_start=$SECONDS
}

if [ ! -x "$VENV/bin/python" ]; then
    "$PYTHON" -m venv "$VENV"
fi
"$VENV/bin/python" -m pip install -q --disable-pip-version-check -r crates/python/requirements-test.txt
if ! "$VENV/bin/python" -m pip install -q --disable-pip-version-check colour-science; then
    echo "python-tests: colour-science did not install; the ColorChecker cross-check will be skipped"
fi
step "virtual environment $VENV ready"

if [ -z "${PRISM_BIN:-}" ]; then
    cargo build --bin prism
    PRISM_BIN="$TARGET/debug/prism"
    step "prism binary built"
fi
if [ ! -x "$PRISM_BIN" ]; then
    echo "python-tests: PRISM_BIN=$PRISM_BIN is not an executable" >&2
    exit 2
fi

rm -rf "$TARGET/python-wheels"
# No --strip: it changes the flags of every crate, which would then be compiled again
# instead of reused from the workspace build.
"$VENV/bin/maturin" build --profile dev --manifest-path crates/python/Cargo.toml \
    --interpreter "$VENV/bin/python" --out "$TARGET/python-wheels"
"$VENV/bin/python" -m pip install -q --disable-pip-version-check --force-reinstall --no-deps \
    "$TARGET"/python-wheels/prism-*.whl
step "wheel built and installed"

PRISM_BIN="$PRISM_BIN" "$VENV/bin/python" -m pytest -q -rs crates/python/tests
step "pytest passed"
