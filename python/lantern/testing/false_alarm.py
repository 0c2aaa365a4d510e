"""False-alarm rates of the comparison families of tests/ (tests/README.md): each family's
comparison (lantern.metrics.compare_renders, as its tests call it) on 20 independent seed sets
of a fair pair, counting failures at the tests' alpha (1e-3) and, to see the calibration with 20
trials, at alpha 0.05 and 0.2. Expected counts are 20 alpha.

    nice python3 -m lantern.testing.false_alarm [--trials 20]
        [--families cross,analytic,backend,cycles] [--out tests/false_alarm.json]
    (false_alarm.py runs the same, as the commands recorded in bench/results do)

Families (fair pairs; the settings are the tests' or cheaper, which changes the noise, not the
null distribution):
- cross: lt against pt on cornell_point (test_light_tracing), bdpt against pt on the Cornell box
  (test_bidirectional), 16 seeds each;
- analytic: pt furnace against its exact value (test_render, test_bidirectional), and the
  direct term of the integrating sphere against the exact tessellated value;
- backend: the GPU tests' rule (test_cuda_backend, tools/gpu_compare.py) on CPU against CPU,
  two independent seed sets of the same integrator (what a correct GPU gives);
- paired: Lantern's own BVH against Embree with the same seeds, compared seed by seed
  (test_cpu_accel: bvh_k - embree_k + mean(embree) against mean(embree)) on the alpha-tested
  features box, pt, 16 seeds of 8 spp;
- scale: the glossy box at 1 m against 1 mm with the same seeds, paired
  (test_bidirectional.py::test_scale_invariance: cis, 16 seeds of 8 spp);
- instance: a box moved in a running session against a fresh render of the moved scene, the
  same seeds, paired (test_instance_move: 16 seeds of 8 spp, the built-in BVH);
- adaptive: adaptive renders against full ones on the half-emitter box, pt
  (test_adaptive_sampling's threshold, seeds and block);
- film: the shadow catcher's alpha against the wall's exact shadow (test_film, its settings);
- rotation: the HDRI turned by its mapping against the rolled map, paired seeds (test_world);
- hdri: test_world's HDRI scene with its world sun, bdpt against pt (16 x 64 spp a side) and
  lvc against bdpt on the same seeds, paired (test_integrators_agree_under_hdri);
- layers: tests/cycles/test_layers_passes' Combined of both view layers and the uncropped
  border against Cycles, 8 seeds of 16 spp an engine (needs bpy, like cycles);
- passes: the same test's data passes (Normal, Denoising Albedo, Denoising Normal, Diffuse
  Color) against Cycles, the same seeds and samples (needs bpy);
- bl_catcher: tests/blender/test_bl_world's F12 shadow catcher scene, exported, its alpha
  against the wall's exact shadow (16 seeds of 8 spp; needs bpy);
- bl_hdri: the same file's HDRI-lit Lambert plane against its exact irradiance (16 seeds of
  24 spp; needs bpy);
- coat_normal: tests/cycles/test_coat_normal's interior blocks against Cycles, 12 seeds of
  128 spp an engine, each trial its own seeds on both sides (needs bpy);
- pano: lt against pt through the panoramic camera (test_camera_pano, its samples);
- lighttree: bdpt against pt on the many-light stage with the tree (test_light_tree);
- cycles: Lantern against the stored Cycles reference of light_sun (needs bpy; the reference
  is one fixed set, so the 20 trials share it);
- fixture: the fixture's paired comparisons of test_bidirectional (lvc against bdpt, cis with
  the BSDF-product target against lvc: the same seeds on both sides), 16 seeds of 16 spp;
- tungsten: test_mitsuba's Cornell box and veach-mis against Tungsten's stored references,
  rendered at their footprints (the 20 trials share each reference, as cycles does);
- exact_images: the alpha card (test_textures, pt), the ball under a world hidden from the
  camera (test_world) and the glass ball's reflection alone (test_world_visibility) against
  their exact images, at their tests' settings;
- gpu_paired: test_cuda_backend's paired rule on CPU data: the built-in BVH against Embree with
  the same seeds (another traversal, the same wavefront), Cornell pt at that test's settings
  (32x32, 16 seeds of 64 spp, max_depth 8; one iteration of 64 where the test runs 4 of 16).
- lt_furnace: test_world's lt furnace, the image's totals over the ball's value times pt's
  coverage, one value a seed, against 1 (its seeds and samples; the coverage render is shared);
- sun_disc: render/test_sky_cycles' disc Lantern's camera sees, summed over the pixels' solid
  angles, against its light's strength (both skies, 8 seeds of 16 spp, cap 0.3 %; needs bpy).
"""

import argparse
import importlib
import json
import platform
import sys
import time
from pathlib import Path

from lantern import metrics

ALPHAS = (1e-3, 0.05, 0.2)
# name -> pairs function: every fa_*.py module of this package adds its FAMILIES
# (fa_lantern, fa_bl_scenes, fa_issue19 hold the families this file held; fa_bidir, fa_blender,
# fa_cycles, fa_cycles_tests, fa_python those of the tests' own files)
FAMILIES = {}


def load_family_modules():
    """Every fa_*.py of this package with a FAMILIES dict (name -> pairs function) joins
    FAMILIES; a name given by two modules is an error."""
    for path in sorted(Path(__file__).parent.glob("fa_*.py")):
        mod = importlib.import_module(f"{__package__}.{path.stem}")
        for name, fn in getattr(mod, "FAMILIES", {}).items():
            if FAMILIES.get(name) is fn:   # loaded before (a second main() in one process)
                continue
            if name in FAMILIES:
                raise SystemExit(f"false_alarm: family '{name}' of {path.name} is defined twice")
            FAMILIES[name] = fn


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--trials", type=int, default=20)
    p.add_argument("--families", default="cross,analytic,backend")
    p.add_argument("--out", default=None)
    args = p.parse_args(argv)
    load_family_modules()
    rows = {}
    t0 = time.perf_counter()
    for fam in [f.strip() for f in args.families.split(",") if f.strip()]:
        for trial in range(args.trials):
            for label, make in FAMILIES[fam](trial):
                a, b, kw = make()
                compare = kw.pop("compare", metrics.compare_renders)
                res = compare(a, b, **kw)
                row = rows.setdefault(label, {"family": fam, "trials": 0, "worst_p_x_n": [],
                                              **{f"fails@{al:g}": 0 for al in ALPHAS}})
                row["trials"] += 1
                for al in ALPHAS:
                    r = compare(a, b, alpha=al, **kw)
                    row[f"fails@{al:g}"] += int(not r.passed)
                row["worst_p_x_n"].append(round(float(res.blocks.p.min() * res.blocks.n), 4))
                print(f"{fam} trial {trial}: {label}: {'ok' if res.passed else 'FALSE ALARM'}"
                      f" ({time.perf_counter() - t0:.0f} s)", flush=True)
                save(args.out, rows, t0)  # after every trial: a run cut short keeps its counts
    print(json.dumps({k: {kk: vv for kk, vv in v.items() if kk != "worst_p_x_n"}
                      for k, v in rows.items()}, indent=1))
    return 0


def save(path, rows, t0):
    if not path:
        return
    out = {"machine": f"{platform.node()} {platform.processor() or platform.machine()}, "
                      f"{platform.python_version()}", "command": " ".join(sys.argv),
           "seconds": round(time.perf_counter() - t0, 1), "rows": rows}
    Path(path).write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    sys.exit(main())
