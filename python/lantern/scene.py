"""The Lantern scene: the one container between the add-on, the scene file and the native core.

Fields, units and the `.lantern` file follow docs/scene_format.md. `validate()` normalises the
scene in place (dtypes, defaults) and raises ValueError naming the offending element; the
fields' choices, defaults and checks are in scene_schema.py."""

import io
import json
import zipfile
from pathlib import Path

import numpy as np

from .grid_schema import MAX_GRID_VOXELS, validate_density_grid, validate_grid
from .scene_file import ARRAY_SPECS, SceneArchive, SceneError, entries, member_name, read_mesh
from .scene_schema import (
    MATERIAL_TEXTURES, MESH_ARRAYS, RAY_VISIBILITY, _int, default_camera, default_film, default_world,
    flatten_programs, look_at, receiver_mask, screen_for_fov, validate_camera, validate_film, validate_light, validate_material,
    validate_mesh, validate_texture, validate_world)

FORMAT_NAME = "lantern-scene"
FORMAT_VERSION = 1


def fixed_time_member(name, compress_type=zipfile.ZIP_DEFLATED):
    """A zip member stamped 1980-01-01: the same scene saves to the same bytes (writestr with a
    bare name stamps the current time, two seconds apart from a save a moment later)."""
    info = zipfile.ZipInfo(name, date_time=(1980, 1, 1, 0, 0, 0))
    info.compress_type = compress_type
    info.external_attr = 0o644 << 16
    return info

