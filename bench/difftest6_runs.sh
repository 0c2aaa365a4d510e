#!/bin/bash
# the three runs of difftest6 (docs/difftest.md), started 2026-12-06 23:43 UTC side by side
cd "$(dirname "$0")/.."
O=bench/results/2026-12-07-difftest6
C=(--profile full --avoid-known --allow "two lights" --avoid "vdb volume" --until 00:40 --max-evals 25)
# pt: every tag of the sixth batch
nice .venv/bin/python tools/difftest_run.py --integrator pt --want new6 "${C[@]}" \
    --seed 30000 --cases 30 --out $O/pt > $O/pt.log 2>&1 &
# bdpt: ray visibility by kind and an object's Cast Shadow off on surfaces (no media, no
# subsurface, no linking, no lamp Cast Shadow off: with those bdpt hands ray visibility to pt)
nice .venv/bin/python tools/difftest_run.py --integrator bdpt --want "object ray visibility" \
    --want "lamp ray visibility" --want "object no shadow" "${C[@]}" --avoid "world volume" \
    --avoid volume --avoid subsurface --avoid "light linking" --avoid "shadow linking" \
    --avoid "no shadow" --seed 31000 --cases 30 --out $O/bdpt > $O/bdpt.log 2>&1 &
# cis: Cast Shadow off (object's and lamp's) and shadow linking in fog, the linked lamp beside
# glossy (no ray visibility by kind, which cis hands to pt beside media)
nice .venv/bin/python tools/difftest_run.py --integrator cis --want "object no shadow in fog" \
    --want "no shadow in fog" --want "shadow linking in fog" --want "shadow link beside glossy" \
    --want "object no shadow" "${C[@]}" --avoid "object ray visibility" \
    --avoid "lamp ray visibility" --avoid subsurface --seed 32000 --cases 30 \
    --out $O/cis > $O/cis.log 2>&1 &
wait
# (bdpt restarted at 23:51 with the generator that draws diffuse or glossy hidden alone only
# where no Principled or mixed material is: the same line)
# lt (started 23:50): an object's Cast Shadow off on surfaces, shadow linking in fog (lt hands
# ray visibility by kind, and an object's Cast Shadow off beside media, to pt)
nice .venv/bin/python tools/difftest_run.py --integrator lt --want "object no shadow" \
    --want "shadow linking in fog" --want "shadow link beside glossy" "${C[@]}" \
    --avoid "object ray visibility" --avoid "lamp ray visibility" --avoid subsurface \
    --avoid "object no shadow in fog" --seed 33000 --cases 20 --out $O/lt > $O/lt.log 2>&1
# pt restarted at 00:03 from seed 30001 (30000's shrink, a 4x-sample render of five lamps in fog
# a step, would not finish; examined by hand, README), a shrink budget of 12
nice .venv/bin/python tools/difftest_run.py --integrator pt --want new6 --profile full \
    --avoid-known --allow "two lights" --avoid "vdb volume" --until 00:40 --max-evals 12 \
    --seed 30001 --cases 30 --out $O/pt > $O/pt.log 2>&1
