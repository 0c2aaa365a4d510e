"""Render-farm sample chunks: the header metadata a chunk carries and the sample-weighted merge
(`python -m lantern merge a.exr b.exr ... -o out.exr`).

A chunk is a render of the whole frame with its own seed (`chunk_seed(seed, k)`: chunk 0 is
the plain render), so chunks hold independent samples and their spp-weighted mean is a render
with the summed samples. Each EXR records its samples, seed, chunk and a scene identity (a hash
of everything the render saw, `scene_identity`) in its header; merging refuses files of other
resolutions, channels or scenes, files without a sample count and repeated chunks (the same
samples twice). Every channel is merged, so Blender's multilayer EXRs keep their passes;
index and Cryptomatte passes are ids, not means: they are taken from the first file."""

import hashlib
import sys
from pathlib import Path

import numpy as np

from . import exr

SPP = "lantern.spp"
SCENE = "lantern.scene"
SEED = "lantern.seed"
CHUNK = "lantern.chunk"
INTEGRATOR = "lantern.integrator"
_GOLDEN = 0x9E3779B97F4A7C15
# passes whose pixels are ids (Cycles' names): never averaged
_ID_PASSES = ("IndexOB", "IndexMA", "Crypto")


class MergeError(ValueError):
    """Files that cannot be merged, with the reason in words."""


def chunk_seed(seed, chunk):
    """The seed of sample chunk `chunk` of a render with `seed`: chunk 0 keeps the seed, the
    others are spread over 64 bits (the core hashes the seed into every path's stream)."""
    if chunk < 0:
        raise ValueError(f"chunk must be >= 0, got {chunk}")
    return (int(seed) + int(chunk) * _GOLDEN) % 2**64


def _feed(h, value):
    if isinstance(value, np.ndarray) and value.size > 64:
        a = np.ascontiguousarray(value)
        h.update(f"nd{a.dtype.str}{a.shape}".encode())
        h.update(memoryview(a).cast("B"))
    elif isinstance(value, np.ndarray):
        _feed(h, value.tolist())
    elif isinstance(value, dict):
        h.update(b"{")
        for k in sorted(value):
            h.update(repr(k).encode())
            _feed(h, value[k])
        h.update(b"}")
    elif isinstance(value, (list, tuple)):
        h.update(b"[")
        for v in value:
            _feed(h, v)
        h.update(b"]")
    elif isinstance(value, (bool, np.bool_)):
        h.update(b"T" if value else b"F")
    elif isinstance(value, (int, float, np.integer, np.floating)):
        h.update(repr(float(value)).encode())
    else:
        h.update(repr(value).encode())


def scene_identity(scene, max_depth=None):
    """A hex digest of the scene's film, camera, world, materials, textures, meshes, lights,
    strands, grids and attribute channels (and the path depth, which changes what a render converges to): equal for the same scene
    however it was loaded, different after any edit."""
    h = hashlib.blake2b(digest_size=16)
    for part in ("film", "camera", "world", "materials", "textures", "meshes", "lights"):
        h.update(part.encode())
        _feed(h, getattr(scene, part))
    # strands, Volume objects' grids and the attribute channels' names: fed only where the scene
    # has them, so the identity of a scene without them is what it was before they were added
    for part in ("curves", "grids", "attribute_channels"):
        if getattr(scene, part, None):
            h.update(part.encode())
            _feed(h, getattr(scene, part))
    _feed(h, {"max_depth": max_depth})
    return h.hexdigest()


def chunk_metadata(scene_id, spp, seed, chunk, integrator):
    """The header attributes of a chunk (str for the 64-bit seed)."""
    return {SPP: int(spp), SCENE: str(scene_id), SEED: str(int(seed)), CHUNK: int(chunk),
            INTEGRATOR: str(integrator)}


def _spp(meta, path):
    value = meta.get(SPP)
    try:
        spp = int(value)
    except (TypeError, ValueError):
        raise MergeError(f"{path}: the header records no sample count ('{SPP}'); only EXRs "
                         f"rendered by Lantern (python -m lantern render, or Blender with the "
                         f"Lantern add-on) can be merged") from None
    if spp < 1:
        raise MergeError(f"{path}: the header records {spp} samples")
    return spp


