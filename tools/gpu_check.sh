#!/usr/bin/env bash
# The whole GPU check of issue 6 on a bare machine with an NVIDIA GPU, in about 8 minutes:
#   1. build lantern._core with CUDA (sm_90), no Embree, the nanobind module for `python3`;
#      then the executor conformance test (lantern_exec_conformance_cuda), which stops the check
#      at the first primitive of CudaExec that disagrees with its reference;
#   2. pytest tests/python with LANTERN_TEST_BACKENDS=cpu,cuda (strict: an unavailable backend
#      fails instead of skipping; tests needing bpy, Embree or OpenImageIO skip themselves);
#   2b. the self-check of backend auto (python -m lantern gpu-check --again): its verdict, per
#      feature (subsurface, media), fresh;
#   3. tools/gpu_compare.py: CUDA against CPU, per-block z-test, pt/bdpt/lvc/cis, no NaN/Inf;
#      first its feature scenes in a process of their own (subsurface_skin, fog_box, lt too:
#      every subsurface walk and medium stage), then the four scene files;
#   4. bench/gpu_bench.py: rays/s, ms per stage, the paper's Table 1 (cis with/without sorting);
#   5. a short table, printed last.
# Logs and images go under $OUT (default ./gpu_check_out): summary.txt, pytest.txt,
# compare.md, gpu_bench.md, gpu_bench.json, conformance.txt and logs.tar.gz (every log, compare
# PNGs, GPU memory samples, resource_usage.md): seven files, one folder level.
#
# Device tool (docs/gpu.md): run from the repository root, carry the benchmark scenes:
#   run(command="bash tools/gpu_check.sh", carry=["build/bench_scenes"], timeout_s=600)
# Carry: build/bench_scenes/{monkeybox,whiteroom,bedroom}.lantern (~44 MB, git-ignored; made by
# tools/export_bench_scenes.py). Without them the benchmark runs on the committed
# bench/scenes/*.lantern only (and says so). Committed scenes used: bench/scenes/*.lantern.
#
# Options: --prebuilt [DIR] links the CUDA objects tools/gpu_prebuild.sh made beforehand on a
# developer machine (DIR default build/gpu_prebuilt, carried with the working tree; its stamp
# must match these sources, checked first, before the GPU; it never rebuilds them), so the
# build step is the C++ core and the Python module only (about a minute on 16 cores):
#   run(command="bash tools/gpu_check.sh --prebuilt", carry=["build/gpu_prebuilt",
#       "build/bench_scenes"], timeout_s=600)
# --quick: the CUDA backend's own tests, the quick comparison and benchmark, a 200 s budget
# (with --prebuilt, under 4 minutes in all). Every step runs under a timeout from the budget,
# so a hang in one still leaves the table of the others.
#
# Exit: 0 all passed; 1 a step failed; 3 no GPU (nothing run). Environment: PYTHON (python3),
# OUT, GPU_CHECK_JOBS (nproc), GPU_CHECK_BUDGET (seconds, 480), GPU_CHECK_BUILD_DIR
# (build/gpu_check), GPU_CHECK_CPU_ONLY=1 (test this script without a GPU: no build, the
# lantern._core that PYTHON finds, backend cpu, toy sizes), GPU_CHECK_NVIDIA_SMI (nvidia-smi;
# tests point it elsewhere to see the no-GPU path), GPU_CHECK_PYTEST_K (pytest -k for the test
# step; default "cuda": the [cuda] variants of the backend-parametrized tests and
# tests/python/test_cuda_backend.py; everything else runs in CI, the minutes here go to CUDA).
set -u -o pipefail

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
PREBUILT=""
QUICK=0
while [ $# -gt 0 ]; do
    case "$1" in
        --prebuilt)
            PREBUILT="$ROOT/build/gpu_prebuilt"
            if [ $# -gt 1 ] && [ "${2#--}" = "$2" ]; then PREBUILT="$(cd "$2" 2>/dev/null && pwd || echo "$2")"; shift; fi ;;
        --quick) QUICK=1 ;;
        -h|--help) sed -n '2,40p' "${BASH_SOURCE[0]}"; exit 0 ;;
        *) echo "gpu_check: unknown option $1 (--prebuilt [DIR], --quick)" >&2; exit 2 ;;
    esac
    shift
