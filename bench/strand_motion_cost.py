"""bench/strand_motion_cost.py N: wall time of pt on the still fur ball (32 x 32, 64 spp,
max_depth 8, one thread), N repetitions with each ray-query structure (LANTERN_ACCEL bvh and
embree), as JSON: the cost to scenes without motion of the moving-strand test in the curve
BVH's leaves and the shading's time argument (docs/motion_blur.md "Strands"). Run it from each
checkout (its own core) and compare."""
import json
import os
import sys
import time

import lantern
from lantern.scenes_hair import fur_ball

out = []
for rep in range(int(sys.argv[1])):
    for accel in ("bvh", "embree"):
        os.environ["LANTERN_ACCEL"] = accel
        s = lantern.Session(fur_ball(32, 32), integrator="pt", seed=rep, spp_per_iteration=64,
                            threads=1, max_depth=8)
        t0 = time.perf_counter()
        s.step()
        out.append({"accel": accel, "rep": rep, "seconds": time.perf_counter() - t0})
print(json.dumps(out))
