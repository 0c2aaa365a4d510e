"""Volume objects (OpenVDB) -> a density grid and the box that bounds it (docs/volumes.md).

A Volume object's material Volume output converts as a mesh's (export/volume.py), its
coefficients per unit of a float grid of the object's file: Principled Volume's "Density
Attribute" (default "density") times its Density, or an Attribute node naming a grid on the
Density of Volume Scatter / Volume Absorption / Principled Volume. The core reads the grid with
OpenVDB (lantern.read_vdb: its memory checked from the file's metadata first) into a dense
block; the block's index map times the object's matrix places it (scene.grids); a box over the
block's trilinear support (one voxel beyond the outer voxel centres) with a volume-only
material bounds the medium. No material: Blender's default, Principled Volume.
Fire (native/src/scene/medium_fire.h): Principled Volume's Temperature Attribute names a
temperature grid (blackbody per point, T = the Temperature socket x the grid, as Cycles), and
an Attribute node naming a grid on Emission Strength (Principled Volume) or Strength (Emission),
alone or times a constant through a Math Multiply node, a flame grid (emission per point); each
read as a grid of its own; Principled Volume's Color Attribute names a colour grid (a vec3
grid: Color x its colour per point, as Cycles). What is not rendered (velocity, generated grids
without a file) warns by name; a grid the material names that the file lacks warns and the
socket's value stands for it, as in Cycles."""

import numpy as np

from .volume import _output, convert_volume
from .volume_blocks import (_box, _color_attribute, _color_attribute_grid, _color_dropped,
                            _cover, _texture_space, _times_grid)

# Principled Volume's defaults (bpy 5.0.1), for a Volume object without a material
_DEFAULT_MEDIUM = {"sigma_a": [0.0, 0.0, 0.0], "sigma_s": [0.5, 0.5, 0.5],
                   "emission": [0.0, 0.0, 0.0], "g": 0.0}


