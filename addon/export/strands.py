"""An object instance's hair (Curves data, particle hair of render type Path) as Lantern strand
sets (lantern.Scene.add_curves' dicts; docs/curves.md), through export/curves.py. Cycles' curve
shape (scene.cycles_curves.shape): Thick Linear is exactly Lantern's round linear segments;
3D Curves (THICK) are Catmull-Rom splines, cut into CATMULL_ROM_PIECES linear pieces per key
interval (curves.catmull_rom_pieces); Ribbons (flat strips facing the ray) render as round
tubes, with a warning."""

import numpy as np

from . import curves

CATMULL_ROM_PIECES = 4


def curve_shape(bscene, report):
    """Cycles' curve shape of the scene ('THICK_LINEAR', 'THICK' or 'RIBBONS'), warned once
    where Lantern renders it otherwise."""
    settings = getattr(bscene, "cycles_curves", None)
    shape = str(getattr(settings, "shape", "THICK_LINEAR"))
    return shape


def see_through(material):
    """Whether a converted material covers less than all (Alpha below 1, a Transparent BSDF in
    a mix, an alpha texture or node graph): strands render opaque in Lantern (the stochastic
    alpha test, native/src/scene/alpha.h, is the triangles'), Cycles lets rays through them."""
    return material.get("alpha", 1.0) < 1.0 or "alpha_texture" in material or any(
        p.get("target") == "alpha" for p in material.get("programs", []))


def attributes_read(material, names):
    """The attribute channels (`names`: the AttributeTable's) that a converted material's node
    programs read: Generated and Object coordinates, colour and named attributes are the
    triangles' vertex data, which strands do not carry (the core reads 0 there); Cycles gives a
    strand its own (difftest D44: a ridged Noise of the implicit Generated read black)."""
    from .node_ops import IN_ATTRIBUTE, OP
    found = []
    for p in material.get("programs", []):
        for w in p.get("code", []):
            if (w[0] & 0xFF) == OP["input"] and ((w[0] >> 8) & 0xFF) == IN_ATTRIBUTE:
                name = names[w[3]] if 0 <= w[3] < len(names) else f"channel {w[3]}"
                if name not in found:
                    found.append(name)
    return found


class StrandExporter:
    def __init__(self, bscene, materials, report, final=True, viewport_cache=False):
        self.materials, self.report, self.final = materials, report, final
        self.viewport_cache = viewport_cache   # a viewport depsgraph (curves.particle_*)
        self.shape = curve_shape(bscene, report)
        self.sets = []

    def export(self, inst):
        """The instance's strand sets, appended to self.sets; returns how many."""
        found = self.sets_of(inst)
        self.sets.extend(found)
        return len(found)

    def sets_of(self, inst):
        """The instance's strand sets (their ray visibility: export/walk.py)."""
        obj = inst.object
        found = curves.object_strands(obj, inst.matrix_world, self.report, final=self.final,
                                      viewport_cache=self.viewport_cache)
        if not found:
            return []
        if self.shape == "RIBBONS":
            self.report.warn("Hair: Cycles' curve shape 'Ribbons' (Render Properties > Curves) "
                             "renders as round tubes in Lantern ('3D Curves' or 'Linear 3D "
                             "Curves' match)")
        slots = [self.materials.index(s.material) for s in obj.material_slots] or [0]
        for slot in sorted(set(slots)):
            mat = self.materials.materials[slot]
            if see_through(mat):
                self.report.warn(f"Hair: the material '{mat.get('name', slot)}' of "
                                 f"'{obj.name}' is partly transparent (Alpha, a Transparent "
                                 "BSDF): strands render opaque in Lantern, its emission and "
                                 "shading at full coverage (Cycles lets rays through them)")
            read = attributes_read(mat, list(getattr(getattr(
                self.materials, "attributes", None), "names", [])))
            if read:
                self.report.warn(f"Hair: the material '{mat.get('name', slot)}' of "
                                 f"'{obj.name}' reads {', '.join(repr(n) for n in read)} "
                                 "(texture coordinates or attributes, an unlinked texture "
                                 "vector's Generated too), which strands do not carry in "
                                 "Lantern: read as 0 there (Cycles gives each strand its own)")
        lut = np.array(slots, dtype=np.uint32)
        out = []
        for k, st in enumerate(found):
            if self.shape == "THICK":
                st = curves.catmull_rom_pieces(st, CATMULL_ROM_PIECES)
            out.append({
                "name": f"{obj.name}/{k}",
                "points": np.ascontiguousarray(st.points, np.float32),
                "radius": np.ascontiguousarray(st.radius, np.float32),
                "offsets": np.ascontiguousarray(st.offsets, np.uint32),
                "material_ids": lut[np.clip(st.material, 0, len(lut) - 1)],
            })
        return out
