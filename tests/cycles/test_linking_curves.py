"""Light and shadow linking of strands against Cycles through the add-on (issue 32 item 4): a
Curves object is linked as its object (export/linking.py's curves(); the core gives its
segments the object's receiver and blocker sets, scene_curves.cpp add_curve_prims). A curtain
of vertical strands (Principled BSDF) and a cube stand on a floor under a key area lamp and a
dim world:

- receiver: the key's Receiver Collection includes the hair only (the floor and the cube get
  the world and the light the hair bounces; the hair the key);
- blocker: the key's Blocker Collection includes the hair only (the hair casts the key's
  shadow on the floor, the cube casts none).

Before, the export left strands out of the sets (set 0, an object in no collection): the key
did not light the hair, and the hair cast no shadow. Negative control of each: Lantern with the
key's collection removed must not agree with Cycles' linked render."""

import os
import sys

import numpy as np
import pytest

import bpy  # noqa: E402 (conftest.py skips this folder without bpy or the core)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bpy_stage  # noqa: E402

K = 8
SIZE = 32
SPP = (64, 64)            # (Cycles, Lantern) per seed
CONTROLS = (0.03, 0.15)   # (image, block), as test_linking_fog.py's
SE_FLOOR = 1e-6
_bounces = bpy_stage.bounces(4)  # Cycles max bounces (Lantern max_depth 6)


def curtain(scene):
    """60 vertical wavy strands in a 1.2 m wide curtain standing on the floor."""
    n, keys = 60, 8
    data = bpy.data.hair_curves.new("Hair")
    data.add_curves([keys] * n)
    rng = np.random.default_rng(11)
    x0 = rng.uniform(-0.9, 0.3, n)
    y0 = rng.uniform(-0.15, 0.15, n)
    t = np.linspace(0.0, 1.0, keys)
    pts = np.stack([x0[:, None] + 0.05 * np.sin(5.0 * t[None, :] + 4.0 * x0[:, None]),
                    np.repeat(y0[:, None], keys, axis=1),
                    np.repeat(0.02 + 1.1 * t[None, :], n, axis=0)], axis=-1)
    data.attributes["position"].data.foreach_set("vector", pts.astype(np.float32).ravel())
    rad = data.attributes.get("radius") or data.attributes.new("radius", "FLOAT", "POINT")
    rad.data.foreach_set("value", np.full(n * keys, 0.015, np.float32))
    obj = bpy.data.objects.new("Hair", data)
    scene.collection.objects.link(obj)
    data.materials.append(bpy_stage.rough_material("strand", (0.8, 0.6, 0.3)))
    return obj


def stage(case, linked=True):
    scene = bpy_stage.reset(SIZE, world=(0.05, 0.05, 0.05))
    scene.cycles_curves.shape = "THICK_LINEAR"
    rough = bpy_stage.rough_material
    bpy_stage.cube("floor", (0, 0, -0.05), 1.0, rough("floor", (0.7, 0.7, 0.7)),
                   scale=(6, 6, 0.1))
    bpy_stage.cube("cube", (0.8, 0.2, 0.35), 0.7, rough("cube", (0.1, 0.4, 0.8)))
    hair = curtain(scene)
    key = bpy_stage.light(scene, "AREA", (0.0, -1.6, 2.4), 300.0, rotation=(35, 0, 0),
                          size=0.8)
    bpy_stage.camera(scene, (0, -4.0, 1.6), (72, 0, 0), lens=32.0)
    if linked:
        coll = bpy.data.collections.new("key_link")
        coll.objects.link(hair)
        if case == "receiver":
            key.light_linking.receiver_collection = coll
        else:
            key.light_linking.blocker_collection = coll


@pytest.mark.parametrize("case", ["receiver", "blocker"])
def test_curves_linking_matches_cycles(case):
    name = f"curves_{case}"
    cyc = bpy_stage.compare_with_cycles(name, lambda: stage(case), SPP, CONTROLS,
                                        cycles_seed0=970, k_seeds=K, se_floor=SE_FLOOR)
    stage(case, linked=False)
    bpy_stage.control_differs(f"{name} unlinked", cyc, K, SPP[1], SE_FLOOR)
