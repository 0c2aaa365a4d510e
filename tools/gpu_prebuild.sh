#!/usr/bin/env bash
# Builds on a developer machine (nvcc, no GPU needed) what tools/gpu_check.sh --prebuilt links
# on the GPU machine, so that the device's minutes go to tests and the benchmark, not to ptxas
# (about half an hour of one core for the backend's sm_90 SASS):
#   OUT/objects/*.o                       the CUDA backend's objects (SASS for ARCHS, and PTX)
#   OUT/lantern_exec_conformance_cuda     the executor conformance test (statically linked cudart)
#   OUT/resource_usage.md                 registers and stack of every kernel (ptxas -v)
#   OUT/stamp.txt                         the stamp (tools/gpu_prebuilt_stamp.py), nvcc, archs
#   OUT/build.txt                         the build log
# Same configuration as gpu_check.sh's own build (Release, no Embree). Then, on the device:
#   run(command="bash tools/gpu_check.sh --prebuilt", carry=["build/gpu_prebuilt",
#       "build/bench_scenes"], timeout_s=600)
# Usage: tools/gpu_prebuild.sh [OUT] (default build/gpu_prebuilt). Environment:
# GPU_PREBUILD_ARCHS ("90-real;90-virtual"), GPU_PREBUILD_JOBS (nproc),
# GPU_PREBUILD_DIR (the build folder, build/gpu_prebuild).
set -eu -o pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"
OUT="${1:-$ROOT/build/gpu_prebuilt}"
ARCHS="${GPU_PREBUILD_ARCHS:-90-real;90-virtual}"
JOBS="${GPU_PREBUILD_JOBS:-$(nproc 2>/dev/null || echo 2)}"
BUILD="${GPU_PREBUILD_DIR:-$ROOT/build/gpu_prebuild}"
PY="${PYTHON:-python3}"
command -v nvcc >/dev/null || { echo "gpu_prebuild: no nvcc on PATH" >&2; exit 1; }
NVCC="$(nvcc --version | tail -1)"
STAMP="$("$PY" tools/gpu_prebuilt_stamp.py --nvcc "$NVCC")"
mkdir -p "$OUT"
t=$SECONDS
cmake -S . -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release -DLANTERN_BUILD_PYTHON=OFF \
    -DLANTERN_BUILD_TESTS=OFF -DLANTERN_CUDA=ON -DCMAKE_CUDA_ARCHITECTURES="$ARCHS" \
    -DLANTERN_EMBREE=OFF -DLANTERN_CUDA_RESOURCE_USAGE=ON -DLANTERN_CUDA_PREBUILT= \
    > "$OUT/build.txt" 2>&1
cmake --build "$BUILD" -j "$JOBS" --target lantern_core lantern_exec_conformance_cuda \
    >> "$OUT/build.txt" 2>&1 || { tail -30 "$OUT/build.txt"; exit 1; }
rm -rf "$OUT/objects"
mkdir -p "$OUT/objects"
find "$BUILD/CMakeFiles/lantern_core.dir" -name '*.cu.o' -exec cp {} "$OUT/objects/" \;
cp "$BUILD/lantern_exec_conformance_cuda" "$OUT/"
"$PY" tools/cuda_resource_table.py "$OUT/build.txt" > "$OUT/resource_usage.md" 2>&1 || true
if [ "$STAMP" != "$("$PY" tools/gpu_prebuilt_stamp.py --nvcc "$NVCC")" ]; then
    echo "gpu_prebuild: the sources changed during the build; run it again" >&2
    exit 1
fi
{
    echo "$STAMP"
    echo "$NVCC"
    echo "archs $ARCHS, built $(date -u +%FT%TZ) in $((SECONDS - t)) s on $(hostname)"
} > "$OUT/stamp.txt"
echo "gpu_prebuild: $OUT ($(du -sh "$OUT" | cut -f1)), stamp $STAMP, $((SECONDS - t)) s"
