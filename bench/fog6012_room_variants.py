"""D51 (issue 32, difftest 6012): Cycles against Cycles in tests/cycles/test_fog_lamp_roulette's
glossy room in fog, by variant: Min Light Bounces 0 (Cycles' default roulette) over
Min Light Bounces = BOUNCES (roulette off), image mean ratio and its standard error over seeds.
The mechanism predicts a darker default wherever bounce rays inside the volume reach a lamp
they can hit (area, a point with a Radius) and most where BSDF sampling carries the lamp's
light (sharp glossy), nothing for a lamp no ray can hit (a point of Radius 0).

    nice .venv/bin/python bench/fog6012_room_variants.py --seeds 8 --spp 64 [--only NAME ...]
"""
import argparse
import math
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
sys.path.insert(0, os.path.join(ROOT, "tests", "cycles"))
import bpy  # noqa: E402

import render_compare as rc  # noqa: E402
import test_fog_lamp_roulette as room  # noqa: E402


def _lamp(kind, **kw):
    for o in [o for o in bpy.data.objects if o.type == "LIGHT"]:
        bpy.data.objects.remove(o)
    sc = bpy.context.scene
    room.bpy_stage.light(sc, kind, (0.4, 0.6, 2.9), kw.pop("energy", 150.0), **kw)


def _roughness(r):
    bpy.data.materials["metal"].node_tree.nodes["Glossy BSDF"].inputs["Roughness"]\
        .default_value = r


def _diffuse():
    m = bpy.data.materials["metal"]
    nt = m.node_tree
    d = nt.nodes.new("ShaderNodeBsdfDiffuse")
    d.inputs["Color"].default_value = (0.7, 0.7, 0.7, 1)
    nt.links.new(d.outputs[0], nt.nodes["Material Output"].inputs["Surface"])


VARIANTS = {
    "area": lambda: None,
    "point_r0": lambda: _lamp("POINT", energy=300.0, shadow_soft_size=0.0),
    "point_r02": lambda: _lamp("POINT", energy=300.0, shadow_soft_size=0.2),
    "rough_0.4": lambda: _roughness(0.4),
    "diffuse": _diffuse,
}


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--seeds", type=int, default=8)
    p.add_argument("--spp", type=int, default=64)
    p.add_argument("--only", nargs="*", default=None)
    a = p.parse_args()
    rc.BOUNCES = room.BOUNCES
    for name, edit in VARIANTS.items():
        if a.only and name not in a.only:
            continue
        means = {}
        for min_light in (0, room.BOUNCES):
            room._room(True, min_light)
            edit()
            imgs = [rc.render_cycles(seed=100 + k, spp=a.spp)[0] for k in range(a.seeds)]
            means[min_light] = np.array([float(np.mean(x)) for x in imgs])
        m0, mb = means[0], means[room.BOUNCES]
        r = m0.mean() / mb.mean()
        se = r * math.sqrt((m0.std(ddof=1) / m0.mean()) ** 2 / len(m0) +
                           (mb.std(ddof=1) / mb.mean()) ** 2 / len(mb))
        print(f"[{name}] Cycles min_light_bounces 0 / {room.BOUNCES}: {r - 1:+.2%} +- {se:.2%} "
              f"(means {m0.mean():.4f} / {mb.mean():.4f}; {a.seeds} seeds x {a.spp} spp)",
              flush=True)


if __name__ == "__main__":
    main()
