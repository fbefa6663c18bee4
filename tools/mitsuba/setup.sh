#!/usr/bin/env bash
# Creates tools/mitsuba/.venv with the pinned Mitsuba 3 / Dr.Jit / numpy / OpenEXR and makes
# Mitsuba's LLVM variants (llvm_ad_*) usable: Dr.Jit 1.0 needs libLLVM, and crashes with
# LLVM 15 (Debian bookworm's default libllvm15), so this installs Debian's libllvm19 when it
# can and checks that `llvm_ad_spectral` runs. The tools find the library themselves
# (tools/mitsuba/common.py sets DRJIT_LIBLLVM_PATH); to use it elsewhere:
#   export DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
venv="$here/.venv"
python="${PYTHON:-python3}"

if [ ! -x "$venv/bin/python" ]; then
    "$python" -m venv "$venv"
fi
"$venv/bin/pip" install -q --upgrade pip
"$venv/bin/pip" install -q -r "$here/requirements.txt"

find_llvm() {
    for p in /usr/lib/x86_64-linux-gnu/libLLVM.so.19.1 /usr/lib/x86_64-linux-gnu/libLLVM-19.so \
             /usr/lib/llvm-19/lib/libLLVM.so.19.1 /usr/lib/llvm-19/lib/libLLVM-19.so; do
        [ -e "$p" ] && { echo "$p"; return 0; }
    done
    return 1
}

llvm="$(find_llvm || true)"
if [ -z "$llvm" ]; then
    if command -v apt-get >/dev/null 2>&1 && [ "$(id -u)" = 0 ]; then
        echo "installing libllvm19 (Debian) for Mitsuba's llvm_ad_* variants…" >&2
        apt-get update -qq >/dev/null 2>&1 || true
        DEBIAN_FRONTEND=noninteractive apt-get install -y -q libllvm19 >/dev/null 2>&1 \
            || echo "apt-get install libllvm19 failed: only the scalar_* variants will work" >&2
    else
        echo "libLLVM 19 not found and apt-get unavailable (or not root): install libllvm19" \
             "to use Mitsuba's llvm_ad_* variants; scalar_* work without it" >&2
    fi
    llvm="$(find_llvm || true)"
fi

if [ -n "$llvm" ]; then
    if DRJIT_LIBLLVM_PATH="$llvm" "$venv/bin/python" - <<'PY'
import mitsuba as mi, drjit as dr
mi.set_variant("llvm_ad_spectral")
x = dr.arange(mi.Float, 8) * 2
dr.eval(x)
assert float(dr.sum(x)[0]) == 56.0
PY
    then
        echo "llvm_ad_spectral works (DRJIT_LIBLLVM_PATH=$llvm)"
    else
        echo "llvm_ad_spectral does not run with $llvm: only the scalar_* variants will work" >&2
    fi
fi
"$venv/bin/python" -c "import mitsuba as mi, drjit as dr; print('mitsuba', mi.__version__, 'drjit', dr.__version__)"
