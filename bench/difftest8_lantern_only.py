"""Lantern pt alone on a saved difftest case and three variants (the mesh volume casting its shadow, no Volume object, no mesh volume): image means, 8 seeds x 8 spp (difftest8, 53020).
    .venv/bin/python bench/difftest8_lantern_only.py CASE.json"""
import json, sys, copy
sys.path.insert(0, 'tools')
import difftest_run  # noqa (patches)
import difftest as dt, difftest_build as db
import numpy as np
d = json.load(open(sys.argv[1]))
for label, edit in (("as drawn", None), ("volume casts shadow", "c['objects'][1].pop('cast_shadow')"),
                    ("no vdb", "c['objects'].pop(2)"), ("no mesh volume", "c['objects'].pop(1)")):
    c = copy.deepcopy(d['case'])
    if edit: exec(edit)
    db.build(c)
    scene, w = dt.export_lantern()
    imgs = dt.render_lantern(scene, c['bounces'], list(range(1, 9)), 8, 'pt', 1)
    m = np.mean([i.mean(axis=(0, 1)) for i in imgs], axis=0)
    print(label, w, np.round(m, 5), flush=True)
