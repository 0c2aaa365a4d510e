"""CPU time of a render with and without connection_allocation, repeated (3 x seeds 1000, 1001,
interleaved), 64 x 64, 64 one-sample steps, max_depth 12, one thread: the images and work are
deterministic, so repeats only narrow the time's load noise
(bench/results/2026-12-04-auto6/time_repeats.txt).

    PYTHONPATH=python .venv/bin/python bench/connection_alloc_time_repeats.py fixture_box auto
"""
import sys
import time

import numpy as np

import lantern
from lantern import scenes


def main():
    scene_name, integrator = sys.argv[1], sys.argv[2]
    scene = getattr(scenes, scene_name)(64, 64)
    res = {False: [], True: []}
    for _ in range(3):
        for seed in (1000, 1001):
            for alloc in (False, True):
                s = lantern.Session(scene, integrator=integrator, seed=seed, backend="cpu",
                                    threads=1, max_depth=12, spp_per_iteration=1,
                                    connection_allocation=alloc)
                t = time.process_time()
                for _ in range(64):
                    s.step()
                res[alloc].append(time.process_time() - t)
    ratio = np.median(res[True]) / np.median(res[False])
    print(scene_name, integrator, {k: [round(x, 2) for x in v] for k, v in res.items()},
          "median time ratio alloc/without", round(float(ratio), 3))


if __name__ == "__main__":
    main()
