"""Holdouts, with Cycles' meaning (measured with bpy 5.0.1, tests/render/test_world_film.py):
where the camera sees a holdout, the pixel gets no colour and alpha 0; the holdout still hides
what is behind it and casts shadows.

- The Holdout shader: a material of "holdout": True that indirect rays see as black (it has no
  BSDF), material.py's convert_material hands it here.
- A holdout object (Object > Visibility > Holdout, or in a view layer's holdout collection):
  its materials as they are, copied with "holdout": True, so that indirect rays still see them.

- A shadow catcher object (Object > Visibility > Shadow Catcher): its mesh gets
  "shadow_catcher": True; over transparent film only the shadow it receives shows, as alpha
  (lantern/film.py has the whole meaning, Cycles' with the Shadow Catcher pass off).

The core ends camera paths on holdout and catcher triangles (integrator/pt.h, TriangleFlags
kHoldout, kShadowCatcher) and lantern/film.py gives them no coverage. Only pt does: the
bidirectional integrators render both as ordinary surfaces, and the export says so; a shadow
catcher without transparent film renders as an ordinary surface too, named in a warning."""

import numpy as np


def holdout_material(material):
    """The Lantern material of a Blender material whose surface is a Holdout shader."""
    return {"name": material.name, "type": "diffuse", "base_color": [0.0, 0.0, 0.0],
            "holdout": True}


def _holdout_copy(m):
    return dict(m, holdout=True, name=f"{m.get('name', 'material')} (holdout)")


class Holdouts:
    """Holdout objects' meshes pointed at holdout copies of their materials (one copy per
    material), and the warning for integrators that do not render holdouts."""

    def __init__(self, materials, report, integrator="pt", view_layer=None, transparent=True):
        self.materials = materials      # export/material.py MaterialTable
        self.report = report
        self.integrator = integrator
        self.transparent = transparent  # the film's (None: the viewport): catchers need it
        self.view_layer = view_layer    # for holdout collections (Object.holdout_get)
        self._copies = {}

    def _copy(self, index):
        if index not in self._copies:
            table = self.materials.materials
            table.append(_holdout_copy(table[index]))
            self._copies[index] = len(table) - 1
        return self._copies[index]

    def refresh(self):
        """The copies made again from their materials (the viewport's sync keeps this object
        and its copies across syncs, and converts an edited material again in its slot)."""
        table = self.materials.materials
        for index, copy in self._copies.items():
            table[copy] = _holdout_copy(table[index])

    def mesh(self, obj, mesh):
        """Called for every exported mesh of object `obj` (export/__init__.py)."""
        if getattr(obj, "is_shadow_catcher", False):
            self.shadow_catcher(obj, mesh)
        shader = any(self.materials.materials[i].get("holdout") for i in
                     np.unique(mesh["material_ids"]).tolist())
        if self.is_holdout(obj):
            ids = np.asarray(mesh["material_ids"], np.int64)
            used = np.unique(ids)
            lut = np.zeros(int(used.max()) + 1 if len(used) else 1, np.uint32)
            for i in used.tolist():
                lut[i] = self._copy(i)
            mesh["material_ids"] = lut[ids]  # a new array: MeshExporter's cache keeps its own
            shader = True
        if shader and self.integrator != "pt":
            self.report.warn(f"Object '{obj.name}': holdouts are rendered by the pt integrator "
                             f"only; {self.integrator} renders it as an ordinary surface")

    def shadow_catcher(self, obj, mesh):
        if self.integrator != "pt":
            self.report.warn(f"Object '{obj.name}': a shadow catcher is rendered by the pt "
                             f"integrator only; {self.integrator} renders it as an ordinary "
                             "surface")
        elif self.transparent is None:
            self.report.warn(f"Object '{obj.name}': the viewport renders the shadow catcher "
                             "as an ordinary surface (a final render over transparent film "
                             "shows its shadow only)")
        elif not self.transparent:
            self.report.warn(f"Object '{obj.name}': a shadow catcher is rendered over "
                             "transparent film only (Film > Transparent); it renders as an "
                             "ordinary surface")
        else:
            mesh["shadow_catcher"] = True

    def is_holdout(self, obj):
        """The object's own flag or a holdout collection of the view layer (what Cycles reads)."""
        if getattr(obj, "is_holdout", False):
            return True
        original = getattr(obj, "original", obj)
        if self.view_layer is None or not hasattr(original, "holdout_get"):
            return False
        try:
            return bool(original.holdout_get(view_layer=self.view_layer))
        except (TypeError, RuntimeError, ReferenceError):
            return False