class _GridProbe:
    """Stands in for material_compile's GraphCompiler in convert_volume: a Density driven by an
    Attribute node names a grid (the coefficients are then per unit of it); any other graph
    returns None (convert_volume then warns by name and uses the socket's value)."""

    def __init__(self, where, report, material=None, attributes=None):
        self.grid, self.attributes = None, attributes  # the scene's table (Generated, Object)
        self.flame = None     # (grid name, rgb radiance per metre per unit of it)
        self.where, self.report, self.material = where, report, material
        self.grids = None     # a graph's grids (_GridTable), with its "density" program
        self.table = _GridTable()   # the grids every program of this material reads
        self.emission_program = None  # a graph on Emission Strength ("volume_emission")
        self.file_grids, self.color_times = set(), None   # a Color graph x its grid's node

    def program(self, socket, target, dim):
        from .volume import _source
        node = _source(socket)
        if target == "density" and node is not None and node.type == "ATTRIBUTE" and \
                getattr(node, "attribute_type", "GEOMETRY") == "GEOMETRY" and \
                socket.links[0].from_socket.identifier in ("Fac", "Color"):
            self.grid = node.attribute_name
            return {"grid": self.grid}
        if self.material is None or \
                target not in ("density", "volume_color", "volume_emission_color",
                                   "volume_absorption_color"):
            return None
        if target != "density":
            # a graph on a Color or Emission Color: a program of the object's grids, a
            # Principled Volume's Color times its Color Attribute grid (kOpGrid's colour) where
            # the file has it, as Cycles multiplies them (_color then leaves the grid alone)
            own = _color_attribute_grid(socket.node, self.file_grids) \
                if target == "volume_color" else None
            prog = _GridCompiler(self.material, self.report, self.table).program(
                socket, target, dim, post=_times_grid(own) if own else None)
            if prog is not None and own:
                self.color_times = socket.node
            return prog
        # any other graph: a program reading the object's grids (kOpGrid), times Principled
        # Volume's Density Attribute grid where the shader has one (Cycles multiplies by it)
        comp = _GridCompiler(self.material, self.report, self.table, self.attributes)
        shader = socket.node
        attr = shader.inputs.get("Density Attribute") \
            if shader.type == "PRINCIPLED_VOLUME" else None
        attr = str(attr.default_value) if attr is not None else ""
        post = None
        if attr:
            def post(ctx, v):
                from .node_handlers import grid_register
                g = ctx.reg(grid_register(ctx, attr) + 3, 1, "VALUE")
                r, _ = ctx.emit_node("math", [v, g, ctx.const((0.0,), "VALUE")], 1, mode=2)
                return ctx.reg(r, 1, "VALUE")
        prog = comp.program(socket, target, dim, post=post)
        if prog is None:
            return None
        self.grids = comp.grids
        self.grid = attr or (comp.grids.names[0] if comp.grids.names else None)
        if self.grid is None:
            self.report.warn(f"{self.where}: the node graph on '{socket.name}' reads no grid of "
                             "the object; not rendered")
            return None
        return prog

    def grid_strength(self, node, sock, weight):
        """True when `sock` is an emission strength that a grid drives (an Attribute node, or
        one times a constant by a Math Multiply node): kept as the flame grid."""
        from .volume import _source, _value
        if _color_attribute(node) is not None and sock.name == "Color":
            return True  # a colour grid on the Color (volume_objects._color converts it)
        names = {"PRINCIPLED_VOLUME": ("Emission Strength", "Emission Color"),
                 "EMISSION": ("Strength", "Color")}.get(node.type)
        if names is None or sock.name != names[0] or not sock.is_linked:
            return False
        src, scale = _source(sock), 1.0
        if src is not None and src.type == "MATH" and src.operation == "MULTIPLY":
            a, b = src.inputs[0], src.inputs[1]
            attr = a if _source(a) is not None else b
            other = b if attr is a else a
            if _source(other) is not None:
                return False
            scale, src = float(other.default_value), _source(attr)
        if src is None or src.type != "ATTRIBUTE" or \
                getattr(src, "attribute_type", "GEOMETRY") != "GEOMETRY":
            return self._strength_program(node, sock, weight, names[1])
        name = src.attribute_name
        if self.flame is not None and self.flame[0] != name:
            self.report.warn(f"{self.where}: a second emission grid '{name}' is not rendered "
                             f"(only '{self.flame[0]}')")
            return True
        color = _flame_color(node, names[1], self.where, self.report)
        add = [weight * scale * max(c, 0.0) for c in color]
        old = self.flame[1] if self.flame is not None else [0.0, 0.0, 0.0]
        self.flame = (name, [x + y for x, y in zip(old, add)])
        return True


_COLOR_TARGETS = ("volume_color", "volume_emission_color", "volume_absorption_color")


class _GridTable:
    """The grids a Volume object's graph reads, in order (kOpGrid's aux until export)."""

    def __init__(self):
        self.names = []

    def index_of(self, name):
        name = str(name)
        if name not in self.names:
            self.names.append(name)
        return self.names.index(name)


class _NoChannels:
    """A Volume object has no mesh attributes (colour and generic attributes) and no image
    textures: a graph reading them is not rendered (warned by GraphCompiler.program)."""

    def channel(self, name):
        from .material_compile import Unsupported
        raise Unsupported(f"'{name}' is not read inside a Volume object yet")

    def __getattr__(self, name):
        from .material_compile import Unsupported
        raise Unsupported("textures are not read inside a Volume object yet")


class _VolumeChannels(_NoChannels):
    """Generated and Object coordinates: channels of the scene's attribute table, given per
    vertex of the object's box (_texture_space; the core fits the medium's affine maps)."""

    def __init__(self, attributes):
        self._attributes = attributes

    def channel(self, name):
        if name in ("generated", "object") and self._attributes is not None:
            return self._attributes.channel(name)
        return _NoChannels.channel(self, name)


