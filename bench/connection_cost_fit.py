"""CPU time of cis per iteration under uniform connection maps (N, M), with its counters: the
data behind pixel_alloc.h's kConnectionRayCost and kCandidateCost (a connection ray and a
candidate in rays of the rest of the iteration). One thread, 64 x 64, max_depth 12, the first
iteration dropped, the mean of the next six.

    PYTHONPATH=python .venv/bin/python bench/connection_cost_fit.py \\
        > bench/results/2026-12-04-auto6/connection_cost_fit.txt

Read: (5, 20) -> (10, 20) adds connection rays at equal candidates (time per connection ray);
(0, 1) is the base (time per other ray); (5, 10) less its connection rays gives the
candidates' time."""
import time

import numpy as np

import lantern
from lantern import scenes

for name in ("cornell_box", "room_area_point", "glossy_box"):
    sc = getattr(scenes, name)(64, 64)
    for n, m in [(0, 1), (1, 1), (2, 5), (5, 10), (5, 20), (10, 20)]:
        s = lantern.Session(sc, integrator="cis", seed=1, backend="cpu", threads=1,
                            max_depth=12, spp_per_iteration=1, connection_allocation=False)
        s.set_connection_map(np.full((64, 64), n), np.full((64, 64), m))
        s.step()
        st0 = s.stats
        t = time.process_time()
        for _ in range(6):
            s.step()
        dt = (time.process_time() - t) / 6
        st = s.stats
        rays = (st["rays_total"] - st0["rays_total"]) / 6
        cand = (st.get("cis_candidates", 0) - st0.get("cis_candidates", 0)) / 6
        conn = (st["rays_connection"] - st0["rays_connection"]) / 6
        print(f"{name} N {n} M {m}: {dt * 1e3:.1f} ms, rays {rays:.0f} (connection {conn:.0f}), "
              f"candidates {cand:.0f}", flush=True)
