"""Shared helpers for the Mitsuba 3 comparison tools (tools/mitsuba/*.py).

Setup: `bash tools/mitsuba/setup.sh` (venv in tools/mitsuba/.venv with the pinned
requirements; it also installs Debian's libllvm19 for Mitsuba's `llvm_ad_*` variants).
"""

import os
import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[2]

# Debian's libllvm19 (bookworm package `libllvm19`). Dr.Jit 1.0 crashes with LLVM 15, the
# version bookworm's default `libllvm15` provides, so it must be pointed at 19 explicitly.
LIBLLVM_CANDIDATES = [
    "/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1",
    "/usr/lib/x86_64-linux-gnu/libLLVM-19.so",
    "/usr/lib/llvm-19/lib/libLLVM.so.19.1",
    "/usr/lib/llvm-19/lib/libLLVM-19.so",
]


def find_libllvm():
    """Path of a usable libLLVM (19) or None; honours an existing DRJIT_LIBLLVM_PATH."""
    env = os.environ.get("DRJIT_LIBLLVM_PATH")
    if env and os.path.exists(env):
        return env
    for p in LIBLLVM_CANDIDATES:
        if os.path.exists(p):
            return p
    return None


def import_mitsuba():
    """Imports mitsuba after pointing Dr.Jit at libLLVM 19 (must happen before the import)."""
    lib = find_libllvm()
    if lib:
        os.environ["DRJIT_LIBLLVM_PATH"] = lib
    import drjit as dr  # noqa: F401
    import mitsuba as mi

    return mi


def has_llvm_variant(mi):
    """True if `llvm_ad_spectral` can be selected and runs a tiny kernel."""
    if find_libllvm() is None:
        return False
    try:
        mi.set_variant("llvm_ad_spectral")
        import drjit as dr

        x = dr.arange(mi.Float, 4) * 2
        dr.eval(x)
        return True
    except Exception:  # noqa: BLE001 - any failure means "not available here"
        return False