def _GridCompiler(material, report, table, attributes=None):
    from .material_compile import GraphCompiler
    comp = GraphCompiler(material, report, _NoChannels(), _VolumeChannels(attributes))
    comp.grids = table
    return comp


def _strength_program(self, node, sock, weight, color_name):
    """A graph of the object's grids on an emission strength (Map Range, Math, ColorRamp, ...
    between Attribute nodes and the socket): a "volume_emission" program, its colour factor
    weight x the Emission Color kept as the flame's (a flame grid's place); False where it
    cannot be compiled (warned) or another emission graph or grid is there already."""
    from .volume import _value
    if self.material is None:
        return False
    if self.flame is not None or self.emission_program is not None:
        self.report.warn(f"{self.where}: a second emission graph on '{node.name}' is not "
                         "rendered (one emission grid or graph per volume)")
        return True
    comp = _GridCompiler(self.material, self.report, self.table, self.attributes)
    prog = comp.program(sock, "volume_emission", 1)
    if prog is None:
        return False
    color = _flame_color(node, color_name, self.where, self.report)
    self.emission_program = prog
    self.flame = (None, [weight * max(c, 0.0) for c in color])
    return True


_GridProbe._strength_program = _strength_program


def _flame_color(node, name, where, report):
    """The colour factor of a flame grid or strength graph: the socket's colour, or 1 where a
    node graph drives it (its "volume_emission_color" program multiplies per point)."""
    from .volume import _linked, _value
    if _linked(node, name):
        return [1.0, 1.0, 1.0]
    return _value(node, name, where, report) or [1.0, 1.0, 1.0]


