"""Volume objects (OpenVDB) -> a density grid and the box that bounds it (docs/volumes.md).

A Volume object's material Volume output converts as a mesh's (export/volume.py), its
coefficients per unit of a float grid of the object's file: Principled Volume's "Density
Attribute" (default "density") times its Density, or an Attribute node naming a grid on the
Density of Volume Scatter / Volume Absorption / Principled Volume. The core reads the grid with
OpenVDB (lantern.read_vdb: its memory checked from the file's metadata first) into a dense
block; the block's index map times the object's matrix places it (scene.grids); a box over the
block's trilinear support (one voxel beyond the outer voxel centres) with a volume-only
material bounds the medium. No material: Blender's default, Principled Volume. What is not
rendered (other grids: temperature, flame, colour; velocity; generated grids without a file)
warns by name."""

import numpy as np

from .volume import _output, convert_volume

# Principled Volume's defaults (bpy 5.0.1), for a Volume object without a material
_DEFAULT_MEDIUM = {"sigma_a": [0.0, 0.0, 0.0], "sigma_s": [0.5, 0.5, 0.5],
                   "emission": [0.0, 0.0, 0.0], "g": 0.0}


class _GridProbe:
    """Stands in for material_compile's GraphCompiler in convert_volume: a Density driven by an
    Attribute node names a grid (the coefficients are then per unit of it); any other graph
    returns None (convert_volume then warns by name and uses the socket's value)."""

    def __init__(self):
        self.grid = None

    def program(self, socket, target, dim):
        from .volume import _source
        node = _source(socket)
        if node is not None and node.type == "ATTRIBUTE" and \
                getattr(node, "attribute_type", "GEOMETRY") == "GEOMETRY" and \
                socket.links[0].from_socket.identifier in ("Fac", "Color"):
            self.grid = node.attribute_name
            return {"grid": self.grid}
        return None


def _box(index_to_world, dims):
    """positions (8, 3) and indices (12, 3) of the block's trilinear support [-1, n] per axis
    mapped to the world, faces outward (also under a mirroring matrix)."""
    nx, ny, nz = dims
    lo, hi = [-1.0, -1.0, -1.0], [float(nx), float(ny), float(nz)]
    corners = np.array([[hi[0] if c & 1 else lo[0], hi[1] if c & 2 else lo[1],
                         hi[2] if c & 4 else lo[2], 1.0] for c in range(8)])
    pos = (corners @ np.asarray(index_to_world, np.float64).T)[:, :3]
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    tris = []
    for a, b, c, d in quads:
        tris += [(a, b, c), (a, c, d)]
    tris = np.array(tris, np.uint32)
    if np.linalg.det(np.asarray(index_to_world, np.float64)[:3, :3]) < 0.0:
        tris = tris[:, ::-1].copy()
    return pos.astype(np.float32), np.ascontiguousarray(tris)


class VolumeObjects:
    """Converts Volume objects: convert() gives an object's (grid, box mesh, material) dicts,
    export() appends them to a scene (final renders: export/__init__.py; the viewport keeps
    them per instance, export/sync.py). Grids are read once per (file, grid) per instance of
    this class."""

    def __init__(self, report, lantern):
        self.report = report
        self.lantern = lantern
        self._read = {}

    def _medium(self, obj):
        """(medium dict per unit of the grid, grid name, material name) or None (warned)."""
        mat = obj.material_slots[0].material if len(obj.material_slots) else None
        if mat is None:
            return dict(_DEFAULT_MEDIUM), "density", "Principled Volume (default)"
        where = f"Object '{obj.name}' (material '{mat.name}')"
        tree = getattr(mat, "node_tree", None)
        output = _output(tree, "OUTPUT_MATERIAL") if tree is not None else None
        if output is None or output.inputs.get("Volume") is None:
            return None
        probe, programs = _GridProbe(), []
        medium = convert_volume(output.inputs["Volume"], where, self.report, probe, programs)
        if medium is None:
            return None
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
        for node, _ in _leaves_of(output):
            for name in ("Color Attribute", "Temperature Attribute"):
                sock = node.inputs.get(name)
                if sock is not None and str(sock.default_value) and \
                        str(sock.default_value) in _grid_names(obj):
                    self.report.warn(f"{where}: the grid '{sock.default_value}' ({name}) is "
                                     "not rendered yet (the socket's own value is used)")
        return medium, grid, mat.name

    def export(self, inst, scene, materials):
        """Appends the object's grid, box mesh and material to scene (the material to the
        list `materials`, which becomes scene.materials); False when not rendered (warned)."""
        got = self.convert(inst)
        if got is None:
            return False
        grid, mesh, mat = got
        mat["density_grid"] = scene.add_grid(grid["voxels"], grid["index_to_world"],
                                              name=grid["name"])
        materials.append(mat)
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
        medium, grid, mat_name = got
        key = (path, grid)
        if key not in self._read:
            try:
                self._read[key] = self.lantern.read_vdb(path, grid)
            except (RuntimeError, ValueError, OSError) as e:
                self._read[key] = e
        got = self._read[key]
        if isinstance(got, Exception):
            warn(f"Object '{obj.name}': its volume is not rendered: {got}")
            return None
        voxels, index_to_object, background = got
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
        nz, ny, nx = voxels.shape
        positions, indices = _box(to_world, (nx, ny, nz))
        g = {"name": f"{obj.name}:{grid}", "voxels": voxels, "index_to_world": to_world}
        m = {"name": f"{mat_name} ({obj.name})", "type": "diffuse", "volume": medium,
             "volume_only": True}
        return g, {"name": obj.name, "positions": positions, "indices": indices}, m


def _object_space(medium, vol, matrix_world):
    """The medium as Cycles scales it for the Volume's Render Space "Object" (Blender's
    default: the opacity stays when the object is scaled): absorption and scattering divided by
    the length of the object's matrix applied to the unit diagonal (Cycles'
    object_volume_density, measured: without it a volume scaled (1.3, 1.1, 1.2) rendered 7 %
    darker than Cycles); emission is not scaled (Cycles scales the density only)."""
    render = getattr(vol, "render", None)
    if getattr(render, "space", "OBJECT") != "OBJECT":
        return medium
    m = np.array(matrix_world, np.float64)[:3, :3]
    k = float(np.linalg.norm(m @ (np.ones(3) / np.sqrt(3.0))))
    if not k > 0.0:
        return medium
    out = dict(medium)
    for key in ("sigma_a", "sigma_s"):
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
