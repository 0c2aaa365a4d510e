"""A sparse smoke in a large box (docs/volumes.md, majorant bricks): a Volume object's grid of
N^3 voxels holding one small dense blob, lit by a sun over a floor, rendered by pt with one
majorant per medium (LANTERN_MAJORANT_BRICKS=0, what main did) and with the majorant bricks
(scene/medium_majorant.h). Reported per variant: process CPU time per render (K seeds), the
image mean and its standard error over seeds (the two must agree: both are unbiased), and the
expected tentative collisions of a camera ray crossing the box, the integral of the majorant
along it (computed here from the grid: the medium's one majorant x the chord, or the sum over
bricks of the brick's majorant x the length inside it, by fine steps), mean over the pixels.
Run from the repository root (the checkout's python/lantern with its _core):

    nice python bench/fire_majorant.py --out bench/results/2026-12-04-fire/majorant.txt"""
import argparse
import os
import platform
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "python"))
import lantern  # noqa: E402
from lantern.scenes import aabb_mesh  # noqa: E402

B = 8   # kMajorantBrick
HALF = 0.3   # the camera's half window at unit distance


def sparse_voxels(n):
    """A blob of radius n/10 off the centre of an n^3 block, 0 elsewhere."""
    c = np.arange(n, dtype=np.float64)
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    r2 = (x - 0.55 * n) ** 2 + (y - 0.45 * n) ** 2 + (z - 0.5 * n) ** 2
    d = np.clip(np.exp(-r2 / (2 * (0.06 * n) ** 2)) - 0.05, 0.0, None) * 20.0
    return np.ascontiguousarray(d.astype(np.float32))


def scene(n, size):
    s = lantern.Scene()
    s.film.update(width=size, height=size)
    h = HALF
    s.camera = {"type": "perspective", "screen": [-h, h, -h, h], "clip": [0.01, 100.0],
                "to_world": np.array([[1, 0, 0, 0], [0, 0, -1, -4.0], [0, 1, 0, 0.0],
                                      [0, 0, 0, 1]], np.float32).tolist()}
    s.world = {"color": [0.05, 0.06, 0.08]}
    voxel = 2.0 / n
    m = np.array([[voxel, 0, 0, -1 + voxel / 2], [0, voxel, 0, -1 + voxel / 2],
                  [0, 0, voxel, -1 + voxel / 2], [0, 0, 0, 1]], np.float64)
    vox = sparse_voxels(n)
    g = s.add_grid(vox, m, name="smoke:density")
    mat = s.add_material("smoke")
    s.materials[mat].update(volume={"sigma_a": [0.2, 0.2, 0.2], "sigma_s": [0.8, 0.8, 0.8]},
                            volume_only=True, density_grid=g)
    lo, hi = -1 - voxel / 2, 1 + voxel / 2   # the grid's trilinear support
    p, idx = aabb_mesh((lo, lo, lo), (hi, hi, hi))
    s.add_mesh(p, idx, material=mat)
    s.lights.append({"type": "sun", "direction": [-0.3, 0.4, -0.87], "strength": [3.0] * 3,
                     "angle": 0.05})
    return s, vox, m


