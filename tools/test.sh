#!/usr/bin/env bash
# Every test: set-up (idempotent), the C++ tests through ctest, then pytest over tests/.
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
bash tools/setup.sh || exit 1
echo "== C++ tests (ctest)"
ctest=.venv/bin/ctest; [ -x "$ctest" ] || ctest=ctest
"$ctest" --test-dir build/py --output-on-failure
cpp=$?
echo "== Python, Blender and render tests (pytest)"
.venv/bin/python -m pytest -q -rs "$@" tests
py=$?
echo "ctest exit $cpp, pytest exit $py"
[ $cpp -eq 0 ] && [ $py -eq 0 ]
