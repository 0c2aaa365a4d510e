#!/usr/bin/env bash
# The tests marked `long` (pyproject.toml): statistical comparisons too long for CI, e.g.
# test_bidirectional's principled and features scenes. Run them before merging a change to the
# integrators or the BSDFs, on a quiet machine: bench/long_tests.sh [pytest args]
# One pytest process per test folder, as tools/test.sh: same-named test modules in tests/python
# and tests/cycles (test_volumes.py, test_light_linking.py, ...) cannot meet in one session (one
# session over tests/ stopped at collection with 4 errors), and bpy's folders want their own.
set -uo pipefail
cd "$(dirname "$0")/.."
rc=0
for dir in tests/*/; do
  case "$dir" in tests/cpp/) continue ;; esac
  ls "$dir"test_*.py >/dev/null 2>&1 || continue
  echo "== $dir"
  .venv/bin/python -m pytest -q -rs -m long "$@" "$dir"
  r=$?
  # a folder without long tests collects nothing (5): not a failure
  [ $r -ne 0 ] && [ $r -ne 5 ] && rc=$r
done
exit $rc
