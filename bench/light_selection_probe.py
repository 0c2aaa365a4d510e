"""What the light pick does per pixel (issue 28, "Several lights"): at each pixel's first hit, the
probability the light tree gives each light against the ideal one, proportional to the light's
unoccluded contribution there (its next-event estimate of irradiance, lantern._core.
light_selection_probe), and the cost of the difference.

The cost: one light picked with pmf p_k, its contribution E_k estimated exactly, has the second
moment sum_k E_k^2 / p_k; over the ideal choice's (sum_k E_k)^2 that is the selection's
variance factor F >= 1 (1 at p_k ~ E_k). F is reported with E unoccluded (what the importance
can know) and with shadows (what the render pays), as means over the pixels of each part of
the scene (regions by the hit's position and normal), beside the mean pmf of each light and
its ideal.

    PYTHONPATH=python python bench/light_selection_probe.py --scene small_room_two_lights \\
        --res 64 --samples 256 [--out bench/results/<date>-light-selection/probe_<label>.json]
"""
import argparse
import json
from pathlib import Path

import numpy as np

import lantern
from lantern import scenes


def regions(pos, nrm, hit):
    """Named masks of the first hits: the small room's ceiling, floor, walls and the rest."""
    z, nz = pos[..., 2], nrm[..., 2]
    out = {"all": hit}
    out["ceiling"] = hit & (nz < -0.9) & (z > 1.99)
    out["floor"] = hit & (nz > 0.9) & (z < 0.01)
    out["walls"] = hit & (np.abs(nz) < 0.1) & (np.abs(pos[..., :2]).max(axis=-1) > 0.99)
    out["other"] = hit & ~(out["ceiling"] | out["floor"] | out["walls"])
    out["upper walls (z > 1.5)"] = out["walls"] & (z > 1.5)
    return out


def factor(e, pmf):
    """Per-pixel selection variance factor sum E^2/p / (sum E)^2; inf where a light that gives
    something has p = 0 (the estimate is biased there)."""
    tot = e.sum(axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        m2 = np.where(e > 0, e * e / np.where(pmf > 0, pmf, np.nan), 0.0)
        m2 = np.where((e > 0) & ~(pmf > 0), np.inf, m2).sum(axis=-1)
        return np.where(tot > 0, m2 / (tot * tot), np.nan)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scene", default="small_room_two_lights")
    ap.add_argument("--res", type=int, default=64)
    ap.add_argument("--samples", type=int, default=256)
    ap.add_argument("--label", default="")
    ap.add_argument("--out", default="")
    args = ap.parse_args()
    scene = getattr(scenes, args.scene)(args.res, args.res)
    from lantern import _core as core
    r = core.light_selection_probe(scene.to_native(), {"samples": args.samples, "seed": 7,
                                                       "threads": 1})
    pmf = np.asarray(r["pmf"], np.float64)
    free = np.asarray(r["unoccluded"], np.float64)
    seen = np.asarray(r["visible"], np.float64)
    pos, nrm = np.asarray(r["position"]), np.asarray(r["normal"])
    hit = np.abs(nrm).sum(axis=-1) > 0
    names = [lt["type"] for lt in scene.lights]
    with np.errstate(invalid="ignore", divide="ignore"):
        ideal = free / free.sum(axis=-1, keepdims=True)
    f_free, f_seen = factor(free, pmf), factor(seen, pmf)
    rows = []
    print(f"{args.scene} {args.label}: lights {names}")
    print(f"{'region':24s} {'px':>5s} " + " ".join(f"{'p_' + n:>8s} {'ideal':>7s}" for n in names)
          + f" {'F unocc':>8s} {'F shadow':>8s} {'F=inf px':>8s}")
    for name, m in regions(pos, nrm, hit).items():
        m = m & (free.sum(axis=-1) > 0)
        if not m.any():
            continue
        row = {"region": name, "pixels": int(m.sum()),
               "pmf": pmf[m].mean(axis=0).tolist(), "ideal": ideal[m].mean(axis=0).tolist(),
               "F_unoccluded": float(np.mean(np.where(np.isfinite(f_free[m]), f_free[m], np.nan))),
               "F_shadowed": float(np.nanmean(np.where(np.isfinite(f_seen[m]), f_seen[m], np.nan))),
               "biased_pixels": int((~np.isfinite(f_free[m])).sum())}
        rows.append(row)
        print(f"{name:24s} {row['pixels']:5d} " +
              " ".join(f"{p:8.3f} {i:7.3f}" for p, i in zip(row["pmf"], row["ideal"])) +
              f" {row['F_unoccluded']:8.3f} {row['F_shadowed']:8.3f} {row['biased_pixels']:8d}")
    if args.out:
        out = Path(args.out)
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(json.dumps({"scene": args.scene, "label": args.label, "lights": names,
                                   "res": args.res, "samples": args.samples, "rows": rows},
                                  indent=1))
        np.savez_compressed(out.with_suffix(".npz"), pmf=pmf, unoccluded=free, visible=seen,
                            position=pos, normal=nrm)


if __name__ == "__main__":
    main()
