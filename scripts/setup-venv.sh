#!/usr/bin/env bash
# Creates scripts/.venv with the comparison tools (python-flint, SymPy).
# Only the comparison scripts need it; mms and its tests never do.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
python3 -m venv "$here/.venv"
"$here/.venv/bin/pip" install --quiet python-flint==0.9.0 sympy numpy scipy
echo "ready: $here/.venv/bin/python"
