#!/usr/bin/env bash
# Creates tools/peers/.venv (git-ignored) with the pinned peers of tools/peers/*.py:
# embreex (Intel Embree 4 through Python, from the Python package index) and numpy.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
python="${PYTHON:-python3}"
[ -x "$here/.venv/bin/python" ] || "$python" -m venv "$here/.venv"
"$here/.venv/bin/pip" install -q --upgrade pip
"$here/.venv/bin/pip" install -q -r "$here/requirements.txt"
"$here/.venv/bin/python" -c "import embreex, numpy; print('embreex ready')"