def brick_majorants(vox, ext):
    """The bricks' majorants as the core builds them (medium_majorant_build.cpp)."""
    nz, ny, nx = vox.shape
    nb = [(n + B) // B for n in (nx, ny, nz)]
    out = np.zeros((nb[2], nb[1], nb[0]))
    for bk in range(nb[2]):
        for bj in range(nb[1]):
            for bi in range(nb[0]):
                sl = vox[max(bk * B - 2, 0):(bk + 1) * B + 1, max(bj * B - 2, 0):(bj + 1) * B + 1,
                         max(bi * B - 2, 0):(bi + 1) * B + 1]
                out[bk, bj, bi] = ext * (sl.max() if sl.size else 0.0)
    return out


def majorant_integrals(sc, vox, m, size, ext):
    """Mean over pixel-centre camera rays of the integral of the majorant over the box."""
    cam = np.array(sc.camera["to_world"], np.float64)
    o = cam[:3, 3]
    nz = vox.shape[0]
    bricks = brick_majorants(vox, ext)
    inv = np.linalg.inv(m)
    one, brick = [], []
    half = HALF
    for py in range(size):
        for px in range(size):
            u = (2 * (px + 0.5) / size - 1) * half
            v = (1 - 2 * (py + 0.5) / size) * half
            d = cam[:3, :3] @ np.array([u, v, -1.0])
            d /= np.linalg.norm(d)
            ts = np.linspace(0.0, 8.0, 8001)
            dt = ts[1] - ts[0]
            pts = o[None, :] + ts[:, None] * d[None, :]
            q = (inv[:3, :3] @ pts.T).T + inv[:3, 3]
            inside = np.all((q > -1) & (q < nz), axis=1)
            one.append(inside.sum() * dt * ext * vox.max())
            b = np.floor((q[inside] + 1) / B).astype(int)
            b = np.clip(b, 0, np.array(bricks.shape[::-1]) - 1)
            brick.append(bricks[b[:, 2], b[:, 1], b[:, 0]].sum() * dt)
    return float(np.mean(one)), float(np.mean(brick))


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            return next(line.split(":", 1)[1].strip() for line in f if "model name" in line)
    except (OSError, StopIteration):
        return platform.processor() or platform.machine()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=128, help="voxels per side")
    ap.add_argument("--size", type=int, default=48)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--out", default="")
    a = ap.parse_args()
    sc, vox, m = scene(a.n, a.size)
    ext = 1.0   # the extinction per unit density's largest channel (0.2 + 0.8)
    lines = [f"# bench/fire_majorant.py --n {a.n} --size {a.size} --spp {a.spp} "
             f"--seeds {a.seeds}",
             f"# machine: {platform.node()} {cpu_model()}, "
             f"{os.cpu_count()} cores, load {os.getloadavg()[0]:.1f} at start; pt, 1 thread, "
             f"max_depth 8",
             f"# grid {a.n}^3 voxels, {int((vox > 0).sum())} non-zero "
             f"({100.0 * (vox > 0).mean():.2f} %), bricks of {B}^3"]
    one, brick = majorant_integrals(sc, vox, m, a.size, ext)
    lines.append(f"expected tentative collisions per camera ray across the box (integral of the "
                 f"majorant): one majorant {one:.1f}, bricks {brick:.1f} ({one / brick:.1f}x fewer)")
    res = {}
    for label, env in (("one majorant", "0"), ("bricks", "1")):
        os.environ["LANTERN_MAJORANT_BRICKS"] = env
        means, cpu = [], []
        for seed in range(1, a.seeds + 1):
            t0 = time.process_time()
            img = lantern.render(sc, spp=a.spp, integrator="pt", max_depth=8, seed=seed,
                                 threads=1)
            cpu.append(time.process_time() - t0)
            means.append(float(np.asarray(img, np.float64)[..., :3].mean()))
        means = np.array(means)
        res[label] = (np.mean(cpu), means.mean(), means.std(ddof=1) / np.sqrt(len(means)))
        lines.append(f"{label}: CPU {np.mean(cpu):.2f} s per render (min {min(cpu):.2f}), image "
                     f"mean {means.mean():.5f} +- {res[label][2]:.5f}")
    os.environ.pop("LANTERN_MAJORANT_BRICKS", None)
    (c1, m1, s1), (c2, m2, s2) = res["one majorant"], res["bricks"]
    lines.append(f"bricks / one majorant: CPU time {c2 / c1:.3f} ({c1 / c2:.2f}x faster); image "
                 f"means differ by {(m2 - m1) / np.hypot(s1, s2):.2f} standard errors")
    print("\n".join(lines))
    if a.out:
        os.makedirs(os.path.dirname(a.out), exist_ok=True)
        with open(a.out, "w") as f:
            f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
