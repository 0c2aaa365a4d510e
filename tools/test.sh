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
# Every CUDA kernel of every CUDA object: bounded to 128 registers, and measured by ptxas where
# that is quick (tools/cuda_kernel_check.py, on the PTX the build kept in build/ptx)
echo "== CUDA kernels (tools/cuda_kernel_check.py)"
.venv/bin/python tools/cuda_kernel_check.py build/ptx --max-lines 6000 -j 2 > build/cuda_kernels.md
kern=$?
tail -1 build/cuda_kernels.md
[ $kern -ne 0 ] && grep FAIL build/cuda_kernels.md && cpp=$kern
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
