"""The Mitsuba scene walker: XML elements to a lantern.Scene (see the package docstring)."""

import math
import os
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

from ..scene import Scene
from .bsdf import _BsdfReader
from .common import _BH_STD_PER_WIDTH, Y_UP_TO_Z_UP, MitsubaError, log
from .geometry import (_bool_text, _floats, _xyz, camera_to_lantern, cube_mesh, disk_mesh,
                       fov_tangents, parse_transform, read_obj, read_ply, rectangle_mesh,
                       sphere_mesh, transform_mesh)

# ---------------------------------------------------------------------------------------------
# The loader
# ---------------------------------------------------------------------------------------------

class _Loader(_BsdfReader):
    def __init__(self, path, params):
        self.path = Path(path)
        self.dir = self.path.parent
        self.params = dict(params or {})
        self.warnings = []
        self.ids = {}
        self.scene = Scene()
        self.material_ids = {}       # (bsdf key, emission tuple) -> material id
        self.fallback_types = {}     # bsdf type -> count
        self.beckmann = {}           # BSDFs with a Beckmann distribution (read as GGX), ordered
        self.one_sided = True
        self.emitter_backs = []
        self.metadata = {"source": str(self.path), "max_depth": None, "integrator": None,
                         "spp": None, "rfilter": "box", "warnings": self.warnings}

    def warn(self, msg):
        if msg not in self.warnings:
            self.warnings.append(msg)
            log.warning(msg)

    # ---- parameters and properties ----

    def subst(self, root):
        """Collect `<default>`s (caller params win), then replace $name in every attribute."""
        for el in list(root):
            if el.tag == "default":
                self.params.setdefault(el.get("name"), el.get("value"))
        names = sorted(self.params, key=len, reverse=True)
        pattern = re.compile(r"\$(" + "|".join(re.escape(n) for n in names) + r")") \
            if names else None
        for el in root.iter():
            for k, v in el.attrib.items():
                if "$" in v and pattern is not None:
                    el.attrib[k] = pattern.sub(lambda mo: str(self.params[mo.group(1)]), v)
                if "$" in el.attrib[k]:
                    raise MitsubaError(f"<{el.tag}> {k}={v!r}: undefined parameter")

    def props(self, el):
        """Named properties of an element: {name: value}; nested objects are skipped."""
        out = {}
        for c in el:
            name = c.get("name")
            tag = c.tag
            if tag in ("float", "integer"):
                out[name] = float(c.get("value")) if tag == "float" else int(float(c.get("value")))
            elif tag == "boolean":
                out[name] = _bool_text(c.get("value"))
            elif tag == "string":
                out[name] = c.get("value")
            elif tag in ("rgb", "spectrum"):
                vals = _floats(c.get("value", "0"), f"<{tag} name={name!r}>")
                if tag == "spectrum" and len(vals) != 1:
                    self.warn(f"spectrum {name!r}: only a constant spectrum is read; "
                              f"using the mean of its values")
                    vals = [float(np.mean(vals[1::2])) if len(vals) % 2 == 0 else vals[0]]
                out[name] = vals * 3 if len(vals) == 1 else vals[:3]
            elif tag in ("point", "vector"):
                out[name] = _xyz(c)
            elif tag == "transform":
                out[name] = parse_transform(c)
        return out

    def _child_objects(self, el, tag):
        """Nested `<tag>` objects and `<ref>`s that resolve to one."""
        out = []
        for c in el:
            if c.tag == tag:
                out.append(c)
            elif c.tag == "ref":
                target = self.ids.get(c.get("id"))
                if target is None:
                    raise MitsubaError(f"<ref id={c.get('id')!r}>: no object with that id")
                if target.tag == tag:
                    out.append(target)
        return out

    def material(self, bsdf_el, emission, name):
        key = (id(bsdf_el) if bsdf_el is not None else None, tuple(emission))
        mid = self.material_ids.get(key)
        if mid is None:
            params = (self.bsdf_material(bsdf_el) if bsdf_el is not None
                      else {"type": "diffuse", "base_color": [0.5, 0.5, 0.5]})
            mname = (bsdf_el.get("id") if bsdf_el is not None else None) or name
            if max(emission) > 0:
                mname = f"{mname}_emitter"
            mid = self.scene.add_material(mname, emission=emission, **params)
            self.material_ids[key] = mid
        return mid

    # ---- shapes ----

    def shape(self, el, index):
        stype = el.get("type")
        p = self.props(el)
        name = el.get("id") or f"{stype}_{index}"
        m = p.get("to_world", np.eye(4))
        if stype in ("obj", "ply"):
            fname = p.get("filename")
            if fname is None:
                raise MitsubaError(f"shape {name!r}: missing filename")
            fpath = Path(fname) if os.path.isabs(fname) else self.dir / fname
            pos, idx, nrm, uv = (read_obj if stype == "obj" else read_ply)(fpath)
            if p.get("face_normals", False):
                nrm = None
        elif stype == "rectangle":
            pos, idx, nrm, uv = rectangle_mesh()
        elif stype == "cube":
            pos, idx, nrm, uv = cube_mesh()
        elif stype == "disk":
            pos, idx, nrm, uv = disk_mesh()
        elif stype == "sphere":
            pos, idx, nrm, uv = sphere_mesh(p.get("center", [0.0, 0.0, 0.0]),
                                            p.get("radius", 1.0))
        elif stype in ("shapegroup", "instance", "serialized", "cylinder"):
            self.warn(f"shape {stype!r} is not supported; skipped")
            return
        else:
            self.warn(f"shape {stype!r} is not supported; skipped")
            return
        pos, nrm = transform_mesh(Y_UP_TO_Z_UP @ m, np.asarray(pos, dtype=np.float64),
                                  None if nrm is None else np.asarray(nrm, dtype=np.float64))
        idx = np.asarray(idx, dtype=np.uint32)
        if np.linalg.det(m[:3, :3]) < 0:
            idx = idx[:, [0, 2, 1]]  # keep the geometric normal on the shading normal's side
        if p.get("flip_normals", False):
            idx = idx[:, [0, 2, 1]]
            if nrm is not None:
                nrm = -nrm
        bsdfs = self._child_objects(el, "bsdf")
        emission = [0.0, 0.0, 0.0]
        for em in self._child_objects(el, "emitter"):
            if em.get("type") == "area":
                emission = [float(x) for x in self.props(em).get("radiance", [1.0] * 3)]
            else:
                self.warn(f"emitter {em.get('type')!r} inside a shape is not supported")
        bsdf = bsdfs[0] if bsdfs else None
        mid = self.material(bsdf, emission, name)
        self.scene.add_mesh(pos, idx, material=mid, normals=nrm, uvs=uv, name=name)
        if max(emission) > 0 and self.one_sided and stype not in ("sphere", "cube"):
            # (closed shapes emit their back side inwards, where it is never seen)
            self.emitter_backs.append((name, pos, idx, nrm, uv, bsdf))

    def add_emitter_backs(self):
        """Mitsuba's area emitters emit from their front (the geometric normal's side) only;
        Lantern's mesh emission is two-sided. Give every emissive mesh a non-emissive copy of
        itself (the emitter's own BSDF) a hair behind it, facing the other way: it absorbs the
        back-side emission and shows the BSDF from behind, as Mitsuba does."""
        if not self.emitter_backs:
            return
        lo = np.min([m["positions"].min(axis=0) for m in self.scene.meshes], axis=0)
        hi = np.max([m["positions"].max(axis=0) for m in self.scene.meshes], axis=0)
        eps = 1e-4 * float(np.linalg.norm(hi - lo))
        for name, pos, idx, nrm, uv, bsdf in self.emitter_backs:
            tri = pos[idx.astype(np.int64)]
            fn = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
            vn = np.zeros_like(pos)
            for k in range(3):
                np.add.at(vn, idx[:, k].astype(np.int64), fn)
            ln = np.linalg.norm(vn, axis=1, keepdims=True)
            vn = vn / np.where(ln > 0, ln, 1.0)
            mid = self.material(bsdf, [0.0, 0.0, 0.0], name)
            self.scene.add_mesh(pos - eps * vn, idx[:, [0, 2, 1]], material=mid,
                                normals=None if nrm is None else -nrm, uvs=uv,
                                name=f"{name}_back")

    # ---- emitters, sensor, integrator ----

    def emitter(self, el):
        etype = el.get("type")
        p = self.props(el)
        if etype == "constant":
            self.scene.world["color"] = [float(x) for x in p.get("radiance", [1.0] * 3)]
        elif etype == "point":
            pos = p.get("position")
            if pos is None:
                pos = p.get("to_world", np.eye(4))[:3, 3].tolist()
            pos = (Y_UP_TO_Z_UP[:3, :3] @ np.asarray(pos, dtype=np.float64)).tolist()
            intensity = np.asarray(p.get("intensity", [1.0] * 3), dtype=np.float64)
            self.scene.add_light("point", position=pos, radius=0.0,
                                 power=(4.0 * math.pi * intensity).tolist(),
                                 soft_falloff=False, visible_camera=False)
        else:
            self.warn(f"emitter {etype!r} is not supported; skipped")

    def sensor(self, el, width, height):
        stype = el.get("type")
        p = self.props(el)
        film = next((c for c in el if c.tag == "film"), None)
        fp = self.props(film) if film is not None else {}
        if film is not None and film.get("type") not in ("hdrfilm", None):
            self.warn(f"film {film.get('type')!r}: read as hdrfilm")
        src_w = int(fp.get("width", 768))
        src_h = int(fp.get("height", 576))
        if any(k in fp for k in ("crop_width", "crop_height", "crop_offset_x", "crop_offset_y")):
            self.warn("film crop window is ignored")
        if width is None and height is None:
            width, height = src_w, src_h
        elif height is None:
            height = max(1, round(width * src_h / src_w))
        elif width is None:
            width = max(1, round(height * src_w / src_h))
        if abs(width / height - src_w / src_h) > 1e-3 * src_w / src_h:
            self.warn(f"resolution {width}x{height} changes the aspect ratio of the scene's "
                      f"{src_w}x{src_h} film")
        self.metadata["source_resolution"] = [src_w, src_h]
        self.scene.film["width"], self.scene.film["height"] = int(width), int(height)

        # pixel filter: Blackman-Harris with the same standard deviation
        rf = film.find("rfilter") if film is not None else None
        rtype = rf.get("type") if rf is not None else "gaussian"
        rp = self.props(rf) if rf is not None else {}
        if rtype == "tent":
            std = rp.get("radius", 1.0) / math.sqrt(6.0)
        elif rtype == "box":
            std = 1.0 / math.sqrt(12.0)
        elif rtype == "gaussian":
            std = rp.get("stddev", 0.5)
        else:
            std = None
            self.warn(f"rfilter {rtype!r}: Lantern has only Blackman-Harris; using its "
                      f"default width 1.5")
        self.metadata["rfilter"] = rtype
        fw = 1.5 if std is None else std / _BH_STD_PER_WIDTH
        # (in pixels of the output film: at a reduced resolution this is the filter Mitsuba
        # itself would use rendering at that resolution)
        self.scene.film["filter_width"] = float(fw)
        sampler = next((c for c in el if c.tag == "sampler"), None)
        if sampler is not None:
            self.metadata["spp"] = self.props(sampler).get("sample_count")

        if stype not in ("perspective", "thinlens"):
            self.warn(f"sensor {stype!r} is not supported; using a perspective camera")
        if stype == "thinlens":
            self.warn("thinlens: depth of field is ignored (pinhole camera)")
        if "focal_length" in p and "fov" not in p:
            f = float(re.sub(r"mm$", "", str(p["focal_length"]).strip()))
            fov = math.degrees(2.0 * math.atan(math.hypot(36.0, 24.0) / (2.0 * f)))
            axis = "diagonal"
        else:
            fov = float(p.get("fov", 0.0)) if "fov" in p else None
            axis = p.get("fov_axis", "x")
            if fov is None:
                fov = math.degrees(2.0 * math.atan(math.hypot(36.0, 24.0) / (2.0 * 50.0)))
                axis = "diagonal"
        if "principal_point_offset_x" in p or "principal_point_offset_y" in p:
            self.warn("principal point offsets are ignored")
        tx, ty = fov_tangents(fov, axis, width, height)
        cam, mirrored = camera_to_lantern(p.get("to_world", np.eye(4)))
        if mirrored:
            self.warn("sensor to_world mirrors the image (negative determinant); Lantern's "
                      "camera is rigid, so the import is the unmirrored image")
        self.scene.camera = {
            "type": "perspective",
            "to_world": (Y_UP_TO_Z_UP @ cam).tolist(),
            "screen": [-tx, tx, -ty, ty],
            "clip": [float(p.get("near_clip", 1e-2)), float(p.get("far_clip", 1e4))],
        }

    def integrator(self, el):
        p = self.props(el)
        itype = el.get("type")
        self.metadata["integrator"] = itype
        if itype not in ("path", "volpath", "volpathmis", "prb", "direct"):
            self.warn(f"integrator {itype!r}: read as a path tracer (max_depth only)")
        depth = p.get("max_depth", -1)
        if itype == "direct":
            depth = 2
        self.metadata["max_depth"] = None if depth is None or depth < 0 else int(depth)

    # ---- whole file ----

    def load(self, width, height):
        try:
            root = ET.parse(self.path).getroot()
        except ET.ParseError as e:
            raise MitsubaError(f"{self.path}: not valid XML ({e})") from None
        if root.tag != "scene":
            raise MitsubaError(f"{self.path}: the root element is <{root.tag}>, not <scene>")
        self.subst(root)
        for el in root.iter():
            if el.get("id") is not None and el.tag != "ref":
                self.ids[el.get("id")] = el
        sensor_seen = False
        shape_index = 0
        for el in root:
            tag = el.tag
            if tag in ("default", "bsdf", "texture", "ref"):
                continue
            if tag == "integrator":
                self.integrator(el)
            elif tag == "sensor":
                if sensor_seen:
                    self.warn("more than one sensor: using the first")
                    continue
                sensor_seen = True
                self.sensor(el, width, height)
            elif tag == "shape":
                self.shape(el, shape_index)
                shape_index += 1
            elif tag == "emitter":
                self.emitter(el)
            else:
                self.warn(f"<{tag}> is not supported; skipped")
        self.add_emitter_backs()
        if not sensor_seen:
            self.warn("no sensor: using Lantern's default camera")
        if self.fallback_types:
            kinds = ", ".join(f"{k} ({n})" for k, n in sorted(self.fallback_types.items()))
            self.warn(f"BSDFs not supported yet, imported as diffuse: {kinds}")
        if self.beckmann:
            self.warn(f"Beckmann microfacet distribution read as GGX with the same alpha "
                      f"(Lantern has Beckmann for conductors only): {', '.join(self.beckmann)}")
        self.scene.metadata = self.metadata
        return self.scene.validate()


def load_mitsuba(path, width=None, height=None, params=None, one_sided_emitters=True):
    """Read a Mitsuba 3 XML scene into a validated `lantern.Scene`.

    `width`/`height` override the film size (one alone keeps the aspect ratio); `params`
    overrides `<default>` values ({"spp": "16"}). The result carries `scene.metadata`:
    {"max_depth": int | None (Mitsuba's count, which Lantern shares; None = unlimited),
     "integrator", "spp", "rfilter", "source_resolution", "source", "warnings": [...]}.
    `metadata` is not written to `.lantern` files.

    `one_sided_emitters` backs each area emitter with a non-emissive copy of itself a hair
    behind it, so it emits from its front only as in Mitsuba (Lantern's mesh emission is
    two-sided; without this the Cornell box is ~12% too bright: the light's back lights the
    ceiling 2 cm above it)."""
    loader = _Loader(path, params)
    loader.one_sided = bool(one_sided_emitters)
    return loader.load(width, height)
