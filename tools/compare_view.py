"""Side-by-side PNGs of the last render-test comparisons (build/render_tests/<scene>.npz):
Lantern | Cycles | difference x4 (grey = 0) | z map per 8x8 block (red +, blue -, full at 5).

    .venv/bin/python tools/compare_view.py [SCENE ...]   -> build/render_tests/<scene>.png"""

import glob
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DIR = os.path.join(ROOT, "build", "render_tests")


def view(path, zoom=3):
    from lantern.imageio import write_image
    d = np.load(path)
    lan, cyc, z = d["lantern"], d["cycles"], d["z"]
    srgb = lambda x: np.clip(x, 0, 1) ** (1 / 2.2)  # noqa: E731
    diff = np.clip((lan - cyc) * 4 + 0.5, 0, 1)
    zb = np.abs(z).max(axis=2) * np.sign(z.sum(axis=2))
    zimg = np.zeros(zb.shape + (3,))
    zimg[..., 0] = np.clip(zb / 5, 0, 1)
    zimg[..., 2] = np.clip(-zb / 5, 0, 1)
    b = lan.shape[0] // zb.shape[0]
    zimg = np.repeat(np.repeat(zimg, b, 0), b, 1)
    zfull = np.zeros_like(lan)
    zfull[:zimg.shape[0], :zimg.shape[1]] = zimg
    im = np.concatenate([srgb(lan), srgb(cyc), diff, zfull], axis=1)
    im = np.repeat(np.repeat(im, zoom, 0), zoom, 1).astype(np.float32)
    out = os.path.splitext(path)[0] + ".png"
    write_image(out, im)
    return out


if __name__ == "__main__":
    names = sys.argv[1:]
    paths = [os.path.join(DIR, n + ".npz") for n in names] or sorted(glob.glob(os.path.join(DIR, "*.npz")))
    for p in paths:
        print(view(p))
