"""lt's adjoint random walk (docs/subsurface.md, "The adjoint walk") against pt on subsurface
scenes where light paths should help: noise and CPU time, one thread, K seeds each. Before the
adjoint walk lt handed every subsurface scene to pt (so "before" is pt's efficiency for both);
after it lt renders them with its own light paths. Reported per scene and integrator: the image
mean, the mean per-pixel variance over seeds (pixels whose mean is > 1 % of the image mean), the
process CPU time per seed and the efficiency 1 / (variance x time); then lt / pt and the means'
agreement (lantern.agreement.compare_renders, block 8).

Scenes (each a Principled with subsurface, world black):
- caustic: a small sphere light focused by a glass ball onto a Skin slab (caustics on skin:
  pt reaches the light through the glass only by BSDF sampling);
- shade: a point light inside a hollow sphere of Random Walk subsurface (a lamp in a wax
  shade), seen from outside, on a grey floor;
- backlit: a 2 cm Skin slab lit from behind by a small sphere light (an ear lit from behind).

    PYTHONPATH=python nice python bench/sss_lt_efficiency.py --seeds 8 \\
        --out bench/results/2026-12-06-sssadjoint/efficiency.txt"""
import argparse
import os
import platform
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))
import lantern  # noqa: E402
from lantern import agreement, scenes  # noqa: E402
from lantern.scenes import aabb_mesh  # noqa: E402


def _quad(scene, material, z, half):
    q = np.array([[-half, -half, z], [half, -half, z], [half, half, z], [-half, half, z]],
                 np.float32)
    scene.add_mesh(q, np.array([[0, 1, 2], [0, 2, 3]], np.uint32), material=material)


def caustic(size):
    s = lantern.Scene()
    s.film.update(width=size, height=size)
    s.look_at((0.0, -2.2, 1.6), (0.0, 0.0, 0.0), fov=40.0)
    s.world = {"color": [0.0, 0.0, 0.0]}
    skin = s.add_material("skin", type="principled", base_color=(0.8, 0.55, 0.45), roughness=0.5,
                          subsurface={"weight": 1.0, "radius": [0.05, 0.02, 0.01],
                                      "method": "random_walk_skin"})
    p, idx = aabb_mesh((-1.5, -1.5, -0.1), (1.5, 1.5, 0.0))
    s.add_mesh(p, idx, material=skin)
    glass = s.add_material("glass", type="dielectric", base_color=(1.0, 1.0, 1.0), ior=1.5,
                           roughness=0.0)
    pos, tri = scenes.icosphere(3)
    s.add_mesh(np.asarray(pos) * 0.4 + np.array([0.0, 0.0, 0.9]), tri, material=glass)
    s.add_light("point", position=[0.0, 0.0, 2.2], power=[200.0] * 3, radius=0.05,
                soft_falloff=False)
    return s


def shade(size):
    s = lantern.Scene()
    s.film.update(width=size, height=size)
    s.look_at((0.0, -4.0, 0.8), (0.0, 0.0, 0.0), fov=40.0)
    s.world = {"color": [0.0, 0.0, 0.0]}
    wax = s.add_material("wax", type="principled", base_color=(0.9, 0.75, 0.5), roughness=0.5,
                         subsurface={"weight": 1.0, "radius": [0.3, 0.2, 0.1],
                                     "method": "random_walk"})
    pos, tri = scenes.icosphere(3)
    pos = np.asarray(pos)
    s.add_mesh(pos, tri, material=wax)
    s.add_mesh(pos * 0.92, np.asarray(tri)[:, ::-1].copy(), material=wax)  # the shell's inside
    floor = s.add_material("floor", base_color=0.5)
    _quad(s, floor, -1.0, 4.0)
    s.add_light("point", position=[0.0, 0.0, 0.0], power=[100.0] * 3, radius=0.0)
    return s


def backlit(size):
    s = lantern.Scene()
    s.film.update(width=size, height=size)
    s.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), fov=40.0)
    s.world = {"color": [0.0, 0.0, 0.0]}
    skin = s.add_material("skin", type="principled", base_color=(0.8, 0.55, 0.45), roughness=0.5,
                          subsurface={"weight": 1.0, "radius": [0.05, 0.02, 0.01],
                                      "method": "random_walk_skin"})
    p, idx = aabb_mesh((-1.0, -1.0, -0.02), (1.0, 1.0, 0.0))
    s.add_mesh(p, idx, material=skin)
    s.add_light("point", position=[0.0, 0.0, -0.3], power=[50.0] * 3, radius=0.05,
                soft_falloff=False)
    return s


SCENES = {"caustic": caustic, "shade": shade, "backlit": backlit}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", type=int, default=32)
    ap.add_argument("--spp", type=int, default=32)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--max-depth", type=int, default=8)
    ap.add_argument("--scenes", nargs="+", default=list(SCENES))
    ap.add_argument("--integrators", nargs="+", default=["pt", "lt"])
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    # lt hands Random Walk (not Skin) to pt (session.cpp, docs/subsurface.md): the switch keeps
    # its adjoint walk, which this bench measures (the shade scene)
    os.environ.setdefault("LANTERN_SSS_ADJOINT", "walk")
    machine = (f"{platform.node()} {platform.processor() or platform.machine()}, "
               f"{os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}")
    lines = [f"subsurface, lt's adjoint walk against pt: {args.size}x{args.size}, max_depth "
             f"{args.max_depth}, {args.seeds} seeds x {args.spp} spp, 1 thread; {machine}"]
    for name in args.scenes:
        scene = SCENES[name](args.size)
        imgs, eff = {}, {}
        for integ in args.integrators:
            out, cpu = [], []
            for k in range(args.seeds):
                c0 = time.process_time()
                s = lantern.Session(scene, integrator=integ, backend="cpu", seed=1 + k,
                                    max_depth=args.max_depth, spp_per_iteration=args.spp,
                                    threads=1)
                while s.spp < args.spp:
                    s.step()
                out.append(np.asarray(s.image(), dtype=np.float64)[..., :3])
                cpu.append(time.process_time() - c0)
                assert not any("rendering with pt" in w for w in s.warnings), s.warnings
            a = np.stack(out)
            mean = a.mean(axis=0)
            lit = mean.mean(axis=-1) > 0.01 * mean.mean()
            var = a.var(axis=0, ddof=1).mean(axis=-1)[lit].mean()
            t = float(np.mean(cpu))
            imgs[integ], eff[integ] = out, 1.0 / (var * t)
            lines.append(f"  {name} {integ}: image mean {a.mean():.5f}; mean pixel variance "
                         f"{var:.4e}; CPU {t:.2f} s/seed; efficiency {eff[integ]:.4g}")
        for integ in eff:
            if integ != "pt" and "pt" in eff:
                res = agreement.compare_renders(imgs[integ], imgs["pt"], block=8)
                lines.append(f"  {name} efficiency {integ} / pt: "
                             f"{eff[integ] / eff['pt']:.2f}x; {res}")
        print("\n".join(lines[-3:]), flush=True)
    text = "\n".join(lines)
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    with open(args.out, "a") as f:
        f.write(text + "\n")


if __name__ == "__main__":
    main()