class Scene:
    """Film, camera, world, materials, meshes and lights, as in docs/scene_format.md.

    An empty Scene is valid: a 64x64 image of a black world seen by a camera at the origin
    looking down -Z."""

    def __init__(self):
        self.film = default_film()
        self.camera = default_camera()
        self.world = default_world()
        self.materials = []
        self.meshes = []
        self.lights = []
        self.textures = []
        self.attribute_channels = []   # names of the meshes' per-vertex attribute channels
        self.curves = []               # strand sets (add_curves; docs/curves.md)
        self.grids = []   # Volume objects' density grids (grid_schema.py, docs/volumes.md)

    def add_grid(self, voxels, index_to_world=None, name=None):
        """Append a density grid: voxels (nz, ny, nx), voxel (i, j, k) centred at index
        (i, j, k), mapped to the world by index_to_world (4x4, default identity); or a colour
        grid, voxels (nz, ny, nx, 3). Returns its index for a material's "density_grid" (or
        "temperature_grid", "flame_grid", "color_grid")."""
        grid = {"name": name if name is not None else f"grid_{len(self.grids)}",
                "voxels": voxels,
                "index_to_world": np.eye(4) if index_to_world is None else index_to_world}
        self.grids.append(validate_grid(grid, len(self.grids)))
        return len(self.grids) - 1

    # ---- Building ----

    def add_texture(self, pixels, name=None, colorspace="srgb", wrap="repeat",
                    interpolation="linear", output="color", uv_transform=None):
        """Append an image texture; returns its id for a material's `*_texture` inputs.

        `pixels`: (height, width, 4) RGBA, rows bottom to top (Blender's order: uv (0, 0) is the
        lower-left corner); uint8 is stored as 8-bit, decoded from sRGB when `colorspace` is
        "srgb" (colour images) or read as is for "linear" (Non-Color data); float32 is scene
        linear. (H, W, 3) gets alpha 1. `output`: what scalar inputs (roughness, metallic, alpha)
        read: "color" (its luminance), "alpha", or one channel ("red", "green", "blue"). `uv_transform`: [[a, b, c], [d, e, f]],
        u' = a u + b v + c, v' = d u + e v + f (Blender's Mapping node)."""
        if name is None:
            name = f"texture_{len(self.textures)}"
        tex = {"name": str(name), "pixels": pixels, "colorspace": colorspace, "wrap": wrap,
               "interpolation": interpolation, "output": output,
               "uv_transform": uv_transform if uv_transform is not None
               else [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]}
        self.textures.append(validate_texture(tex, len(self.textures)))
        return len(self.textures) - 1

    def add_material(self, name=None, base_color=(0.8, 0.8, 0.8), emission=(0.0, 0.0, 0.0),
                     type="diffuse", roughness=0.5, ior=1.5, specular_tint=(1.0, 1.0, 1.0),
                     metallic=0.0, transmission=0.0, specular_level=0.5, multiscatter=True,
                     tint_reflection=False,
                     coat_weight=0.0, coat_roughness=0.03, coat_ior=1.5,
                     coat_tint=(1.0, 1.0, 1.0), sheen_weight=0.0, sheen_roughness=0.5,
                     thin_film_thickness=0.0, thin_film_ior=1.33,
                     sheen_tint=(1.0, 1.0, 1.0), eta=None, k=None, distribution="ggx",
                     alpha=1.0, normal_strength=1.0, coat_normal_strength=1.0, mix=None,
                     diffuse_roughness=0.0,
                     anisotropy=0.0, anisotropic_rotation=0.0, tangent="triangle",
                     subsurface=None, hair=None, **textures):
        """Append a material; returns its id (index into `materials`).

        `type`: "diffuse" (Lambert, albedo `base_color`; `diffuse_roughness` > 0: Blender's
        energy-preserving Oren-Nayar), "conductor" (GGX metal with F0 `base_color` and F82
        `specular_tint`; given `eta` and `k` (RGB, complex index eta + i k) the exact conductor
        Fresnel instead, scaled by `base_color`), "dielectric" (glass of index `ior`, GGX
        `roughness`; roughness 0 is smooth, `base_color` tints transmission, and reflection too with
        `tint_reflection`, as Blender's Glass BSDF), "principled"
        (Blender's Principled BSDF as layers: sheen, coat, `metallic`, `transmission`, a
        dielectric specular layer of `ior`, `specular_level` and `specular_tint` over a diffuse
        `base_color`; docs/materials.md), "translucent" (Lambertian transmission of colour
        `base_color`) or "mix": `mix` = [[leaf, weight], ...] (up to 4 leaf material ids, not
        mixes): sum of weight x leaf BSDF (Blender's Mix Shader: 1 - fac, fac; Add Shader:
        1, 1), emission likewise; `mix_texture` gives two leaves the weights 1 - t, t.
        `anisotropy` (Blender's Anisotropic) stretches the GGX lobes along a tangent: `tangent`
        "uv" (the uv map's) or "triangle" (each triangle's first minus third vertex, Cycles'
        default), turned by `anisotropic_rotation` (turns). `alpha` < 1 lets that share of rays
        pass the surface (Blender's Alpha). Textures by id: `base_color_texture`,
        `roughness_texture`, `metallic_texture`, `alpha_texture`, `normal_texture` (a
        tangent-space normal map of `normal_strength`), `emission_texture` (radiance = texel x
        `emission`), `coat_normal_texture` (principled: the coat's own tangent-space normal map
        of `coat_normal_strength`; without it, a coat under a normal-mapped base follows the
        smooth interpolated normal, as Cycles' unlinked Coat Normal). `thin_film_thickness`
        (nm, 0: none) and `thin_film_ior`: thin-film interference on the principled specular layer
        and metal, and on conductors (docs/materials.md)."""
        if name is None:
            name = f"material_{len(self.materials)}"
        material = {
            "name": str(name), "type": type, "base_color": base_color, "emission": emission,
            "roughness": roughness, "ior": ior, "specular_tint": specular_tint,
            "metallic": metallic, "transmission": transmission, "specular_level": specular_level,
            "multiscatter": multiscatter, "tint_reflection": tint_reflection,
            "coat_weight": coat_weight,
            "coat_roughness": coat_roughness, "coat_ior": coat_ior, "coat_tint": coat_tint,
            "sheen_weight": sheen_weight, "sheen_roughness": sheen_roughness,
            "sheen_tint": sheen_tint, "distribution": distribution, "alpha": alpha,
            "thin_film_thickness": thin_film_thickness, "thin_film_ior": thin_film_ior,
            "normal_strength": normal_strength, "coat_normal_strength": coat_normal_strength,
            "diffuse_roughness": diffuse_roughness,
            "anisotropy": anisotropy, "anisotropic_rotation": anisotropic_rotation,
            "tangent": tangent,
        }
        if mix is not None:
            material["mix"] = mix
        if subsurface is not None:  # dict: weight, radius (x scale, metres), ior, anisotropy,
            # method ("random_walk", "random_walk_skin"); docs/subsurface.md
            unknown = set(subsurface) - {"weight", "radius", "ior", "anisotropy", "method"}
            if unknown:
                raise TypeError(f"add_material() subsurface: unknown keys {sorted(unknown)}")
            material.update({"subsurface_" + k: v for k, v in subsurface.items()})
        if hair is not None:  # type "hair": Principled Hair (docs/curves.md); keys
            # parametrization ("melanin", "color": base_color, "absorption"), melanin,
            # melanin_redness, tint, absorption, radial_roughness, coat, offset (radians)
            from .curves_schema import HAIR_KEYS
            unknown = set(hair) - set(HAIR_KEYS)
            if unknown:
                raise TypeError(f"add_material() hair: unknown keys {sorted(unknown)}")
            material.update({HAIR_KEYS[k]: v for k, v in hair.items()})
        for key, value in textures.items():
            if key not in MATERIAL_TEXTURES:
                raise TypeError(f"add_material() got an unexpected keyword argument {key!r}")
            if value is not None:
                material[key] = value
        if eta is not None or k is not None:
            material.update(eta=eta, k=k)
        material = validate_material(material, len(self.materials), len(self.textures))
        self.materials.append(material)
        return len(self.materials) - 1

    def material_id(self, material):
        """Material id from an id or a name."""
        if isinstance(material, str):
            for i, m in enumerate(self.materials):
                if m.get("name") == material:
                    return i
            raise ValueError(f"no material named {material!r}")
        return _int(material, "material", minimum=0)

    def add_mesh(self, positions, indices, material=0, normals=None, uvs=None,
                 material_ids=None, name=None, visible_camera=True, cast_shadow=True,
                 tangents=None, **ray_visibility):
        """Append a triangle mesh; `material` (id or name) applies to every triangle unless
        `material_ids` gives one per triangle. `ray_visibility`: visible_diffuse,
        visible_glossy, visible_transmission, visible_volume_scatter (bools, default True;
        Cycles' object ray visibility, rendered by pt). Returns the mesh index."""
        unknown = set(ray_visibility) - set(RAY_VISIBILITY)
        if unknown:
            raise TypeError(f"add_mesh: unexpected keyword(s) {sorted(unknown)}")
        if name is None:
            name = f"mesh_{len(self.meshes)}"
        indices = np.asarray(indices)
        if material_ids is None:
            count = indices.shape[0] if indices.ndim >= 1 else 0
            material_ids = np.full(count, self.material_id(material), dtype=np.uint32)
        mesh = {
            "name": str(name),
            "positions": positions,
            "indices": indices,
            "normals": normals,
            "uvs": uvs,
            "tangents": tangents,
            "material_ids": material_ids,
            "visible_camera": visible_camera,
            "cast_shadow": cast_shadow,
            **ray_visibility,
        }
        validate_mesh(mesh, len(self.meshes))
        self.meshes.append(mesh)
        return len(self.meshes) - 1

    def add_curves(self, points, radius, offsets, material=0, material_ids=None, name=None,
                   visible_camera=True, cast_shadow=True, deform=None, deform_radius=None,
                   motion=None, motion_base=None, **ray_visibility):
        """Append a set of strands rendered as round linear segments (docs/curves.md): points
        (P, 3) world space, radius (P,) per point, offsets (S + 1,): strand s is points
        offsets[s] .. offsets[s + 1] - 1; `material` (id or name) for every strand unless
        `material_ids` gives one per strand. Motion blur (docs/motion_blur.md "Strands"):
        `deform` (S, P, 3) the points and `deform_radius` (S, P) the radii at S >= 2 steps evenly
        spread over the shutter, placed as `points`; `motion` (S, 4, 4) the object-to-world
        matrices of the object the strands move with and `motion_base` the one `points` were
        exported with ("Strands of a turning object": turned along their arcs).
        `ray_visibility`: visible_diffuse, visible_glossy, visible_transmission,
        visible_volume_scatter, its object's (as add_mesh's). Returns the set's index."""
        from .curves_schema import validate_curves
        unknown = set(ray_visibility) - set(RAY_VISIBILITY)
        if unknown:
            raise TypeError(f"add_curves: unexpected keyword(s) {sorted(unknown)}")
        if name is None:
            name = f"curves_{len(self.curves)}"
        offsets = np.asarray(offsets)
        if material_ids is None:
            material_ids = np.full(max(len(offsets) - 1, 0), self.material_id(material),
                                   dtype=np.uint32)
        c = {"name": str(name), "points": points, "radius": radius, "offsets": offsets,
             "material_ids": material_ids, "visible_camera": visible_camera,
             "cast_shadow": cast_shadow, "deform": deform, "deform_radius": deform_radius,
             "motion": motion, "motion_base": motion_base, **ray_visibility}
        self.curves.append(validate_curves(c, len(self.curves), len(self.materials)))
        return len(self.curves) - 1

    def add_light(self, type, **params):
        """Append a light of `type` (point, spot, area, sun) with the fields of
        docs/scene_format.md; missing optional fields get defaults. Returns the light index."""
        light = {"type": type}
        light.update(params)
        self.lights.append(validate_light(light, len(self.lights)))
        return len(self.lights) - 1

    def look_at(self, eye, target, up=(0.0, 0.0, 1.0), fov=None):
        """Point a perspective camera; `fov` in degrees along the larger image side."""
        self.camera["to_world"] = look_at(eye, target, up)
        self.camera["type"] = "perspective"
        if fov is not None:
            self.camera["screen"] = screen_for_fov(fov, self.film["width"],
                                                   self.film["height"])

    @property
    def triangle_count(self):
        return int(sum(np.asarray(m["indices"]).reshape(-1, 3).shape[0] for m in self.meshes))

    # ---- Validation ----

    def validate(self):
        """Check the whole scene and normalise it in place (array dtypes, defaults, floats).
        Raises ValueError naming the offending element. Returns self."""
        self.film = validate_film(self.film)
        self.camera = validate_camera(self.camera)
        self.world = validate_world(self.world)
        if not isinstance(self.textures, list):
            self.textures = list(self.textures)
        self.textures = [validate_texture(t, i) for i, t in enumerate(self.textures)]
        if not isinstance(self.materials, list):
            self.materials = list(self.materials)
        self.grids = [validate_grid(g, i) for i, g in enumerate(getattr(self, "grids", []))]
        if sum(g["voxels"].size for g in self.grids) > MAX_GRID_VOXELS:
            raise ValueError(f"grids: more than {MAX_GRID_VOXELS} voxels together")
        self.materials = [validate_material(m, i, len(self.textures))
                          for i, m in enumerate(self.materials)]
        for i, m in enumerate(self.materials):
            validate_density_grid(m, m, f"material {i} ({m['name']!r})", len(self.grids))
            for leaf, _ in m.get("mix", ()):
                if leaf >= len(self.materials) or self.materials[leaf]["type"] == "mix":
                    raise ValueError(f"material {i} ({m['name']!r}) mix: leaf {leaf} is not a "
                                     f"material of the scene, or is itself a mix")
        if not isinstance(self.meshes, list):
            self.meshes = list(self.meshes)
        for i, mesh in enumerate(self.meshes):
            validate_mesh(mesh, i, num_materials=len(self.materials))
        if not isinstance(self.lights, list):
            self.lights = list(self.lights)
        self.lights = [validate_light(light, i) for i, light in enumerate(self.lights)]
        from .curves_schema import validate_curves
        self.curves = [validate_curves(c, i, len(self.materials))
                       for i, c in enumerate(self.curves)]
        return self


    # ---- Native hand-off ----

    def to_native(self):
        """The dict `_core.Session` takes: validated fields, C-contiguous numpy arrays,
        `None` for absent optional arrays, 4x4 matrices as float32 (4, 4) arrays."""
        self.validate()

        def mat(m):
            return np.ascontiguousarray(np.asarray(m, dtype=np.float32))

        camera = dict(self.camera)
        camera["to_world"] = mat(camera["to_world"])

        def steps(m):  # motion blur: (S, 4, 4) -> float32 (S, 16)
            return np.ascontiguousarray(np.asarray(m, dtype=np.float32).reshape(-1, 16))

        if camera.get("motion") is not None:
            camera["motion"] = steps(camera["motion"])
        lights = []
        for light in self.lights:
            light = dict(light)
            if "to_world" in light:
                light["to_world"] = mat(light["to_world"])
            for key in ("receivers", "blockers"):  # light / shadow linking: sets or a mask
                if key in light:
                    light[key] = receiver_mask(light[key], f"light {key}")
            lights.append(light)
        if self.world.get("sun") is not None:   # the sky's sun disc joins the lights, as the
            # world's own: the camera sees it where it sees the world, and the world's ray
            # visibility (pt) applies to it (LightInput::of_world, native/src/scene/scene.h)
            lights.append(dict(self.world["sun"], of_world=True))
        meshes = [dict(m) for m in self.meshes]
        for m in meshes:
            for key in ("receivers", "blockers"):
                if key in m:
                    m[key] = receiver_mask(m[key], f"mesh {key}")
            if m.get("deform") is not None:  # deformation blur: (S, N, 3) -> (S * N, 3)
                m["deform"] = np.ascontiguousarray(np.asarray(m["deform"], np.float32)
                                                   .reshape(-1, 3))
            else:
                m.pop("deform", None)
            if m.get("motion") is not None:
                m["motion"] = steps(m["motion"])
                m["motion_base"] = mat(m["motion_base"])
            else:
                m.pop("motion", None)
                m.pop("motion_base", None)
        textures = []
        for t in self.textures:
            t = dict(t)
            t["uv_transform"] = [float(x) for row in t["uv_transform"] for x in row]
            textures.append(t)
        materials = [dict(m) for m in self.materials]
        arrays, spans = flatten_programs(materials)
        for m, (first, count) in zip(materials, spans):
            if m.pop("programs", None):
                m["program_first"], m["program_count"] = first, count
        channels = len(self.attribute_channels)
        extra = {}   # only scenes with node graphs carry them (docs/scene_format.md)
        if len(arrays[0]) or channels:
            extra["node_programs"] = {"programs": arrays[0], "code": arrays[1],
                                      "consts": arrays[2], "attribute_channels": channels}
        for m in meshes:
            if channels == 0:
                m.pop("attributes", None)
            elif m.get("attributes") is None or m["attributes"].shape[1] != 3 * channels:
                nv = len(m["positions"])
                m["attributes"] = np.zeros((nv, 3 * channels), np.float32)
        if self.curves:  # strands (docs/curves.md): only scenes with them carry the key
            extra["curves"] = [dict(c) for c in self.curves]
            for c in extra["curves"]:  # motion steps: (S, P, 3) -> (S * P, 3), (S, P) -> (S * P,)
                if c.get("deform") is not None:
                    c["deform"] = np.ascontiguousarray(c["deform"].reshape(-1, 3))
                if c.get("deform_radius") is not None:
                    c["deform_radius"] = np.ascontiguousarray(c["deform_radius"].reshape(-1))
                if c.get("motion") is not None:  # its object's steps: (S, 4, 4) -> (S, 16)
                    c["motion"] = steps(c["motion"])
                    c["motion_base"] = mat(c["motion_base"])
        if self.grids:   # Volume objects (docs/volumes.md)
            extra["grids"] = [dict(g) for g in self.grids]
        return {
            **extra,
            "film": dict(self.film),
            "camera": camera,
            "world": _world_native(self.world),
            "materials": materials,
            "textures": textures,
            "meshes": meshes,
            "lights": lights,
        }

    # ---- The .lantern file ----

    def save(self, path):
        """Write a `.lantern` file: a deflate zip of scene.json and one .npy per array."""
        from . import __version__

        self.validate()
        doc = {
            "format": FORMAT_NAME,
            "version": FORMAT_VERSION,
            "generator": f"lantern {__version__}",
            "film": self.film,
            "camera": self.camera,
            "world": {k: v for k, v in self.world.items() if k != "map"},
            "materials": self.materials,
            "lights": self.lights,
            "meshes": [],
            "textures": [],
            "attribute_channels": list(self.attribute_channels),
        }
        arrays = {}
        if self.curves:
            from .curves_schema import save_curves
            doc["curves"] = save_curves(self.curves, arrays)
        if self.world.get("map") is not None:
            doc["world"]["map"] = "world/map.npy"
            arrays["world/map.npy"] = self.world["map"]
        if self.grids:
            doc["grids"] = []
            for i, g in enumerate(self.grids):
                member = f"grids/{i}/voxels.npy"
                arrays[member] = g["voxels"]
                entry = {"name": g["name"], "voxels": member,
                         "index_to_world": g["index_to_world"].tolist()}
                if g["voxels"].ndim == 4:  # a colour grid (nz, ny, nx, 3)
                    entry["channels"] = 3
                doc["grids"].append(entry)
        for i, tex in enumerate(self.textures):
            member = f"textures/{i}/pixels.npy"
            arrays[member] = tex["pixels"]
            doc["textures"].append(dict(tex, pixels=member))
        for i, mesh in enumerate(self.meshes):
            entry = {}
            for key, value in mesh.items():
                if key in MESH_ARRAYS:
                    if value is None:
                        entry[key] = None
                    else:
                        member = f"meshes/{i}/{key}.npy"
                        arrays[member] = value
                        entry[key] = member
                else:
                    entry[key] = value
            doc["meshes"].append(entry)
        path = Path(path)
        tmp = path.with_name(path.name + ".tmp")
        with zipfile.ZipFile(tmp, "w", compression=zipfile.ZIP_DEFLATED) as zf:
            zf.writestr(fixed_time_member("scene.json"), json.dumps(doc, indent=1, allow_nan=False))
            for member, arr in arrays.items():
                buf = io.BytesIO()
                np.save(buf, arr, allow_pickle=False)
                zf.writestr(fixed_time_member(member), buf.getvalue())
        tmp.replace(path)

    def summary(self):
        """One dict of counts for `python -m lantern info`."""
        light_types = {}
        for light in self.lights:
            light_types[light["type"]] = light_types.get(light["type"], 0) + 1
        emissive = sum(1 for m in self.materials if max(m.get("emission", [0])) > 0)
        return {
            "resolution": f"{self.film['width']}x{self.film['height']}",
            "camera": self.camera["type"],
            "meshes": len(self.meshes),
            "triangles": self.triangle_count,
            "vertices": int(sum(np.asarray(m["positions"]).shape[0] for m in self.meshes)),
            "materials": len(self.materials),
            "textures": len(self.textures),
            "emissive_materials": emissive,
            "lights": len(self.lights),
            "light_types": light_types,
            "world_color": self.world["color"],
        }

    def __repr__(self):
        return (f"<lantern.Scene {self.film['width']}x{self.film['height']}, "
                f"{len(self.meshes)} meshes, {self.triangle_count} triangles, "
                f"{len(self.materials)} materials, {len(self.lights)} lights>")


