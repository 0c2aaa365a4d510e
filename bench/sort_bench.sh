#!/usr/bin/env bash
# Builds and runs bench/sort_bench.cpp (CPU only): g++ against the CCCL (Thrust) headers that
# come with the CUDA toolkit; prints a Markdown table.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
cccl=${CCCL_INCLUDE:-$(ls -d /usr/local/cuda*/include/cccl 2>/dev/null | head -1)}
[ -d "$cccl" ] || { echo "sort_bench: CCCL headers not found (set CCCL_INCLUDE)" >&2; exit 1; }
out=${TMPDIR:-/tmp}/lantern_sort_bench
g++ -O2 -std=c++17 -DTHRUST_DEVICE_SYSTEM=THRUST_DEVICE_SYSTEM_CPP -DTHRUST_HOST_SYSTEM=THRUST_HOST_SYSTEM_CPP \
    -I"$cccl" "$here/sort_bench.cpp" -o "$out"
echo "machine: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | xargs), $(nproc) cpus; single thread"
"$out"
