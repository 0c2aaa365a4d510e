#!/usr/bin/env bash
# CI's suite (tools/test.sh) with every stored reference (tests/refs, lantern.testing.refs)
# rendered again and required to agree with its file: what the stored sets stand for, checked
# outside CI (it costs what CI cost before the references were stored, ~20 CPU-minutes more).
# Run it after a change that may move an expected image (a BSDF, a light, the exporter), on a
# quiet machine: bench/verify_refs.sh [pytest args]
cd "$(dirname "$0")/.."
LANTERN_VERIFY_REFS=1 exec bash tools/test.sh "$@"
