"""d60: Lantern (and Cycles) image means of variants of a saved difftest case, each an edit on
`c` (the case); per channel mean and its standard error over seeds.
    .venv/bin/python bench/d60_probe.py CASE.json SEEDS SPP [--cycles] [--cyc STMT] [--integrator pt] "label=EDIT" ...
EDIT '' keeps the case; several edits joined by ';'."""
import copy, json, sys
sys.path.insert(0, 'tools')
import difftest_run  # noqa (patches: Cycles' roulette off)
import difftest as dt, difftest_build as db
import numpy as np
args = sys.argv[1:]
cycles = '--cycles' in args
args = [a for a in args if a != '--cycles']
integ = 'pt'
if '--integrator' in args:
    k = args.index('--integrator'); integ = args[k + 1]; del args[k:k + 2]
cyc = ''
if '--cyc' in args:  # a Python statement on `c` (scene.cycles) after the tester's settings
    k = args.index('--cyc'); cyc = args[k + 1]; del args[k:k + 2]
    _cs = dt.cycles_settings
    def _cs2(sc, *a, **kw):
        _cs(sc, *a, **kw)
        exec(cyc, {'c': sc.cycles, 'sc': sc})
    dt.cycles_settings = _cs2
src, seeds, spp, *variants = args
seeds, spp = int(seeds), int(spp)
d = json.load(open(src))
def blocks(imgs, n=4):
    h, w = imgs[0].shape[:2]
    b = np.array([i[:h // n * n, :w // n * n].reshape(n, h // n, n, w // n, 3).mean(axis=(1, 3)) for i in imgs])
    return b.mean(0), b.std(0, ddof=1) / np.sqrt(len(b))
def stats(imgs):
    m = np.array([i.mean(axis=(0, 1)) for i in imgs])
    return m.mean(0), m.std(0, ddof=1) / np.sqrt(len(m))
for v in variants:
    label, edit = v.split('=', 1)
    c = copy.deepcopy(d['case'])
    if edit: exec(edit)
    db.build(c)
    scene, w = dt.export_lantern()
    li = dt.render_lantern(scene, c['bounces'], list(range(1, seeds + 1)), spp, integ, 1)
    a, ase = stats(li)
    line = f"{label:28s} L {np.round(a, 5)} +- {np.round(ase, 5)}"
    if cycles:
        ci = dt.render_cycles(c['bounces'], list(range(1, seeds + 1)), spp, 1)
        b, bse = stats(ci)
        z = (a - b) / np.sqrt(ase ** 2 + bse ** 2)
        (la, lse), (cb, cse) = blocks(li), blocks(ci)
        zb = (la - cb) / np.sqrt(lse ** 2 + cse ** 2 + 1e-30)
        k = np.unravel_index(np.argmax(np.abs(zb)), zb.shape)
        blk = f"  worst block {k[:2]} ch {k[2]}: {100 * (la[k] / cb[k] - 1):+.1f} % z {zb[k]:.1f}"
        line += f"  C {np.round(b, 5)} +- {np.round(bse, 5)}  rel {np.round(100 * (a / b - 1), 2)} % z {np.round(z, 1)}"
        line += blk
    print(line, w if w else '', flush=True)