def _chunks(meta):
    """The (seed, chunk) pairs a file holds: one for a chunk, several for a merged file."""
    seeds = str(meta.get(SEED)).split(",")
    chunks = str(meta.get(CHUNK)).split(",")
    if len(chunks) != len(seeds):
        chunks = chunks[:1] * len(seeds)
    return list(zip(seeds, chunks))


def _is_id_pass(name):
    return any(part.startswith(_ID_PASSES) for part in name.split("."))


def _oiio():
    """OpenImageIO, except inside Blender (bpy brings its own OpenImageIO libraries into the
    process): there the built-in codec reads the ZIP EXRs the farm job writes."""
    if "bpy" in sys.modules:
        return None
    from .imageio import _want_oiio
    return _want_oiio(None)


def check_compatible(images, paths):
    """Raise MergeError unless the images are chunks of one frame; returns their samples."""
    if len(images) < 2:
        raise MergeError("merge needs at least two files")
    first, p0 = images[0], paths[0]
    h0, w0 = first.shape
    spps, seen = [], {}
    for img, path in zip(images, paths):
        h, w = img.shape
        if (h, w) != (h0, w0):
            raise MergeError(f"{path} is {w}x{h} but {p0} is {w0}x{h0}: chunks of one frame "
                             f"have one resolution")
        if set(img.channels) != set(first.channels):
            raise MergeError(f"{path} has channels {sorted(img.channels)} but {p0} has "
                             f"{sorted(first.channels)}: chunks of one frame have the same "
                             f"passes")
        spps.append(_spp(img.metadata, path))
        scene = img.metadata.get(SCENE)
        if not scene:
            raise MergeError(f"{path}: the header records no scene identity ('{SCENE}')")
        if scene != first.metadata.get(SCENE):
            raise MergeError(f"{path} and {p0} are renders of different scenes (scene "
                             f"identity {scene} vs {first.metadata.get(SCENE)}): only chunks "
                             f"of one scene and frame can be merged")
        for key in _chunks(img.metadata):
            if key in seen:
                raise MergeError(f"{path} and {seen[key]} hold the same samples (seed "
                                 f"{key[0]}, chunk {key[1]}): render each chunk with its own "
                                 f"--chunk index (or seed)")
            seen[key] = path
    return spps


def merge_images(images, paths):
    """The spp-weighted mean of every channel (ids from the first file) and the merged
    metadata: summed samples, the metadata all files share."""
    spps = check_compatible(images, paths)
    total = float(sum(spps))
    out = {}
    for name in images[0].channels:
        if _is_id_pass(name):
            out[name] = images[0].channels[name]
            continue
        acc = np.zeros(images[0].shape, np.float64)
        for img, spp in zip(images, spps):
            acc += np.asarray(img.channels[name], np.float64) * (spp / total)
        out[name] = acc.astype(np.float32)
    shared = {k: v for k, v in images[0].metadata.items()
              if all(img.metadata.get(k) == v for img in images[1:])}
    shared[SPP] = int(total)
    shared[SEED] = ",".join(str(img.metadata.get(SEED)) for img in images)
    shared[CHUNK] = ",".join(str(img.metadata.get(CHUNK)) for img in images)
    return out, shared


def merge_files(paths, output, half=False):
    """Merge the chunk EXRs `paths` into `output`; returns the merged samples per pixel."""
    paths = [Path(p) for p in paths]
    for p in paths + [Path(output)]:
        if p.suffix.lower() != ".exr":
            raise MergeError(f"{p}: merge reads and writes OpenEXR files (.exr)")
    if Path(output).resolve() in {p.resolve() for p in paths}:
        raise MergeError(f"{output}: the output would overwrite one of the inputs")
    oiio = _oiio()
    images = [exr.read_exr(p, oiio) for p in paths]
    channels, meta = merge_images(images, paths)
    exr.write_exr(output, channels, meta, half=half, oiio=oiio)
    return meta[SPP]
