"""Heavy tail or bias? pt's next-event estimation alone (a shadow-linked lamp) on a near-specular
Glossy against MIS (the same lamp unlinked), at rising samples. nee10022, issue 32 item 4.

    nice .venv/bin/python bench/nee10022_tail.py case     # difftest case 10022, lamp 1 alone
    nice .venv/bin/python bench/nee10022_tail.py direct   # tests/python's Glossy floor scene

case: difftest case 10022 (bench/results/2026-12-06-difftest4/cis/case-full-10022-original.json)
with lamp 1 alone, exported through the add-on (bpy), max_depth 3; "linked": every mesh in the
lamp's blocker set, plus a triangle far outside the room in a set that does not block, so that
the lamp stays shadow-linked after drop_redundant_shadow_links (the same shadows). Block (3, 0)
(rows 24-31, columns 0-7 of 32), green, one value per seed.
direct: test_linking_shadow_redundant.py's floor and lamp (the ball behind the lamp keeps the
link), max_depth 2; block rows 16-23, columns 16-23 of 24 (the sharp reflection's lower edge).
A heavy tail: the per-seed median stays low while the mean over seeds converges."""
import json
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "python"))
sys.path.insert(0, os.path.join(ROOT, "tools"))
sys.path.insert(0, os.path.join(ROOT, "tests", "python"))
import lantern  # noqa: E402

CASE = os.path.join(ROOT, "bench/results/2026-12-06-difftest4/cis/case-full-10022-original.json")


def case_scenes():
    import difftest_run as dr
    dt = dr.difftest
    c = json.load(open(CASE))["case"]
    c["lights"] = [c["lights"][1]]
    c["linking"] = [{"emitter": ["light", 0], "kind": "blocker", "objects": [0, 1, 2, 3],
                     "states": ["INCLUDE"] * 4}]
    dt.db.build(c)
    linked, _ = dt.export_lantern()
    c.pop("linking")
    dt.db.build(c)
    free, _ = dt.export_lantern()
    far = np.array([[50, 50, 50], [51, 50, 50], [50, 51, 50]], np.float32)
    linked.add_mesh(far, np.array([[0, 1, 2]], np.uint32), material=0, name="far")
    sets = {int(m.get("shadow_set") or 0) for m in linked.meshes[:-1]}
    linked.meshes[-1]["shadow_set"] = max(sets) + 1  # not in the lamp's blockers
    return linked, free, 3, (slice(24, 32), slice(0, 8))


def direct_scenes():
    from test_linking_shadow_redundant import glossy_under_lamp
    return (glossy_under_lamp(blockers=[0], ball=True), glossy_under_lamp(), 2,
            (slice(16, 24), slice(16, 24)))


def main():
    which = sys.argv[1] if len(sys.argv) > 1 else "direct"
    linked, free, depth, block = case_scenes() if which == "case" else direct_scenes()

    def value(scene, seed, spp):
        s = lantern.Session(scene, integrator="pt", backend="cpu", max_depth=depth, seed=seed,
                            spp_per_iteration=spp, threads=1)
        while s.spp < spp:
            s.step()
        return float(np.asarray(s.image(), np.float64)[block + (1,)].mean())

    runs = [("free (MIS)", free, 1024, 16, 6001), ("linked", linked, 64, 64, 5001),
            ("linked", linked, 256, 16, 7001),
            ("linked", linked, 1024, 16, 5001),
            ("linked", linked, 4096, 16, 8001)]
    for name, scene, spp, n, base in runs:
        t = time.process_time()
        v = np.array([value(scene, base + k, spp) for k in range(n)])
        print(f"{which} {name} {spp} spp x {n} seeds: mean {v.mean():.4f} +- "
              f"{v.std(ddof=1) / np.sqrt(n):.4f}  median {np.median(v):.4f}  min {v.min():.4f} "
              f"max {v.max():.4f}  cpu {time.process_time() - t:.1f} s", flush=True)


if __name__ == "__main__":
    main()