def _world_native(world):
    """The world as the core reads it: the map's 3x3 as 9 floats; its sun is a light."""
    out = dict(world)
    out.pop("sun", None)
    if out.get("to_map") is not None:
        out["to_map"] = [float(x) for row in out["to_map"] for x in row]
    return out


def _parse_major(version):
    if isinstance(version, bool):
        raise ValueError(f"bad version {version!r}")
    if isinstance(version, int):
        return version
    if isinstance(version, str):
        return int(version.split(".")[0])
    raise ValueError(f"bad version {version!r}")


def load_scene(path, max_bytes=None):
    """Read a `.lantern` file written by `Scene.save` (or the add-on's exporter).

    Nothing is read before it is checked: each member's declared size against the file's
    load budget (scene_file.load_budget; `max_bytes` overrides it), scene.json's size, nesting
    and strings, each `.npy` header's dtype and shape against the field and its data size
    against the member. Any failure raises `SceneError` (a ValueError) naming the file, the
    member and what was expected; a missing file raises FileNotFoundError."""
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(f"scene file not found: {path}")
    if not path.is_file():
        raise SceneError(path, None, "is not a file; expected a Lantern scene file")
    try:
        with open(path, "rb"):
            pass
    except OSError as e:
        raise SceneError(path, None, f"cannot be read ({e.strerror or e}); expected a "
                         "readable Lantern scene file") from None
    if not zipfile.is_zipfile(path):
        raise SceneError(path, None, "not a Lantern scene file (not a zip archive, or cut "
                         "short); expected a zip of scene.json and .npy arrays")
    with SceneArchive(path, max_bytes) as archive:
        if "scene.json" not in archive.names():
            raise SceneError(path, None, "not a Lantern scene file (no scene.json inside)")
        doc = archive.read_json("scene.json")
        if not isinstance(doc, dict) or doc.get("format") != FORMAT_NAME:
            fmt = doc.get("format") if isinstance(doc, dict) else None
            raise archive.error("scene.json", f"not a Lantern scene file (format {fmt!r}, "
                                f"expected {FORMAT_NAME!r})")
        try:
            major = _parse_major(doc.get("version"))
        except ValueError:
            raise archive.error("scene.json", f"bad scene file version "
                                f"{doc.get('version')!r}, expected {FORMAT_VERSION}") from None
        if major > FORMAT_VERSION:
            raise archive.error("scene.json", f"scene file version {doc.get('version')} is "
                                f"newer than this Lantern reads (version {FORMAT_VERSION}); "
                                f"update Lantern to open it")
        scene = Scene()
        try:
            scene.film = validate_film(doc.get("film", default_film()))
            scene.camera = validate_camera(doc.get("camera", default_camera()))
            world = doc.get("world", default_world())
            if isinstance(world, dict) and world.get("map") is not None:
                what = "world map"
                member = member_name(archive, world, "map", what)
                kinds, ndim, last = ARRAY_SPECS["map"]
                world = dict(world, map=archive.read_array(member, what, kinds, ndim, last))
            scene.world = validate_world(world)
            scene.materials = entries(archive, doc, "materials")
            scene.lights = entries(archive, doc, "lights")
            textures = entries(archive, doc, "textures")
            meshes = entries(archive, doc, "meshes")
            scene.materials = [validate_material(m, i, len(textures))
                               for i, m in enumerate(scene.materials)]
            scene.lights = [validate_light(light, i) for i, light in enumerate(scene.lights)]
            channels = doc.get("attribute_channels", [])
            if not isinstance(channels, list) or not all(isinstance(c, str) for c in channels):
                raise ValueError("attribute_channels: expected a list of names (strings)")
            scene.attribute_channels = list(channels)
        except SceneError:
            raise
        except ValueError as e:
            raise archive.error("scene.json", str(e)) from None
        scene.textures = []
        for i, entry in enumerate(textures):
            if not isinstance(entry, dict):
                raise archive.error("scene.json", f"texture {i}: expected an object, got "
                                    f"{type(entry).__name__}")
            what = f"texture {i} pixels"
            member = member_name(archive, entry, "pixels", what)
            kinds, ndim, last = ARRAY_SPECS["pixels"]
            px = archive.read_array(member, what, kinds, ndim, last)
            try:
                scene.textures.append(validate_texture(dict(entry, pixels=px), i))
            except ValueError as e:
                raise archive.error(member if "pixels" in str(e) else "scene.json",
                                    str(e)) from None
        scene.grids = []
        for i, entry in enumerate(entries(archive, doc, "grids")):
            if not isinstance(entry, dict):
                raise archive.error("scene.json", f"grid {i}: expected an object")
            what = f"grid {i} voxels"
            member = member_name(archive, entry, "voxels", what)
            color = entry.get("channels", 1) == 3
            vox = archive.read_array(member, what, "f", 4 if color else 3,
                                     (3,) if color else None)
            try:
                scene.grids.append(validate_grid(
                    {k: v for k, v in dict(entry, voxels=vox).items() if k != "channels"}, i))
            except ValueError as e:
                raise archive.error(member, str(e)) from None
        scene.meshes = []
        for i, entry in enumerate(meshes):
            if not isinstance(entry, dict):
                raise archive.error("scene.json", f"mesh {i}: expected an object, got "
                                    f"{type(entry).__name__}")
            scene.meshes.append(read_mesh(archive, entry, i, len(scene.materials)))
        from .curves_schema import read_curves
        scene.curves = [read_curves(archive, entry, i, len(scene.materials), member_name)
                        for i, entry in enumerate(entries(archive, doc, "curves"))]
        try:
            return scene.validate()
        except ValueError as e:  # what crosses elements: mix leaves
            raise archive.error("scene.json", str(e)) from None
