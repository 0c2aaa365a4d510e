"""What the roughness rows cost when a scene is built (issue 28, bsdf/multiscatter.h ms_rough):
the time to build a one-triangle scene (lantern.Session) whose Principled or metal material
takes its Roughness from a texture, against the same with a constant roughness. The first
textured scene of a process pays the shared rows (white GGX, the specular basis of its IOR),
later ones of the same IOR only the interpolation.

    PYTHONPATH=python .venv/bin/python bench/lobe_tables_cost.py
"""
import platform
import time

import numpy as np

import lantern


def scene(kind, textured, ior=1.5):
    """One triangle, a Principled material (metal: Metallic 1) of roughness 0.3, or a texture
    of 0.3 on Roughness."""
    s = lantern.Scene()
    extra = {}
    if textured:
        extra["roughness_texture"] = s.add_texture(np.full((2, 2, 4), 0.3, np.float32))
    s.add_material(type="principled", roughness=0.3, ior=ior,
                   metallic=1.0 if kind == "metal" else 0.0, **extra)
    s.add_mesh(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32),
               np.array([[0, 1, 2]], np.int32), material=0)
    return s


def timed(kind, textured, ior=1.5):
    s = scene(kind, textured, ior)
    t0 = time.perf_counter()
    lantern.Session(s, integrator="pt", backend="cpu", threads=1)
    return time.perf_counter() - t0


print(f"machine: {platform.node()} {platform.processor() or platform.machine()}")
for kind in ("dielectric layer", "metal"):
    print(f"{kind}: constant roughness {1e3 * timed(kind, False):.0f} ms; textured: first "
          f"{1e3 * timed(kind, True):.0f} ms, again {1e3 * timed(kind, True):.0f} ms, "
          f"another IOR {1e3 * timed(kind, True, 1.33):.0f} ms")
