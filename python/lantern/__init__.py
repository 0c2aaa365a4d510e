"""Lantern: a bidirectional path tracer for Blender.

The pure-Python parts (scene container and file, image I/O, metrics) work without the native
module; `Session` and `render` need `lantern._core`, built from the repository root with
`pip install --no-build-isolation --no-deps .`."""

from .scene import Scene, load_scene
from .scene_file import SceneError
from .grid_schema import read_vdb, vdb_available
from .session import Session, render, native_available, native_error, cuda_info

__version__ = "0.1.0"

__all__ = [
    "Scene",
    "load_scene",
    "SceneError",
    "read_vdb",
    "vdb_available",
    "Session",
    "render",
    "native_available",
    "native_error",
    "cuda_info",
    "__version__",
]
