#!/bin/bash
# Issue 13's CPU speed acceptance in one command: A/B of two built checkouts on fixture_box,
# cornell_box and Monkeybox for pt, lvc and cis: interleaved timed runs (CPU time, 1 and 2
# threads) and callgrind instruction counts of the render steps (load-independent).
#
#   bench/issue13_speed.sh A_CHECKOUT B_CHECKOUT [OUT_DIR]
#
# Each checkout is a source tree whose python/lantern holds its built _core (the dev build's
# symlink: cmake ... -DLANTERN_CUDA=OFF -DCMAKE_CXX_FLAGS_RELEASE="-O2 -DNDEBUG", then
# ln -sf build/dev/python/lantern/_core*.so python/lantern/). Monkeybox is exported once,
# through this checkout's add-on, and both builds render that same .lantern file.
# Knobs (environment): PY (a Python with numpy and bpy), REPS (5), THREADS (1,2), SIZE (128),
# CG_SIZE (64), CG_STEPS (2), SCENES, INTEGRATORS, PARTS (time,callgrind).
# Writes OUT_DIR/machine.txt, OUT_DIR/speed_ab.md, OUT_DIR/callgrind.md. Everything niced.
set -euo pipefail
A=$(realpath "$1"); B=$(realpath "$2"); OUT=${3:-/tmp/issue13_speed}
HERE=$(cd "$(dirname "$0")" && pwd)
PY=${PY:-/work/main/.venv/bin/python}
REPS=${REPS:-5}; THREADS=${THREADS:-1,2}; SIZE=${SIZE:-128}
CG_SIZE=${CG_SIZE:-64}; CG_STEPS=${CG_STEPS:-2}; PARTS=${PARTS:-time,callgrind}
MONKEY=${MONKEY:-/tmp/issue13_monkeybox.lantern}
SCENES=${SCENES:-fixture_box,cornell_box,file:$MONKEY}
INTEGRATORS=${INTEGRATORS:-pt,lvc,cis}
mkdir -p "$OUT"
for d in "$A" "$B"; do
    ls "$d"/python/lantern/_core*.so > /dev/null || { echo "no built _core in $d/python/lantern"; exit 1; }
done
[ -f "$MONKEY" ] || nice "$PY" "$HERE/save_blend_scene.py" monkeybox 128x128 "$MONKEY"

describe() {  # commit, dirty state and the build's flags of checkout $1
    local so cache
    so=$(readlink -f "$1"/python/lantern/_core*.so)
    cache=$(dirname "$so")/CMakeCache.txt
    [ -f "$cache" ] || cache=$(find "$(dirname "$so")/.." -maxdepth 2 -name CMakeCache.txt | head -1)
    echo "$1: $(git -C "$1" log -1 --format='%h %s' | cut -c1-90)$(git -C "$1" diff --quiet HEAD -- native || echo ' (native/ modified)')"
    echo "  _core: $so"
    [ -n "$cache" ] && grep -E '^(CMAKE_BUILD_TYPE|CMAKE_CXX_FLAGS_RELEASE|LANTERN_CUDA|LANTERN_EMBREE|CMAKE_CXX_COMPILER):' "$cache" | sed 's/^/  /'
}
{
    echo "date: $(date -u '+%Y-%m-%d %H:%M UTC')"
    echo "host: $(uname -srm); $(nproc) cores; $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
    echo "memory: $(free -g | awk '/Mem:/ {print $2}') GB; load at start: $(cut -d' ' -f1-3 /proc/loadavg)"
    echo "python: $PY ($("$PY" -c 'import sys; print(sys.version.split()[0])'))"
    echo "A = $(describe "$A")"
    echo "B = $(describe "$B")"
    echo "scenes: $SCENES; integrators: $INTEGRATORS"
} > "$OUT/machine.txt"
cat "$OUT/machine.txt"
if [[ $PARTS == *time* ]]; then
    echo "# timed: $REPS reps, threads $THREADS, ${SIZE}px, 3 steps x 4 spp after a warm-up step" | tee "$OUT/speed_ab.md"
    nice "$PY" "$HERE/cpu_speed_ab.py" --a "$A/python" --b "$B/python" --reps "$REPS" \
        --threads "$THREADS" --size "$SIZE" --scenes "$SCENES" --integrators "$INTEGRATORS" \
        | tee -a "$OUT/speed_ab.md"
    echo "load at end: $(cut -d' ' -f1-3 /proc/loadavg)" | tee -a "$OUT/speed_ab.md"
fi
if [[ $PARTS == *callgrind* ]]; then
    echo "# callgrind: ${CG_SIZE}px, $CG_STEPS steps x 4 spp after a warm-up step, 1 thread" | tee "$OUT/callgrind.md"
    nice "$PY" "$HERE/cpu_speed_ab.py" --a "$A/python" --b "$B/python" --callgrind \
        --cg-steps "$CG_STEPS" --size "$CG_SIZE" --scenes "$SCENES" --integrators "$INTEGRATORS" \
        | tee -a "$OUT/callgrind.md"
fi
