#!/bin/bash
# The runs of difftest8 (docs/difftest.md; results: bench/results/2026-12-07-difftest8/README.md):
# drawn scenes with media and subsurface beside ray visibility by kind and Cast Shadow off,
# against Cycles, with pt, bdpt, cis, lvc, lt and auto in turn (--integrators), one process at
# a time, nice, one thread, Cycles' side rendered once a case (--cycles-cache), disagreements
# confirmed, not shrunk (--no-shrink). Three sets of seeds, alternating one case each:
#   m1 (from 50000): object / lamp ray visibility with a world or mesh volume (grid volumes
#      too), no subsurface, linking or Cast Shadow off;
#   m2 (from 51000): object / lamp ray visibility beside subsurface, no media, linking or Cast
#      Shadow off;
#   m3 (from 52000): Cast Shadow off in media: a mesh volume that casts no shadow
#      (difftest_features7), an object's or a lamp's Cast Shadow off beside a medium; ray
#      visibility and subsurface allowed (combinations: whatever an integrator hands to pt is
#      "unsupported" under it).
# From 06:45 UTC (m1 drew world fog only, m3 no mesh volume without shadows yet) two more, and
# the loop m4, m5, m2, m3, m1:
#   m4 (from 53000): a mesh volume that casts no shadow (difftest_features7), anything else
#      but linking (ray visibility, subsurface, world fog, lamps without shadows allowed);
#   m5 (from 54000): object / lamp ray visibility beside a mesh volume or a Volume object's
#      grid, no subsurface, linking or Cast Shadow off.
# No motion, strands (D58) or view-dependent graphs (bidirectional by design) in any set.
cd "$(dirname "$0")/.."
O=bench/results/2026-12-07-difftest8
UNTIL=${UNTIL:-07:25}
MOT=(--avoid "motion blur" --avoid "moving camera" --avoid "deformation blur"
     --avoid "moving emitter" --avoid "parented motion" --avoid "camera rotation"
     --avoid "motion steps" --avoid "shutter position" --avoid "moving strands"
     --avoid "motion in fog" --avoid "particle hair" --avoid "curves hair")
LINK=(--avoid "light linking" --avoid "shadow linking")
C=(--profile full --avoid-known --allow "two lights" "${MOT[@]}" --until "$UNTIL"
   --no-shrink --cycles-cache build/difftest8_cycles
   --avoid "view-dependent graph (bidirectional)" --integrators bdpt,cis,lvc,lt,auto,pt)
M1=(--want "ray visibility in fog" --avoid subsurface "${LINK[@]}" --avoid "no shadow"
    --avoid "object no shadow" --seed 50000)
M2=(--want "object ray visibility" --want "lamp ray visibility" --and subsurface
    --avoid "world volume" --avoid volume --avoid "vdb volume" "${LINK[@]}"
    --avoid "no shadow" --avoid "object no shadow" --seed 51000)
M3=(--want "volume no shadow" --want "object no shadow in fog" --want "no shadow in fog"
    "${LINK[@]}" --seed 52000)
M4=(--want "volume no shadow" "${LINK[@]}" --seed 53000)
M5=(--want "ray visibility in fog" --and volume --and "vdb volume" --avoid subsurface
    "${LINK[@]}" --avoid "no shadow" --avoid "object no shadow" --seed 54000)
for n in $(seq 1 ${CASES:-30}); do
    for s in m4 m5 m2 m3 m1; do
        [[ $(date -u +%H:%M) > $UNTIL ]] && break 2
        case $s in m1) A=("${M1[@]}");; m2) A=("${M2[@]}");; m3) A=("${M3[@]}");;
                   m4) A=("${M4[@]}");; m5) A=("${M5[@]}");; esac
        nice .venv/bin/python tools/difftest_run.py "${C[@]}" "${A[@]}" --cases $n \
            --out $O/$s >> $O/$s.log 2>&1
    done
done
