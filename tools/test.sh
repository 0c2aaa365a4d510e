#!/usr/bin/env bash
# Every test: set-up (idempotent), the C++ tests through ctest, then pytest over tests/.
set -uo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
bash tools/setup.sh || exit 1
# each stage's header carries the seconds since this script began (CI's budget is 35 minutes)
echo "== C++ tests (ctest) [set-up ended at ${SECONDS} s]"
ctest=.venv/bin/ctest; [ -x "$ctest" ] || ctest=ctest
"$ctest" --test-dir build/py --output-on-failure -j "$(nproc)"
cpp=$?
# Every CUDA kernel of every CUDA object measured by ptxas (registers, stack, spills; each distinct
# kernel once, from a PTX module of its own: tools/cuda_kernel_check.py, on the PTX the build kept
# in build/ptx): over 128 registers or 2 KB of stack, or not measured, fails. No cap since the
# camera pass runs as three stages (bdpt_camera_events.h; bench/results/2026-12-05-shadestack2:
# emission 1,024 B, shade 1,792 B, events 1,984 B, ptxas 16 + 80 + 48 s of CPU, the largest
# 129k PTX lines, 1.5 GB), pt shade (148k lines, ptxas 98 s, 2.1 GB) the largest kernel.
# --record: a kernel whose code (its PTX's digest) is in tools/cuda_kernel_resources.json takes
# ptxas's figures from there, measured on the same code by `tools/cuda_kernel_check.py build/ptx
# --update`; only kernels changed since are measured here (all of them: ~530 s of ptxas CPU).
# The table in build/cuda_kernels.md, the time on its last line
echo "== CUDA kernels (tools/cuda_kernel_check.py) [${SECONDS} s]"
.venv/bin/python tools/cuda_kernel_check.py build/ptx -j 2 --record > build/cuda_kernels.md
kern=$?
tail -1 build/cuda_kernels.md
[ $kern -ne 0 ] && grep FAIL build/cuda_kernels.md && cpp=$kern
# pytest, one process per unit: bpy brings its own OpenImageIO and Embree into the process, and
# same-named test modules in different folders must not meet in one session. A unit is one test
# file, except tests/blender (its files share session fixtures): tests/cycles as one unit was
# CI's critical path (1,237 s of CPU, 2,095 s of wall measured alone, while 4 lanes had room).
# Units run side by side, LANTERN_TEST_LANES at a time (default: the cores, at most 4), longest
# first; each unit's output is printed whole, in order, once all have ended, then the slowest.
lanes=${LANTERN_TEST_LANES:-$(nproc)}
[ "$lanes" -gt 4 ] && lanes=4
[ "$lanes" -lt 1 ] && lanes=1
# each unit's renders on one thread (lantern.session: LANTERN_THREADS sets `threads` 0) where the
# lanes fill the cores: two threads per render beside another lane's took 4-9 % more CPU for the
# same samples (cornell 32x32, pt / cis / bdpt, 2026-12-05)
[ "$lanes" -ge "$(nproc)" ] && export LANTERN_THREADS=${LANTERN_THREADS:-1}
logs=build/test-logs
rm -rf "$logs"; mkdir -p "$logs"
# the longest units first (CPU seconds per unit, bench/results/2026-12-05-ci-time), so that the
# lanes end close together; every other unit after them
units=(tests/python/test_bidirectional.py tests/python/test_volume_bdpt.py
       tests/python/test_light_tracing.py tests/python/test_mitsuba_tungsten.py
       tests/python/test_light_tree.py tests/cycles/test_volumes.py
       tests/render/test_cycles_compare.py tests/cycles/test_volumes_hetero.py
       tests/cycles/test_volumes_vdb.py tests/blender/)
add_unit() { [[ " ${units[*]} " == *" $1 "* ]] || units+=("$1"); }
for f in tests/cycles/test_*.py tests/render/test_*.py; do add_unit "$f"; done
for dir in tests/*/; do
  case "$dir" in tests/cpp/|tests/python/|tests/cycles/|tests/render/) continue ;; esac
  ls "$dir"test_*.py >/dev/null 2>&1 && add_unit "$dir"
done
for f in tests/python/test_*.py; do add_unit "$f"; done
# tests marked `long` (long statistical runs: bench/long_tests.sh) only with LANTERN_TEST_LONG=1
long=(-m "not long")
[ "${LANTERN_TEST_LONG:-0}" = 1 ] && long=()
run_unit() {  # $1: the unit's index; its log and exit status land in $logs
  local unit=${units[$1]} t0=$SECONDS
  .venv/bin/python -m pytest -q -rs "${long[@]}" "${@:2}" "$unit" > "$logs/$1.log" 2>&1
  local rc=$?
  # a file whose tests a -k in "$@" deselects entirely collects nothing (5): not a failure
  [[ $rc -eq 5 && $unit == *.py ]] && rc=0
  echo $rc > "$logs/$1.rc"
  # this subshell's children's user and system CPU (bash's `times`, its second line): pytest's
  times > "$logs/$1.times"
  local cpu; cpu=$(tail -1 "$logs/$1.times")
  echo "(unit wall $((SECONDS - t0)) s, cpu ${cpu/ /+}, ended at ${SECONDS} s)" >> "$logs/$1.log"
}
echo "== pytest: ${#units[@]} units, $lanes side by side [${SECONDS} s]"
running=0
for i in "${!units[@]}"; do
  if [ $running -ge "$lanes" ]; then wait -n; running=$((running - 1)); fi
  run_unit "$i" "$@" &
  running=$((running + 1))
done
wait
py=0
for i in "${!units[@]}"; do
  echo "== pytest ${units[$i]}"
  cat "$logs/$i.log"
  rc=$(cat "$logs/$i.rc" 2>/dev/null || echo 1)
  [ "$rc" -ne 0 ] && py=$rc
done
echo "== the slowest pytest units (wall seconds; lanes ran side by side)"
for i in "${!units[@]}"; do
  w=$(sed -n 's/^(unit wall \([0-9]*\) s.*/\1/p' "$logs/$i.log" 2>/dev/null | tail -1)
  echo "${w:-0} ${units[$i]}"
done | sort -rn | head -12
# stored references (tests/refs) whose key no longer matched: rendered live, correct but slow
stale=$(grep -ho "stored reference [^ ]* is [a-z]*" "$logs"/*.log 2>/dev/null | sort -u)
if [ -n "$stale" ]; then
  echo "== stored references rendered live: store them again (tests/README.md, LANTERN_STORE_REFS=1)"
  echo "$stale"
fi
echo "ctest exit $cpp, pytest exit $py [${SECONDS} s]"
[ $cpp -eq 0 ] && [ $py -eq 0 ]
