"""Volume objects' density grids in a Scene (docs/volumes.md): ``scene.grids`` holds dicts
``{"name": str, "voxels": float32 (nz, ny, nx), "index_to_world": (4, 4)}``, a dense block of
voxels (voxel (i, j, k) is ``voxels[k, j, i]``, its centre at index (i, j, k)) and the affine map
from that index space to the world. A material's volume reads one as its density through
``"density_grid"`` (an index into ``scene.grids``): its coefficients are then per unit of the
grid's value. A colour grid (Principled Volume's Color Attribute) has voxels (nz, ny, nx, 3),
read through the material's ``"color_grid"`` with the volume's ``color_scatter``,
``color_absorb`` and ``color_base`` (medium_schema.py). ``read_vdb`` loads a float or vec3 grid
of an OpenVDB file with the core (lantern._core)."""
import math

import numpy as np

# the most voxels of all grids together (the core's kMaxGridVoxels: 1 GiB of floats)
MAX_GRID_VOXELS = 1 << 28


def validate_grid(grid, index):
    """The grid dict, checked and normalised (float32 C-contiguous voxels, float32 matrix)."""
    what = f"grid {index}"
    if not isinstance(grid, dict):
        raise ValueError(f"{what}: expected a dict")
    name = str(grid.get("name", f"grid_{index}"))
    what = f"grid {index} ({name!r})"
    vox = grid.get("voxels")
    if vox is None:
        raise ValueError(f"{what}: missing voxels (a float32 (nz, ny, nx) array)")
    vox = np.ascontiguousarray(np.asarray(vox, dtype=np.float32))
    if not (vox.ndim == 3 or (vox.ndim == 4 and vox.shape[3] == 3)):
        raise ValueError(f"{what} voxels: expected 3 dimensions (nz, ny, nx), or (nz, ny, nx, 3) "
                         f"for a colour grid, got {vox.shape}")
    if vox.size > MAX_GRID_VOXELS:
        raise ValueError(f"{what}: {vox.size} voxels, above the limit of {MAX_GRID_VOXELS}")
    m = np.asarray(grid.get("index_to_world", np.eye(4)), dtype=np.float64)
    if m.shape != (4, 4) or not np.all(np.isfinite(m)):
        raise ValueError(f"{what} index_to_world: expected a finite 4x4 matrix")
    if not np.allclose(m[3], [0.0, 0.0, 0.0, 1.0]):
        raise ValueError(f"{what} index_to_world: expected an affine matrix (last row 0 0 0 1)")
    return {"name": name, "voxels": vox,
            "index_to_world": np.ascontiguousarray(m.astype(np.float32))}


def validate_density_grid(material, out, what, num_grids):
    """A material's "density_grid" into out (validate_material's dict)."""
    g = material.get("density_grid")
    if g is None:
        out.pop("density_grid", None)
        if any(material.get(k) is not None for k in ("temperature_grid", "flame_grid",
                                                      "color_grid")):
            raise ValueError(f"{what}: temperature_grid, flame_grid and color_grid need a "
                             "density_grid")
        return
    if isinstance(g, bool) or not isinstance(g, (int, np.integer)) or g < 0:
        raise ValueError(f"{what} density_grid: expected a grid index >= 0, got {g!r}")
    if num_grids is not None and g >= num_grids:
        raise ValueError(f"{what} density_grid: grid {g} out of range (the scene has "
                         f"{num_grids} grids)")
    if material.get("volume") is None:
        raise ValueError(f"{what} density_grid: the material has no volume to scale")
    out["density_grid"] = int(g)
    # a fire's grids (scene/medium_fire.h): read with the volume's blackbody and flame values
    # and its colour grid (scene/medium_grid.h: grid_color), read with its colour coefficients
    for key in ("temperature_grid", "flame_grid", "color_grid"):
        k = material.get(key)
        if k is None:
            out.pop(key, None)
            continue
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or k < 0 or \
                (num_grids is not None and k >= num_grids):
            raise ValueError(f"{what} {key}: expected a grid index of the scene, got {k!r}")
        out[key] = int(k)


def read_vdb(path, grid="density", max_voxels=MAX_GRID_VOXELS):
    """(voxels float32 (nz, ny, nx), index_to_object float64 (4, 4), background) of the float
    grid named `grid` in the OpenVDB file at `path`, read by the core (a vec3 grid: voxels
    (nz, ny, nx, 3), `max_voxels` counting floats, 3 per voxel); the index map is the
    block's (its voxel (0, 0, 0) is the first active voxel's corner of the grid's bounds).
    Raises RuntimeError with the reason (built without OpenVDB, no such file or grid, a grid
    over `max_voxels` as a dense block, checked from the file's metadata first)."""
    from . import _core
    if not _core.vdb_available():
        raise RuntimeError(f"'{path}': Lantern was built without OpenVDB; Volume objects "
                           "(OpenVDB files) are not rendered")
    voxels, m, background = _core.vdb_read(str(path), str(grid), int(max_voxels))
    return voxels, m, float(background) if math.isfinite(background) else 0.0


def vdb_available():
    from . import _core
    return bool(getattr(_core, "vdb_available", lambda: False)())