class VolumeObjects:
    """Converts Volume objects: convert() gives an object's (grid, box mesh, material) dicts,
    export() appends them to a scene (final renders: export/__init__.py; the viewport keeps
    them per instance, export/sync.py). Grids are read once per (file, grid) per instance of
    this class."""

    def __init__(self, report, lantern, attributes=None):
        self.report = report
        self.lantern = lantern
        self.attributes = attributes  # the scene's attribute table: Generated, Object
        self._read = {}

    def _medium(self, obj):
        """(medium dict per unit of the grid, grid name, material name) or None (warned)."""
        mat = obj.material_slots[0].material if len(obj.material_slots) else None
        if mat is None:
            return dict(_DEFAULT_MEDIUM), "density", "Principled Volume (default)", {}, None
        where = f"Object '{obj.name}' (material '{mat.name}')"
        tree = getattr(mat, "node_tree", None)
        output = _output(tree, "OUTPUT_MATERIAL") if tree is not None else None
        if output is None or output.inputs.get("Volume") is None:
            return None
        probe, programs = _GridProbe(where, self.report, mat, self.attributes), []
        probe.file_grids = _grid_names(obj)
        medium = convert_volume(output.inputs["Volume"], where, self.report, probe, programs)
        if medium is None and probe.flame is None:
            return None
        if medium is None:  # emission from the flame grid alone
            medium = {"sigma_a": [0.0] * 3, "sigma_s": [0.0] * 3, "emission": [0.0] * 3,
                      "g": 0.0}
        grid = probe.grid if programs else None
        if grid is None:
            # Principled Volume's own attribute (Cycles multiplies its Density by it)
            from .volume import _leaves
            for node, _ in _leaves(output.inputs["Volume"], 1.0, where, self.report):
                sock = node.inputs.get("Density Attribute")
                if node.type == "PRINCIPLED_VOLUME" and sock is not None and \
                        str(sock.default_value):
                    grid = str(sock.default_value)
        if grid is None:
            self.report.warn(f"{where}: its volume reads no grid of the object (no Density "
                             "Attribute, no Attribute node on Density); not rendered")
            return None
        fire = _fire(output, medium, probe, obj, where, self.report)
        color = _color(output, medium, obj, where, self.report, probe.color_times)
        if color is not None:
            fire["color"] = color
        # graphs on Density and Emission Strength: their programs (kOpGrid's aux the place of
        # a grid in grid_names)
        progs = [programs[0]] if probe.grids is not None and programs else []
        if probe.emission_program is not None:
            progs.append(probe.emission_program)
        # graphs on Color and Emission Color (convert_volume's "volume_color",
        # "volume_emission_color", "volume_absorption_color")
        progs += [p for p in programs if p.get("target") in _COLOR_TARGETS]
        program = {"programs": progs, "grid_names": list(probe.table.names)} if progs else None
        return medium, grid, mat.name, fire, program

    def _grid(self, path, name):
        """(voxels, index_to_object, background) of grid `name` of `path`, or the exception
        that reading it raised; read once per (file, grid)."""
        key = (path, name)
        if key not in self._read:
            try:
                self._read[key] = self.lantern.read_vdb(path, name)
            except (RuntimeError, ValueError, OSError) as e:
                self._read[key] = e
        return self._read[key]

    def _program_grids(self, obj, path, layout, program, inst):
        """{name: grid dict} of the grids a density program reads other than the layout
        (density) grid; a grid the file lacks warns by name and reads 0 (Cycles' missing
        attribute)."""
        out = {}
        for name in program["grid_names"]:
            if name == layout:
                continue
            got = self._grid(path, name)
            if isinstance(got, Exception):
                self.report.warn(f"Object '{obj.name}': the grid '{name}' its density's node "
                                 f"graph reads is not rendered ({got}); it reads 0 there")
                continue
            out[name] = {"name": f"{obj.name}:{name}", "voxels": got[0],
                         "index_to_world": np.array(inst.matrix_world, np.float64) @
                         np.asarray(got[1])}
        return out

    def export(self, inst, scene, materials):
        """Appends the object's grid, box mesh and material to scene (the material to the
        list `materials`, which becomes scene.materials); False when not rendered (warned)."""
        got = self.convert(inst)
        if got is None:
            return False
        grid, mesh, mat = got
        materials.append(add_grids(scene, mat, grid))
        mesh["material_ids"] = np.full(len(mesh["indices"]), len(materials) - 1, np.uint32)
        scene.meshes.append(mesh)
        return True

    def convert(self, inst):
        """(grid, mesh, material) dicts of the Volume object instance `inst` (the material's
        density_grid and the mesh's material ids left for the caller), or None (warned)."""
        obj = inst.object
        vol = obj.data
        warn = self.report.warn
        if not self.lantern.vdb_available():
            warn(f"Object '{obj.name}': Volume objects are not rendered (Lantern was built "
                 "without OpenVDB)")
            return None
        path = _file_path(vol)
        if not path:
            warn(f"Object '{obj.name}': a Volume without a file (generated grids) is not "
                 "rendered")
            return None
        got = self._medium(obj)
        if got is None:
            return None
        medium, grid, mat_name, fire, program = got
        got = self._grid(path, grid)
        if isinstance(got, Exception):
            warn(f"Object '{obj.name}': its volume is not rendered: {got}")
            return None
        voxels, index_to_object, background = got
        if voxels.ndim == 4:
            warn(f"Object '{obj.name}': grid '{grid}' is a vec3 (colour) grid; a density needs a "
                 "float grid; its volume is not rendered")
            return None
        if background != 0.0:
            warn(f"Object '{obj.name}': grid '{grid}' has background {background:g}; Lantern "
                 "reads 0 outside its active voxels")
        if voxels.size == 0:
            warn(f"Object '{obj.name}': grid '{grid}' of '{path}' is empty; nothing renders")
            return None
        # voxel centres at the grid's integer indices, as OpenVDB (measured against Cycles:
        # an absorbing grid of random voxels seen from above matched at this placement and
        # differed 5x more with the voxels moved half a voxel either way)
        to_world = np.array(inst.matrix_world, np.float64) @ np.asarray(index_to_object)
        medium = _object_space(medium, vol, inst.matrix_world)
        g = {"name": f"{obj.name}:{grid}", "voxels": voxels, "index_to_world": to_world,
             "fire": {}}
        # the temperature, flame and colour grids, each its own block
        for role, name in fire.items():
            got = self._grid(path, name)
            if not isinstance(got, Exception) and (got[0].ndim == 4) != (role == "color"):
                if role == "color":  # a float grid as a colour: grey (Cycles reads it so)
                    got = (np.repeat(got[0][..., None], 3, axis=3), got[1], got[2])
                else:
                    got = ValueError(f"grid '{name}' is a vec3 (colour) grid; a {role} needs "
                                     "a float grid")
            if isinstance(got, Exception):
                warn(f"Object '{obj.name}': its {role} grid is not rendered: {got}")
                if role == "color":
                    _color_dropped(medium)
                else:
                    medium.pop("flame_emission" if role == "flame" else
                               "blackbody_intensity", None)
                continue
            if got[0].size == 0:
                if role == "color":  # no colour anywhere: reads 0 (Cycles' background)
                    _color_dropped(medium, 0.0)
                continue
            g["fire"][role] = {"name": f"{obj.name}:{name}", "voxels": got[0],
                               "index_to_world": np.array(inst.matrix_world, np.float64) @
                               np.asarray(got[1])}
        m = {"name": f"{mat_name} ({obj.name})", "type": "diffuse", "volume": medium,
             "volume_only": True}
        if program is not None:
            g["layout"] = grid
            g["program_grids"] = self._program_grids(obj, path, grid, program, inst)
            # the medium spans every grid its programs read (Cycles' volume mesh covers the
            # active voxels of each grid the shader reads): the layout block grows, with zeros
            g["voxels"], g["index_to_world"] = _cover(voxels, to_world, g["program_grids"].values(),
                                                      lambda t: warn(f"Object '{obj.name}': {t}"))
            m["programs"] = [{k: v for k, v in p.items() if k != "grid_names"}
                             for p in program["programs"]]
            m["grid_names"] = list(program["grid_names"])
        positions, indices = _box(g["index_to_world"], g["voxels"].shape[::-1])
        mesh = {"name": obj.name, "positions": positions, "indices": indices}
        if self.attributes is not None and self.attributes.names:
            mesh["_attributes"] = _texture_space(inst.matrix_world, positions)
        return g, mesh, m


