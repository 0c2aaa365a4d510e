# before/after bits of scenes that take the edited shadow loops (fog box, shadow linking, strands)
import sys, hashlib, numpy as np
sys.path.insert(0, "tests/python")
import test_no_shadow_media as t
import test_linking_shadow_media as tl
out = {}
cases = {"obj_box": lambda: t.obj("box"), "obj_world": lambda: t.obj("world"),
         "lamp_box": lambda: t.lamp("box"), "linked_box": lambda: t.fogged(t.room("glass", slab=True), "box")}
def linked_box():
    s = t.room("glass", slab=True); s.meshes[3]["shadow_set"] = 1; s.meshes[4]["blockers"] = [0]
    return t.fogged(s, "box")
cases["linked_box2"] = linked_box
for name, b in cases.items():
    for integ in ("pt", "bdpt"):
        img, w = tl.render(b(), integ, 5, spp=4)
        out[f"{name}_{integ}"] = hashlib.sha1(np.ascontiguousarray(img).tobytes()).hexdigest()
        print(name, integ, out[f"{name}_{integ}"], w[:1], flush=True)
