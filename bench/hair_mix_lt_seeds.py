"""lt on the mix fur (tests/python/test_hair_mix_bidir.py mix_fur): per seed the image mean, the
brightest pixel (mean of RGB) and where, CPU seconds. Usage: hair_mix_lt_seeds.py SEEDS [SPP]
(SEEDS comma-separated; bench/results/2026-12-06-lttails). Run from the repository root with
PYTHONPATH=python."""
import sys, time
sys.path.insert(0, "tests/python")
import numpy as np
from test_hair_mix_bidir import mix_fur
from test_hair_bidir import render
seeds = [int(x) for x in sys.argv[1].split(",")]
spp = int(sys.argv[2]) if len(sys.argv) > 2 else 1024
sc = mix_fur()
for sd in seeds:
    t = time.process_time()
    img, w = render(sc, "lt", sd, spp)
    lum = img[..., :3].mean(-1)
    y, x = np.unravel_index(np.argmax(lum), lum.shape)
    print(sd, "mean", img[..., :3].mean(), "max", lum.max(), "at", (x, y), "cpu", round(time.process_time() - t, 2), flush=True)