def add_grids(scene, mat, grid):
    """mat (a converted Volume object's material) with its grids appended to scene.grids:
    density_grid, and temperature_grid / flame_grid where the object has them."""
    out = dict(mat, density_grid=scene.add_grid(grid["voxels"], grid["index_to_world"],
                                                name=grid["name"]))
    for role, g in grid.get("fire", {}).items():
        out[f"{role}_grid"] = scene.add_grid(g["voxels"], g["index_to_world"], name=g["name"])
    names = out.pop("grid_names", None)
    if names is not None and out.get("programs"):
        # the density program's grids: kOpGrid's aux from its place in names to the scene's
        layout = grid.get("layout")
        index = []
        for name in names:
            if name == layout:
                index.append(out["density_grid"])
            elif name in grid.get("program_grids", {}):
                g = grid["program_grids"][name]
                index.append(scene.add_grid(g["voxels"], g["index_to_world"], name=g["name"]))
            else:
                index.append(-1)   # missing: reads 0
        from .node_ops import OP
        progs = []
        for p in out["programs"]:
            code = [list(w) for w in p["code"]]
            for w in code:
                if w[0] & 0xFF == OP["grid"]:
                    w[2] = index[w[2]] & 0xFFFFFFFF
            progs.append(dict(p, code=code))
        out["programs"] = progs
    return out


