#!/bin/bash
# The runs of difftest6 (docs/difftest.md; results and what happened to each run:
# bench/results/2026-12-07-difftest6/README.md), side by side, nice, one thread each.
# pt started at 23:43 from seed 30000; its first case's shrink was stopped and the run
# restarted at 00:03 from 30001 with a shrink budget of 12 (the line below); bdpt restarted at
# 23:50 with the generator of that time; lt started at 23:50 and was stopped at 00:00.
cd "$(dirname "$0")/.."
O=bench/results/2026-12-07-difftest6
C=(--profile full --avoid-known --allow "two lights" --avoid "vdb volume" --until 00:40)
# pt: every tag of the sixth batch
nice .venv/bin/python tools/difftest_run.py --integrator pt --want new6 "${C[@]}" \
    --max-evals 12 --seed 30001 --cases 30 --out $O/pt > $O/pt.log 2>&1 &
# bdpt: ray visibility by kind and an object's Cast Shadow off on surfaces (no media, no
# subsurface, no linking, no lamp Cast Shadow off: with those bdpt hands ray visibility to pt)
nice .venv/bin/python tools/difftest_run.py --integrator bdpt --want "object ray visibility" \
    --want "lamp ray visibility" --want "object no shadow" "${C[@]}" --max-evals 25 \
    --avoid "world volume" --avoid volume --avoid subsurface --avoid "light linking" \
    --avoid "shadow linking" --avoid "no shadow" --seed 31000 --cases 30 \
    --out $O/bdpt > $O/bdpt.log 2>&1 &
# cis: Cast Shadow off (an object's and a lamp's) and shadow linking in fog, the linked lamp
# beside glossy (no ray visibility by kind, which cis hands to pt beside media)
nice .venv/bin/python tools/difftest_run.py --integrator cis --want "object no shadow in fog" \
    --want "no shadow in fog" --want "shadow linking in fog" --want "shadow link beside glossy" \
    --want "object no shadow" "${C[@]}" --max-evals 25 --avoid "object ray visibility" \
    --avoid "lamp ray visibility" --avoid subsurface --seed 32000 --cases 30 \
    --out $O/cis > $O/cis.log 2>&1 &
# lt: an object's Cast Shadow off on surfaces, shadow linking in fog (lt hands ray visibility
# by kind, and an object's Cast Shadow off beside media, to pt)
nice .venv/bin/python tools/difftest_run.py --integrator lt --want "object no shadow" \
    --want "shadow linking in fog" --want "shadow link beside glossy" "${C[@]}" \
    --max-evals 25 --avoid "object ray visibility" --avoid "lamp ray visibility" \
    --avoid subsurface --avoid "object no shadow in fog" --seed 33000 --cases 20 \
    --out $O/lt > $O/lt.log 2>&1 &
wait
