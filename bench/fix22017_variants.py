"""difftest5's "bdpt 22017" taken apart (fix22017): which object makes bdpt differ from pt, and
is it light pt cannot sample? Lantern against Lantern, 8 seeds a side, threads 1, max_depth 4
(the case's bounces 2), 32 x 32, 8x8 blocks (4 x 4 of them); prints per variant the image mean's
relative difference and the blocks' relative difference and z (Welch, per-seed block means,
channels averaged).

    nice .venv/bin/python bench/fix22017_variants.py > bench/results/2026-12-06-fix22017/stdout.txt
    nice .venv/bin/python bench/fix22017_variants.py --more > .../stdout-b00.txt
    nice .venv/bin/python bench/fix22017_variants.py --cycles > .../stdout-cycles.txt
"""
import json
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
sys.path.insert(0, os.path.join(ROOT, "python"))
import difftest_run as dr  # noqa: E402
import lantern  # noqa: E402

CASES = os.path.join(ROOT, "bench", "results", "2026-12-06-difftest5")


def export(name, edit):
    doc = json.load(open(os.path.join(CASES, name)))
    c = doc.get("case", doc)
    exec(edit, {"c": c})
    dr.difftest.db.build(c)
    scene, warned = dr.difftest.export_lantern()
    assert not warned, warned
    return scene


def render(scene, side, seeds):
    integ, spp = side.split(":")
    out = []
    for sd in seeds:
        s = lantern.Session(scene, integrator=integ, seed=sd, backend="cpu", max_depth=4,
                            spp_per_iteration=int(spp), threads=1)
        s.step()
        out.append(np.asarray(s.image(), np.float64)[..., :3])
    return np.stack(out)


def pair(label, scene, a, b, k=8):
    t0 = time.process_time()
    A = render(scene, a, range(100, 100 + k))
    B = render(scene, b, range(150, 150 + k))
    ba = A.reshape(k, 4, 8, 4, 8, 3).mean(axis=(2, 4, 5))
    bb = B.reshape(k, 4, 8, 4, 8, 3).mean(axis=(2, 4, 5))
    ma, mb = ba.mean(0), bb.mean(0)
    se = np.sqrt(ba.var(0, ddof=1) / k + bb.var(0, ddof=1) / k)
    with np.errstate(divide="ignore", invalid="ignore"):
        rel, z = ma / mb - 1, (ma - mb) / se
    img = A.mean(axis=(0, 1, 2)) / B.mean(axis=(0, 1, 2)) - 1
    w = np.unravel_index(np.nanargmax(np.where(np.isfinite(z), np.abs(z), 0)), z.shape)
    print(f"## {label}: {a} against {b} ({time.process_time() - t0:.1f} s CPU)")
    print("image mean", " / ".join(f"{100 * x:+.1f} %" for x in img),
          f"; worst block {tuple(int(i) for i in w)} {100 * rel[w]:+.1f} % z {z[w]:.1f}")
    print("blocks rel\n", np.array2string(rel, precision=3))
    print("blocks z\n", np.array2string(z, precision=1), flush=True)


def keep(*names):
    return lambda sc: sc.meshes.__setitem__(slice(None), [m for m in sc.meshes
                                                          if m["name"] in names])


def more():
    """The drawn case's near-black block (0, 0) again, at 4x the samples (stdout-b00.txt)."""
    sc = export("case-22017-drawn.json",
                "c['camera'].pop('motion', None); c['lights'][0]['radius'] = 0.05")
    pair("drawn r0.05", sc, "bdpt:128", "lt:1024")
    pair("drawn r0.05", sc, "cis:128", "lt:1024")


def cycles():
    """Does Cycles render the caustic? The bisected case's floor and glass ico under its spot:
    Cycles 8 x 64 spp (seeds 1..8) against Lantern pt 8 x 256 and bdpt 8 x 32 (stdout-cycles.txt)."""
    doc = json.load(open(os.path.join(CASES, "case-22017-bisected.json")))
    c = doc["case"]
    c["objects"] = [o for o in c["objects"] if o["material"] in ("floor", "glass")]
    dr.difftest.db.build(c)
    scene, _ = dr.difftest.export_lantern()
    cy = np.stack(dr.difftest.render_cycles(c["bounces"], range(1, 9), 64, 1))[..., :3]
    b = cy.reshape(8, 4, 8, 4, 8, 3).mean(axis=(2, 4, 5))
    for side, seed0 in (("pt:256", 100), ("bdpt:32", 200)):
        x = render(scene, side, range(seed0, seed0 + 8))
        a = x.reshape(8, 4, 8, 4, 8, 3).mean(axis=(2, 4, 5))
        se = np.sqrt(a.var(0, ddof=1) / 8 + b.var(0, ddof=1) / 8)
        img = x.mean(axis=(0, 1, 2)) / cy.mean(axis=(0, 1, 2)) - 1
        print(f"## Lantern {side} against Cycles 64: image mean",
              " / ".join(f"{100 * v:+.1f} %" for v in img),
              f"; block (2, 3): {a.mean(0)[2, 3]:.5f} against {b.mean(0)[2, 3]:.5f}")
        with np.errstate(divide="ignore", invalid="ignore"):
            print("blocks rel\n", np.array2string(a.mean(0) / b.mean(0) - 1, precision=3))
            print("blocks z\n", np.array2string((a.mean(0) - b.mean(0)) / se, precision=1))


def main():
    if "--more" in sys.argv:
        return more()
    if "--cycles" in sys.argv:
        return cycles()
    bis = "case-22017-bisected.json"
    drawn = "case-22017-drawn.json"
    still = "c['camera'].pop('motion', None)"
    sc = export(bis, "")
    pair("bisected as is", sc, "bdpt:16", "pt:128")
    sc = export(bis, "c['lights'].clear()")
    pair("bisected, the spot (Radius 0) removed", sc, "bdpt:16", "pt:128")
    sc = export(bis, "")
    keep("plane0", "ico4")(sc)
    pair("floor + smooth glass ico + spot only", sc, "bdpt:16", "pt:128")
    pair("floor + smooth glass ico + spot only", sc, "bdpt:16", "lt:64")
    sc = export(bis, "c['lights'].clear()")
    keep("plane0", "ico4", "ico5")(sc)
    pair("floor + smooth glass ico + mesh emitter, no spot", sc, "bdpt:16", "pt:128")
    sc = export(bis, "c['lights'][0]['radius'] = 0.05")
    keep("plane0", "ico4")(sc)
    pair("floor + smooth glass ico + spot of Radius 0.05", sc, "bdpt:64", "pt:2048")
    sc = export(drawn, still)
    pair("as drawn, the camera still", sc, "bdpt:16", "pt:256")
    sc = export(drawn, still + "; c['lights'][0]['radius'] = 0.05")
    pair("as drawn, the camera still, the spot's Radius 0.05", sc, "bdpt:32", "pt:2048")
    pair("as drawn, the camera still, the spot's Radius 0.05", sc, "bdpt:32", "lt:256")


if __name__ == "__main__":
    main()