def _fire(output, medium, probe, obj, where, report):
    """{"temperature": grid, "flame": grid} of the grids the volume's emission reads, with
    medium (its dict) changed to match: a Principled Volume's Blackbody per point (its constant
    part taken out of "emission"), the flame grid's emission per unit. A grid the file lacks
    warns by name and the socket's value stands (Cycles' behaviour: a missing attribute)."""
    from .volume import _CUTOFF, _leaves, _value, blackbody_emission

    class _Quiet:
        def warn(self, message):
            pass
    quiet, names, fire = _Quiet(), _grid_names(obj), {}
    for node, w in _leaves(output.inputs["Volume"], 1.0, where, quiet):
        sock = node.inputs.get("Temperature Attribute")
        if node.type != "PRINCIPLED_VOLUME" or sock is None or not str(sock.default_value):
            continue
        bb = _value(node, "Blackbody Intensity", where, quiet)
        if bb is None or not bb > _CUTOFF:
            continue
        name = str(sock.default_value)
        if name not in names:
            report.warn(f"{where}: the grid '{name}' (Temperature Attribute) is not in the "
                        "object's file; the Temperature socket's value is used everywhere")
            continue
        if "temperature" in fire:
            report.warn(f"{where}: a second Principled Volume's temperature grid is not "
                        "rendered (its Temperature socket's value is used)")
            continue
        const = blackbody_emission(node, where, quiet)
        medium["emission"] = [max(e - w * c, 0.0) for e, c in zip(medium["emission"], const)]
        tint = _value(node, "Blackbody Tint", where, quiet) or [1.0, 1.0, 1.0]
        medium["blackbody_intensity"] = float(bb)
        medium["temperature"] = max(float(_value(node, "Temperature", where, quiet) or 0.0), 0.0)
        medium["blackbody_tint"] = [w * max(float(c), 0.0) for c in tint]
        fire["temperature"] = name
    if probe.flame is not None:
        name, rgb = probe.flame
        if name is None:   # a graph's program (probe.emission_program) scales it per point
            medium["flame_emission"] = rgb
        elif name not in names:
            report.warn(f"{where}: the grid '{name}' on its emission strength is not in the "
                        "object's file; it reads 0 there (no emission), as in Cycles")
            medium.pop("flame_emission", None)   # (an Emission Color graph's factor too)
        else:
            medium["flame_emission"] = rgb
            fire["flame"] = name
    return fire


