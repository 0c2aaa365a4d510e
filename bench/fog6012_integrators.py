"""D51: every integrator in tests/cycles/test_fog_lamp_roulette's glossy room in fog against its
stored Cycles references (Min Light Bounces = bounces, roulette off; and Cycles' default, the
control), 16 seeds x 64 spp a side of Lantern.

    nice .venv/bin/python bench/fog6012_integrators.py [pt bdpt lvc cis lt auto]
"""
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
sys.path.insert(0, os.path.join(ROOT, "tests", "cycles"))
sys.path.insert(0, os.path.join(ROOT, "python"))   # the checkout's core (as conftest.py)
import bpy  # noqa: E402,F401

import render_compare as rc  # noqa: E402
import test_fog_lamp_roulette as room  # noqa: E402
from lantern import metrics  # noqa: E402


def main():
    rc.BOUNCES = room.BOUNCES
    cyc_rr = room._cycles(room.fog_roulette)
    cyc = room._cycles(room.fog_no_roulette)
    import lantern
    print("lantern:", lantern.__file__, flush=True)
    for integ in sys.argv[1:] or ["pt", "bdpt", "lvc", "cis"]:
        t0 = time.process_time()
        lan = np.stack([rc.render_lantern(seed=1 + k, spp=room.SPP[1], threads=1,
                                          integrator=integ)[0]
                        for k in range(room.K)]).astype(np.float64)
        cpu = time.process_time() - t0
        for name, ref in (("roulette off", cyc), ("Cycles' default", cyc_rr)):
            res = metrics.compare_renders(lan, ref, block=rc.BLOCK, se_floor=room.SE_FLOOR)
            print(f"[{integ}] vs Cycles {name}: {'agree' if res.passed else 'DIFFER'}, mean "
                  f"ratio {lan.mean() / ref.blocks.mean():.4f}; {res} (cpu {cpu:.1f} s)",
                  flush=True)


if __name__ == "__main__":
    main()
