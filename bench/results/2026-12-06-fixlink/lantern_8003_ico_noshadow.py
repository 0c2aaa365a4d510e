import copy, json, sys
sys.path.insert(0, "tools"); sys.path.insert(0, "python")
import difftest as dt
doc = json.load(open("bench/results/2026-12-06-difftest4/pt/case-full-8003.json"))
case = doc["case"]
st = dt.Settings(seeds=16, spp=32, cycles_spp=32, integrator="pt")
def noshadow(scene):
    for m in scene.meshes:
        if m.get("name", "").startswith("ico"):
            m["cast_shadow"] = False
for name, mut in (("ico casts no shadow (Lantern)", noshadow), ("as is", None)):
    res = dt.run_case(copy.deepcopy(case), st, base=0, controls=False, mutate=mut)
    print("RESULT", name, res.line(), flush=True)