def _color(output, medium, obj, where, report, times=None):
    """The grid that a Principled Volume's Color Attribute names (Cycles multiplies its Color
    by it), with medium changed to match: that shader's scattering Color x Density taken out of
    "sigma_s" into "color_scatter", its absorption max(1 - Color, 0) x max(1 - sqrt(Absorption
    Color), 0) x Density out of "sigma_a" into "color_absorb" / max(1 - Color, 0) and the Color
    into "color_base" (the core scales them per point: scene/medium_hetero.h); None without."""
    from .volume import _leaves, _linked, _value

    class _Quiet:
        def warn(self, message):
            pass
    quiet, names, found = _Quiet(), _grid_names(obj), None
    for node, w in _leaves(output.inputs["Volume"], 1.0, where, quiet):
        sock = node.inputs.get("Color Attribute")
        own = str(sock.default_value) if node.type == "PRINCIPLED_VOLUME" and sock is not None \
            else ""
        linked = _color_attribute(node)   # an Attribute node on the Color socket
        if own and own not in names:
            own = ""  # Cycles: a missing attribute leaves the Color as it is (smoke caches
            # without colour are common; nothing to say)
        if own and linked is None and _linked(node, "Color"):
            if node == times:   # the Color graph's program multiplies by the grid
                continue
            report.warn(f"{where}: the Color Attribute grid '{own}' of '{node.name}' with a node "
                        "graph on its Color is not rendered (Cycles multiplies the two); the "
                        "graph's colour alone is")
            continue
        if not own and linked is None:
            continue
        name = own or linked
        if found is not None or (own and linked is not None):
            report.warn(f"{where}: a second colour grid '{linked if own else name}' of "
                        f"'{node.name}' is not rendered (only one colour grid per volume)")
            if found is not None:
                continue
        dens = node.inputs.get("Density")
        d = w * (1.0 if dens is not None and dens.is_linked else
                 max(float(_value(node, "Density", where, quiet, quiet=True) or 0.0), 0.0))
        color = [max(float(c), 0.0) for c in (_value(node, "Color", where, quiet) or [1.0] * 3)]
        absorb = _value(node, "Absorption Color", where, quiet) or [0.0] * 3
        a = [max(1.0 - max(float(k), 0.0) ** 0.5, 0.0) for k in absorb] \
            if node.type == "PRINCIPLED_VOLUME" else [1.0] * 3
        scat = 0.0 if node.type == "VOLUME_ABSORPTION" else 1.0
        ab = 0.0 if node.type == "VOLUME_SCATTER" else 1.0
        # the shader's coefficients with the socket's own Color, as convert_volume added them
        medium["sigma_s"] = [max(x - scat * d * c, 0.0) for x, c in zip(medium["sigma_s"], color)]
        medium["sigma_a"] = [max(x - ab * d * max(1.0 - c, 0.0) * k, 0.0)
                             for x, c, k in zip(medium["sigma_a"], color, a)]
        # the grid's colour c stands for the Color (an Attribute node) or multiplies it
        base = color if own else [1.0] * 3
        medium["color_scatter"] = [scat * d * c for c in base]
        medium["color_absorb"] = [ab * d * k for k in a]
        medium["color_base"] = base
        found = name
        if not own and name not in names:
            report.warn(f"{where}: the grid '{name}' on the Color of '{node.name}' is not in "
                        "the object's file; it reads 0 there (black), as in Cycles")
            _color_dropped(medium, 0.0)
            found = None
    return found


def _object_space(medium, vol, matrix_world):
    """The medium as Cycles scales it for the Volume's Render Space "Object" (Blender's
    default: the opacity stays when the object is scaled): absorption and scattering divided by
    the length of the object's matrix applied to the unit diagonal (Cycles'
    object_volume_density, measured: without it a volume scaled (1.3, 1.1, 1.2) rendered 7 %
    darker than Cycles), and the emission too (its constant part, the blackbody and the flame
    grid's: measured with bpy 5.0.1 on a fire scaled (1, 1, 1.3), the flame's emission read
    10.5 % brighter than Cycles' without it and 0.3 % with the object unscaled)."""
    render = getattr(vol, "render", None)
    if getattr(render, "space", "OBJECT") != "OBJECT":
        return medium
    m = np.array(matrix_world, np.float64)[:3, :3]
    k = float(np.linalg.norm(m @ (np.ones(3) / np.sqrt(3.0))))
    if not k > 0.0:
        return medium
    out = dict(medium)
    for key in ("sigma_a", "sigma_s", "emission", "blackbody_tint", "flame_emission",
                "color_scatter", "color_absorb", "absorb_alone"):
        if key in medium:
            out[key] = [v / k for v in medium[key]]
    return out


def _leaves_of(output):
    from .volume import _leaves

    class _Quiet:
        def warn(self, message):
            pass
    return _leaves(output.inputs["Volume"], 1.0, "", _Quiet())


def _grid_names(obj):
    try:
        return {g.name for g in obj.data.grids}
    except (AttributeError, RuntimeError):
        return set()


def _file_path(vol):
    """The file of the current frame (an image sequence's), absolute; '' without one."""
    import bpy
    try:
        frame_path = vol.grids.frame_filepath
    except AttributeError:
        frame_path = ""
    path = frame_path or getattr(vol, "filepath", "")
    if not path:
        return ""
    return bpy.path.abspath(path, library=vol.library)
