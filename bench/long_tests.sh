#!/usr/bin/env bash
# The tests marked `long` (pyproject.toml): statistical comparisons too long for CI, e.g.
# test_bidirectional's principled and features scenes. Run them before merging a change to the
# integrators or the BSDFs, on a quiet machine: bench/long_tests.sh [pytest args]
set -euo pipefail
cd "$(dirname "$0")/.."
exec .venv/bin/python -m pytest -q -rs -m long "$@" tests