done
PY="${PYTHON:-python3}"
OUT="${OUT:-$ROOT/gpu_check_out}"
DEFAULT_BUDGET=480; [ "$QUICK" = 1 ] && DEFAULT_BUDGET=200
BUDGET="${GPU_CHECK_BUDGET:-$DEFAULT_BUDGET}"
JOBS="${GPU_CHECK_JOBS:-$(nproc 2>/dev/null || echo 4)}"
BUILD="${GPU_CHECK_BUILD_DIR:-$ROOT/build/gpu_check}"
CPU_ONLY="${GPU_CHECK_CPU_ONLY:-0}"
SMI="${GPU_CHECK_NVIDIA_SMI:-nvidia-smi}"
PYTEST_K="${GPU_CHECK_PYTEST_K-cuda}"
mkdir -p "$OUT"
LOG="$(mktemp -d)"
SUMMARY="$OUT/summary.txt"
: > "$SUMMARY"
STATUS=0
START=$SECONDS

say() { echo "gpu_check: $*" | tee -a "$SUMMARY"; }
left() { echo $((BUDGET - (SECONDS - START))); }
step_result() {  # name rc seconds detail
    printf '%-9s %-5s %5ss  %s\n' "$1" "$([ "$2" = 0 ] && echo ok || echo FAIL)" "$3" "$4" \
        >> "$LOG/table.txt"
    [ "$2" = 0 ] || STATUS=1
}
finish() {
    pkill_sampler
    cp "$LOG"/pytest.txt "$OUT/pytest.txt" 2>/dev/null
    cat "$LOG"/compare_features/compare.md "$LOG"/compare/compare.md > "$OUT/compare.md" 2>/dev/null
    cp "$LOG"/bench/gpu_bench.md "$LOG"/bench/gpu_bench.json "$OUT/" 2>/dev/null
    tar -czf "$OUT/logs.tar.gz" -C "$LOG" . 2>/dev/null
    {
        echo
        echo "== gpu_check: $(date -u +%FT%TZ), $((SECONDS - START)) s, device: ${GPU_NAME:-none}"
        [ -f "$LOG/table.txt" ] && cat "$LOG/table.txt"
        [ -f "$LOG/mem_peak.txt" ] && cat "$LOG/mem_peak.txt"
        [ -f "$LOG/bench_summary.txt" ] && cat "$LOG/bench_summary.txt"
        echo "== gpu_check: $([ $STATUS = 0 ] && echo PASSED || echo FAILED) (logs in $OUT)"
    } | tee -a "$SUMMARY"
    rm -rf "$LOG"
    exit $STATUS
}
SAMPLER=""
pkill_sampler() {
    if [ -n "$SAMPLER" ]; then kill "$SAMPLER" 2>/dev/null; wait "$SAMPLER" 2>/dev/null; fi
    SAMPLER=""
    if [ -s "$LOG/gpu_mem.csv" ]; then
        sort -n "$LOG/gpu_mem.csv" | tail -1 |
            awk '{printf "GPU memory peak while comparing and benchmarking: %d MiB\n", $1}' \
            > "$LOG/mem_peak.txt"
    fi
}

