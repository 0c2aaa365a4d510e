"""Write variants of a saved difftest case (bench/results/2026-12-07-difftest8/byhand/): each
edit a Python expression on `c` (the case) or `s` (its settings), e.g.
    .venv/bin/python bench/difftest8_variant.py SRC.json OUT.json "c['lights'][0].pop('cast_shadow')"
The variant keeps SRC's settings; replay it with tools/difftest_run.py --case OUT.json."""
import json
import sys

src, out, *edits = sys.argv[1:]
with open(src) as f:
    doc = json.load(f)
c = doc["case"]
for e in edits:
    exec(e, {"c": c, "s": doc["settings"]})
doc["info"] = {"from": src, "edits": edits}
with open(out, "w") as f:
    json.dump(doc, f, indent=1)
    f.write("\n")
