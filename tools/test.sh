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
# One pytest process per folder: bpy brings its own OpenImageIO and Embree into the process, and
# same-named test modules in different folders must not meet in one session.
py=0
for dir in tests/*/; do
  [ "$dir" = "tests/cpp/" ] && continue
  ls "$dir"test_*.py >/dev/null 2>&1 || continue
  echo "== pytest $dir"
  .venv/bin/python -m pytest -q -rs "$@" "$dir"
  rc=$?
  [ $rc -ne 0 ] && py=$rc
done
echo "ctest exit $cpp, pytest exit $py"
[ $cpp -eq 0 ] && [ $py -eq 0 ]
