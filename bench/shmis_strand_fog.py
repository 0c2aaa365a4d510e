"""pt's shadow rays past strands outside a shadow-linked light's blockers, in fog (shmis, left
open): tests/python/test_linking_curves_core.py's blocker scene (the curtain in set 1, the lamp
blocked by set 0 alone) with a thin world fog, against the same scene without the curtain, same
seeds, pt 8 spp. Without fog the two are the same bits since shmis (pt_shadow_linked_query);
with fog the shadow ray takes pt_shadow_loop, which still re-offsets a passed strand's ray
along it: a rare ray reported blocked would show as a negative image ratio beyond rounding.

    nice .venv/bin/python bench/shmis_strand_fog.py"""
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "python"))
sys.path.insert(0, os.path.join(ROOT, "tests", "python"))
from test_linking_curves_core import blocker_scene, render  # noqa: E402

FOG = {"sigma_s": [0.05, 0.05, 0.05], "sigma_a": [0.0, 0.0, 0.0], "g": 0.0}


def scene(hair):
    s = blocker_scene(hair)
    s.world = {"color": [0.0] * 3, "volume": dict(FOG)}
    return s


for seed in (1, 2, 3, 4):
    a, _ = render(scene(True), seed=seed)
    b, _ = render(scene(False), seed=seed)
    d = np.abs(a - b).max(axis=-1)
    print(f"seed {seed}: image ratio - 1 = {a.mean() / b.mean() - 1:+.2e}, pixels differing "
          f"beyond 1e-6 of the peak: {int((d > 1e-6 * b.max()).sum())}, worst pixel ratio "
          f"{float((a.sum(-1) / np.maximum(b.sum(-1), 1e-12))[d > 0].min() if (d > 0).any() else 1.0):.3f}")