# ---- 0. A prebuilt backend that matches these sources (before the GPU: it costs seconds) ----
if [ -n "$PREBUILT" ]; then
    if [ ! -f "$PREBUILT/stamp.txt" ] || ! ls "$PREBUILT"/objects/*.o >/dev/null 2>&1; then
        say "--prebuilt: $PREBUILT has no stamp.txt or objects/*.o: make it with tools/gpu_prebuild.sh and carry it"
        exit 1
    fi
    want="$(head -1 "$PREBUILT/stamp.txt")"
    nvcc_line="$(sed -n 2p "$PREBUILT/stamp.txt")"
    have="$("$PY" tools/gpu_prebuilt_stamp.py --nvcc "$nvcc_line")"
    if [ "$want" != "$have" ]; then
        say "--prebuilt: $PREBUILT is stale (its stamp $want, these sources $have): run tools/gpu_prebuild.sh again"
        exit 1
    fi
    if command -v nvcc >/dev/null 2>&1 && [ "$(nvcc --version | tail -1)" != "$nvcc_line" ]; then
        say "--prebuilt: built by '$nvcc_line', this machine has '$(nvcc --version | tail -1)'"
    fi
    say "--prebuilt: $PREBUILT, stamp $want ($(sed -n 3p "$PREBUILT/stamp.txt"))"
fi

# ---- 0b. A GPU, or a clear message ----
if [ "$CPU_ONLY" = 1 ]; then
    BACKEND=cpu
    GPU_NAME="none (GPU_CHECK_CPU_ONLY=1: backend cpu, toy sizes)"
    say "GPU_CHECK_CPU_ONLY=1: checking this script on the CPU; nothing here tests CUDA"
else
    BACKEND=cuda
    if ! command -v "$SMI" >/dev/null 2>&1 ||
        ! GPU_NAME="$("$SMI" --query-gpu=name,memory.total,driver_version \
                      --format=csv,noheader 2>/dev/null | head -1)" || [ -z "$GPU_NAME" ]; then
        say "no NVIDIA GPU here (nvidia-smi is missing or lists no GPU)."
        say "This check needs the GPU machine: run it through the device tool, see docs/gpu.md."
        exit 3
    fi
    if [ -z "$PREBUILT" ] && ! command -v nvcc >/dev/null 2>&1; then
        say "GPU '$GPU_NAME' found, but no nvcc on PATH: cannot build the CUDA backend"
        exit 3
    fi
    say "GPU: $GPU_NAME; $(nvcc --version 2>/dev/null | tail -1)"
fi
say "python: $($PY --version 2>&1) ($PY); jobs $JOBS; budget ${BUDGET}s"

# ---- 1. Build ----
t=$SECONDS
if [ "$CPU_ONLY" = 1 ]; then
    PYTHONPATH="$ROOT/python" "$PY" -c "import lantern, sys; sys.exit(not lantern.native_available())"
    step_result build $? 0 "skipped (CPU-only check: using the lantern._core this python finds)"
else
    if [ -n "$PREBUILT" ]; then
        CUDA_ARGS=(-DLANTERN_CUDA_PREBUILT="$PREBUILT" -DLANTERN_BUILD_TESTS=OFF)
        TARGETS=(--target _core)
    else
        CUDA_ARGS=(-DLANTERN_CUDA=ON -DCMAKE_CUDA_ARCHITECTURES=90 -DLANTERN_CUDA_RESOURCE_USAGE=ON
                   -DLANTERN_CUDA_PREBUILT=)
        TARGETS=()
    fi
    {
        cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Release -DLANTERN_BUILD_PYTHON=ON \
            -DPython_EXECUTABLE="$(command -v "$PY")" -DLANTERN_EMBREE=OFF "${CUDA_ARGS[@]}" &&
            timeout $(( $(left) - 60 )) cmake --build "$BUILD" -j "$JOBS" "${TARGETS[@]}" &&
            cp "$BUILD"/_core*.so python/lantern/
    } > "$LOG/build.txt" 2>&1
    rc=$?
    [ -n "$PREBUILT" ] && cat "$PREBUILT/build.txt" >> "$LOG/build.txt" 2>/dev/null
    frame=$(grep -o '[0-9]* bytes stack frame' "$LOG/build.txt" | sort -n | tail -1)
    step_result build $rc $((SECONDS - t)) "$(grep -m1 'Lantern: CUDA' "$LOG/build.txt" |
        sed 's/^-- //'); largest kernel stack frame: ${frame:-unknown}"
    if [ $rc != 0 ]; then
        tail -40 "$LOG/build.txt"
        finish
    fi
fi
# ---- 1b. Executor conformance, first: every primitive of CudaExec against its plain reference
# (tests/cpp/exec_conformance.h); a failure names the primitive and stops the check here ----
if [ "$CPU_ONLY" != 1 ]; then
    t=$SECONDS
    "$PY" tools/cuda_resource_table.py "$LOG/build.txt" > "$LOG/resource_usage.md" 2>&1
    CONFORMANCE="$BUILD/lantern_exec_conformance_cuda"
    [ -n "$PREBUILT" ] && CONFORMANCE="$PREBUILT/lantern_exec_conformance_cuda"
    timeout 120 "$CONFORMANCE" > "$LOG/conformance.txt" 2>&1
    rc=$?
    step_result conform $rc $((SECONDS - t)) "$(tail -1 "$LOG/conformance.txt")"
    cp "$LOG/conformance.txt" "$OUT/conformance.txt" 2>/dev/null
    if [ $rc != 0 ]; then
        grep -v ' ok$' "$LOG/conformance.txt" | head -20
        finish
    fi
fi

export PYTHONPATH="$ROOT/python${PYTHONPATH:+:$PYTHONPATH}"
"$PY" -c "import lantern, json; print(json.dumps(lantern.cuda_info()))" > "$LOG/cuda_info.txt" 2>&1
say "cuda_info: $(cat "$LOG/cuda_info.txt")"
if [ "$BACKEND" = cuda ] && ! "$PY" -c "
import sys, lantern.session as s
r = s.backend_unavailable('cuda')
sys.exit(print('CUDA unavailable:', r) or 1 if r else 0)" >> "$SUMMARY" 2>&1; then
    step_result cuda 1 0 "the module cannot use the GPU (see cuda_info above)"
fi

# ---- 2. Tests, per backend ----
t=$SECONDS
if [ "$CPU_ONLY" = 1 ]; then
    TEST_BACKENDS=cpu
    PYTEST_ARGS=(tests/python/test_render.py)
else
    TEST_BACKENDS=cpu,cuda
    PYTEST_ARGS=(tests/python)
    [ "$QUICK" = 1 ] && PYTEST_ARGS=(tests/python/test_cuda_backend.py)
    [ -n "$PYTEST_K" ] && PYTEST_ARGS+=(-k "$PYTEST_K")
fi
tlimit=$(( $(left) - 260 )); [ "$QUICK" = 1 ] && tlimit=$(( $(left) - 100 ))
[ $tlimit -lt 60 ] && tlimit=60
LANTERN_TEST_BACKENDS=$TEST_BACKENDS LANTERN_TEST_BACKENDS_STRICT=1 MPLBACKEND=Agg \
    timeout "$tlimit" "$PY" -m pytest -v -rfEs -p no:cacheprovider --durations=10 \
    "${PYTEST_ARGS[@]}" > "$LOG/pytest.txt" 2>&1
rc=$?
[ $rc = 124 ] && echo "gpu_check: pytest stopped after ${tlimit}s" >> "$LOG/pytest.txt"
step_result pytest $rc $((SECONDS - t)) "$(grep -E '^[0-9]+ (passed|failed)|^=+ .*(passed|failed)' \
    "$LOG/pytest.txt" | tail -1 | tr -d '=')"

# ---- 2b. The self-check of backend "auto" (lantern gpu-check, python/lantern/gpu_selfcheck.py):
# its verdict, per feature, fresh; without a GPU the child's plumbing with the "pass" double ----
t=$SECONDS
ts=$(( $(left) - 150 )); [ $ts -gt 120 ] && ts=120
if [ $ts -lt 30 ]; then
    step_result selfcheck 1 0 "not run: out of time"
elif [ "$BACKEND" = cuda ]; then
    LANTERN_CACHE_DIR="$LOG/selfcheck_cache" timeout $((ts + 20)) "$PY" -m lantern gpu-check \
        --again --timeout "$ts" > "$LOG/selfcheck.txt" 2> "$LOG/selfcheck_err.txt"
    rc=$?
    step_result selfcheck $rc $((SECONDS - t)) "$("$PY" -c "
import json, sys
v = json.load(open(sys.argv[1]))
f = ', '.join(k + (' ok' if x.get('ok') else ' FAIL') for k, x in v.get('features', {}).items())
print(('core ok' if v.get('ok') else 'core FAIL') + (', ' + f if f else '') + ': ' + v['reason'][:160])
" "$LOG/selfcheck.txt" 2>/dev/null || tail -1 "$LOG/selfcheck_err.txt")"
else
    timeout "$ts" "$PY" -m lantern.gpu_selfcheck_run --double pass \
        --cases envmap/pt,skin/pt,fog/pt > "$LOG/selfcheck.txt" 2>&1
    step_result selfcheck $? $((SECONDS - t)) "$(tail -1 "$LOG/selfcheck.txt" | cut -c1-160)"
fi

# ---- 3. CUDA against CPU: the feature scenes first (subsurface walks, medium stages: the code
# least run on a GPU), in a process of their own, so that a device fault there costs neither
# the file scenes' rows nor all their time; then the file scenes ----
if [ "$BACKEND" = cuda ]; then
    ("$SMI" --query-gpu=memory.used --format=csv,noheader,nounits -lms 250 \
        > "$LOG/gpu_mem.csv" 2>/dev/null) &
    SAMPLER=$!
    COMPARE_ARGS=(--backends cpu,cuda)
    [ "$QUICK" = 1 ] && COMPARE_ARGS+=(--quick)
else
    COMPARE_ARGS=(--backends cpu,cpu --quick)
fi
t=$SECONDS
if [ "$(left)" -gt 150 ]; then
    timeout $(( ($(left) - 90) / 2 )) "$PY" tools/gpu_compare.py "${COMPARE_ARGS[@]}" \
        --scenes features --out "$LOG/compare_features" > "$LOG/compare_features.txt" 2>&1
    rc=$?
    step_result compare-f $rc $((SECONDS - t)) "$(tail -1 "$LOG/compare_features.txt")"
else
    step_result compare-f 1 0 "not run: out of time"
fi
t=$SECONDS
if [ "$(left)" -gt 120 ]; then
    timeout $(( $(left) - 90 )) "$PY" tools/gpu_compare.py "${COMPARE_ARGS[@]}" \
        --scenes files --out "$LOG/compare" > "$LOG/compare.txt" 2>&1
    rc=$?
    step_result compare $rc $((SECONDS - t)) "$(tail -1 "$LOG/compare.txt")"
else
    step_result compare 1 0 "not run: out of time"
fi

# ---- 4. Benchmark ----
t=$SECONDS
if [ "$BACKEND" = cuda ]; then
    BENCH_ARGS=(--backend cuda --budget 15)
    [ "$QUICK" = 1 ] && BENCH_ARGS=(--backend cuda --budget 8 --scenes bench_fixture,bench_glossy)
    have=$(ls build/bench_scenes/*.lantern 2>/dev/null | wc -l)
    [ "$have" -eq 0 ] && BENCH_ARGS+=(--scenes bench_fixture,bench_glossy) &&
        say "build/bench_scenes is empty (not carried): benchmarking the committed small scenes"
else
    BENCH_ARGS=(--backend cpu --quick)
fi
if [ "$(left)" -gt 45 ]; then
    timeout $(( $(left) - 15 )) "$PY" bench/gpu_bench.py "${BENCH_ARGS[@]}" \
        --out "$LOG/bench" > "$LOG/bench.txt" 2>&1
    rc=$?
    sed -n '/^== gpu_bench/,$p' "$LOG/bench.txt" > "$LOG/bench_summary.txt"
    step_result bench $rc $((SECONDS - t)) "$(grep -c 'cumulative' "$LOG/bench.txt") runs"
else
    step_result bench 1 0 "not run: out of time"
fi
finish
