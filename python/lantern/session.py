"""`Session` and `render`: the Python face of the native core (`lantern._core`).

Settings are checked here (names, ranges, reserved integrators, backend fallback) before they
reach `_core.Session`; the core gets plain dicts and numpy arrays only.

Backends: a core with `cuda_info()` gets "cuda" and "auto" as asked and chooses itself (falling
back to the CPU with a warning when no GPU is usable); `Session.backend` says which one
rendered. A core without `cuda_info()` has only the CPU: "cuda" and "auto" become "cpu" here.
"auto" takes a GPU only once the GPU self-check passed on it (gpu_selfcheck.py: once per card,
driver and build, in a child process; a scene with subsurface scattering or media only once
those cases passed too); else it renders on the CPU and says why in `warnings`. "cuda" forces
the GPU without the check."""

import importlib
import logging
import os
import threading
import time

import numpy as np

from . import gpu_selfcheck

log = logging.getLogger("lantern")

INTEGRATORS = ("auto", "pt", "bdpt", "lvc", "cis", "lt")  # auto: pt or cis per iteration; lt: a reference
IMPLEMENTED_INTEGRATORS = ("auto", "pt", "bdpt", "lvc", "cis", "lt")
CIS_TARGETS = ("contribution", "bsdf")
BACKENDS = ("cpu", "cuda", "auto")

DEFAULT_SETTINGS = {
    "integrator": "auto",  # pt or cis, whichever the render measures as more efficient
    "backend": "auto",
    "spp_per_iteration": 1,
    "max_depth": 16,
    "seed": 0,
    "threads": 0,
    "rr_depth": 4,          # Russian roulette from this depth (path_state.h); 0: off
    # bidirectional integrators (bdpt, lvc, cis)
    "sort": None,             # sort hits by material type: None = on for cis only
    "connections": 5,         # N: cache vertices per camera vertex (the paper's N = 5)
    "candidates": 10,         # M: cis candidates (the paper's M = 10)
    "light_path_fraction": 1.0,  # lvc, cis: light paths per camera sample (0: none, so no
                                 # light tracing or connections: path tracing; bdpt: 1 only)
    "cis_target": "contribution",  # or "bsdf": the paper's BSDF-product target
    "naive_ris": False,       # tests only: the biased uniform weight for resampled picks
    "naive_map": False,       # tests only: a connection map's counts under uniform-N weights
    "soft_visibility": True,  # tests only: False leaves V(c, x) (in media also the flights'
                              # factor F(c -> x)) out of soft-falloff lights' light-path
                              # densities (biased; soft_light_path.h, soft_light_medium.h)
    "connection_allocation": None,  # per-pixel N, M from the render (pixel_alloc.h): True for
                                    # lvc, cis and auto; None: auto's cis iterations only
    "cache_budget_mb": 0,     # light vertex cache memory per pass (0: min(4 GiB, RAM / 4));
                              # a larger iteration runs as several passes
    "light_candidates": 1,    # pt: resampled next-event estimation over M light samples (1: off)
    # per-pixel adaptive sampling (CPU backend; native/src/integrator/adaptive.h): Cycles'
    # noise threshold (0: off), samples before the first check (0: Cycles' automatic
    # minimum), samples between checks
    "adaptive_threshold": 0.0,
    "adaptive_min_samples": 0,
    "adaptive_step": 4,
    "instancing": False,      # a bottom-level BVH per mesh, so move_instance() builds none
    "auto_keep_pilot": False,  # integrator auto: the pilot in the image, as on the GPU (tests)
    # integrator auto in homogeneous, non-emissive media: its trials choose pt or cis there
    # (off: pt in media, with a warning; docs/auto_integrator.md, "Media")
    "auto_media": True,
    # tests only (lvc, cis, bdpt): each pixel holds integrator auto's moment channels, not RGB
    # (luminance, path tracing's second moment by the MIS identity, light pt cannot sample)
    "moment_channels": False,
}

BUILD_HINT = ("build it from the repository root with "
              "`pip install --no-build-isolation --no-deps .`")

_core = None
_core_error = None
_core_lock = threading.Lock()


def _borrow_installed_core():
    """When this `lantern` (a source checkout on sys.path, say) has no native module but another
    copy on sys.path (the installed one) has, let the package find `_core` there too, as
    tests/python/conftest.py does. True when one was found."""
    import glob
    import os
    import sys
    pkg = sys.modules.get("lantern")
    if pkg is None:
        return False
    here = {os.path.realpath(p) for p in pkg.__path__}
    for entry in sys.path:
        cand = os.path.join(entry or os.getcwd(), "lantern")
        if (os.path.realpath(cand) not in here and glob.glob(os.path.join(cand, "_core*"))):
            pkg.__path__.append(cand)
            return True
    return False


def _load_core():
    """Import `lantern._core` once; remember why it failed so the message can say."""
    global _core, _core_error
    with _core_lock:
        if _core is None and _core_error is None:
            try:
                try:
                    _core = importlib.import_module("lantern._core")
                except ModuleNotFoundError:
                    if not _borrow_installed_core():
                        raise
                    _core = importlib.import_module("lantern._core")
            except Exception as e:  # ImportError, or a broken build raising anything
                _core_error = f"{type(e).__name__}: {e}"
    return _core


def native_available():
    """True when the native module `lantern._core` imports."""
    return _load_core() is not None


def native_error():
    """Why `lantern._core` did not import (None when it did)."""
    _load_core()
    return _core_error


def require_core():
    core = _load_core()
    if core is None:
        raise RuntimeError(f"lantern's native module (lantern._core) is not available "
                           f"({_core_error}); {BUILD_HINT}")
    return core


NO_CUDA_INFO = {"compiled": False, "available": False,
                "reason": "this build of lantern._core has no CUDA backend",
                "name": "", "memory_bytes": 0, "compute_capability": "", "driver_version": 0}


def _native_has_cuda():
    """True when the native module has the CUDA backend's interface (`cuda_info`)."""
    core = _load_core()
    return core is not None and hasattr(core, "cuda_info")


def cuda_info():
    """The native module's `cuda_info()` dict: compiled, available, reason, name,
    memory_bytes, compute_capability. Without the native module or without CUDA in it:
    compiled and available False, with the reason."""
    core = _load_core()
    if core is None:
        return dict(NO_CUDA_INFO, reason=f"lantern._core is not available ({_core_error})")
    if not hasattr(core, "cuda_info"):
        return dict(NO_CUDA_INFO)
    info = dict(NO_CUDA_INFO)
    info.update(dict(core.cuda_info()))
    return info


def backend_unavailable(name):
    """None when backend `name` ("cpu", "cuda") can render here, else the reason why not."""
    if name not in ("cpu", "cuda"):
        return f"unknown backend {name!r} (cpu, cuda)"
    if _load_core() is None:
        return f"lantern._core is not available ({_core_error})"
    if name == "cpu":
        return None
    info = cuda_info()
    if not info.get("compiled"):
        return f"CUDA is not compiled in: {info.get('reason') or 'no reason given'}"
    if not info.get("available"):
        return f"no usable CUDA GPU: {info.get('reason') or 'no reason given'}"
    return None


def _check_int(name, value, lo, hi):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"setting {name!r} must be an integer, got {value!r}")
    value = int(value)
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        rng = f"[{lo}, {hi}]" if hi is not None else f">= {lo}"
        raise ValueError(f"setting {name!r} must be in {rng}, got {value}")
    return value


def _threads_from_env(warnings):
    """`threads` 0 (every core) becomes the environment's LANTERN_THREADS where it is set, as
    OMP_NUM_THREADS sets OpenMP's: a render farm node or a test runner that runs several renders
    side by side gives each its share of the cores (tools/test.sh: one per lane)."""
    raw = os.environ.get("LANTERN_THREADS", "").strip()
    if not raw:
        return 0
    try:
        n = int(raw)
    except ValueError:
        n = -1
    if not 0 <= n <= 4096:
        warnings.append(f"LANTERN_THREADS={raw!r} is not a thread count in [0, 4096]: "
                        "rendering on every core")
        return 0
    return n


def resolve_settings(settings):
    """Full settings dict for the core plus warnings about fallbacks.
    Unknown names -> TypeError; wrong values -> ValueError; reserved integrators ->
    NotImplementedError."""
    unknown = sorted(set(settings) - set(DEFAULT_SETTINGS))
    if unknown:
        raise TypeError(f"unknown setting(s) {', '.join(map(repr, unknown))}; valid settings: "
                        f"{', '.join(sorted(DEFAULT_SETTINGS))}")
    out = dict(DEFAULT_SETTINGS)
    out.update(settings)
    warnings = []

    integrator = out["integrator"]
    if integrator not in INTEGRATORS:
        raise ValueError(f"setting 'integrator' must be one of {INTEGRATORS}, "
                         f"got {integrator!r}")
    if integrator not in IMPLEMENTED_INTEGRATORS:
        raise NotImplementedError(f"integrator {integrator!r} is not implemented yet (reserved "
                                  f"for a later issue); available: {IMPLEMENTED_INTEGRATORS}")

    backend = out["backend"]
    if backend not in BACKENDS:
        raise ValueError(f"setting 'backend' must be one of {BACKENDS}, got {backend!r}")
    if backend in ("cuda", "auto") and not _native_has_cuda():
        if backend == "cuda":
            warnings.append("this build of lantern has no CUDA backend; rendering on the CPU")
        out["backend"] = "cpu"

    out["spp_per_iteration"] = _check_int("spp_per_iteration", out["spp_per_iteration"], 1, 4096)
    out["max_depth"] = _check_int("max_depth", out["max_depth"], 1, 1024)
    out["seed"] = _check_int("seed", out["seed"], 0, 2**64 - 1)
    out["threads"] = _check_int("threads", out["threads"], 0, 4096)
    if out["threads"] == 0:
        out["threads"] = _threads_from_env(warnings)
    out["rr_depth"] = _check_int("rr_depth", out["rr_depth"], 0, 1024)
    out["connections"] = _check_int("connections", out["connections"], 1, 64)
    out["candidates"] = _check_int("candidates", out["candidates"], 1, 64)
    f = out["light_path_fraction"]
    if isinstance(f, bool) or not isinstance(f, (int, float, np.integer, np.floating)) \
            or not 0.0 <= float(f) <= 1.0:
        raise ValueError(f"setting 'light_path_fraction' must be a number in [0, 1], got {f!r}")
    out["light_path_fraction"] = float(f)
    out["cache_budget_mb"] = _check_int("cache_budget_mb", out["cache_budget_mb"], 0, 1 << 30)
    out["light_candidates"] = _check_int("light_candidates", out["light_candidates"], 1, 8)
    thr = out["adaptive_threshold"]
    if isinstance(thr, bool) or not isinstance(thr, (int, float, np.integer, np.floating)) \
            or not float(thr) >= 0.0 or not np.isfinite(float(thr)):
        raise ValueError(f"setting 'adaptive_threshold' must be a number >= 0 (0: off), "
                         f"got {thr!r}")
    out["adaptive_threshold"] = float(thr)
    out["adaptive_min_samples"] = _check_int("adaptive_min_samples",
                                             out["adaptive_min_samples"], 0, 1 << 30)
    out["adaptive_step"] = _check_int("adaptive_step", out["adaptive_step"], 1, 1 << 20)
    if out["sort"] is not None and not isinstance(out["sort"], (bool, np.bool_)):
        raise TypeError(f"setting 'sort' must be True, False or None, got {out['sort']!r}")
    if out["cis_target"] not in CIS_TARGETS:
        raise ValueError(f"setting 'cis_target' must be one of {CIS_TARGETS}, "
                         f"got {out['cis_target']!r}")
    if not isinstance(out["naive_ris"], (bool, np.bool_)):
        raise TypeError(f"setting 'naive_ris' must be a bool, got {out['naive_ris']!r}")
    out["naive_ris"] = bool(out["naive_ris"])
    if not isinstance(out["soft_visibility"], (bool, np.bool_)):
        raise TypeError(f"setting 'soft_visibility' must be a bool, got {out['soft_visibility']!r}")
    out["soft_visibility"] = bool(out["soft_visibility"])
    if out["connection_allocation"] is not None and not isinstance(
            out["connection_allocation"], (bool, np.bool_)):
        raise TypeError("setting 'connection_allocation' must be True, False or None, got "
                        f"{out['connection_allocation']!r}")
    if out["connection_allocation"] is not None:
        out["connection_allocation"] = bool(out["connection_allocation"])
    for key in ("instancing", "auto_keep_pilot", "auto_media", "moment_channels",
                "naive_map"):
        if not isinstance(out[key], (bool, np.bool_)):
            raise TypeError(f"setting '{key}' must be a bool, got {out[key]!r}")
        out[key] = bool(out[key])
    return out, warnings


# Bytes the native film takes per pixel: running and iteration sums (3 doubles each) and the
# float32 image (native/src/scene/scene_limits.h, kFilmBytesPerPixel).
FILM_BYTES_PER_PIXEL = 2 * 3 * 8 + 3 * 4


def memory_limit_bytes():
    """Memory a render may use: the physical memory, or the address-space limit when lower."""
    import os
    limit = float("inf")
    try:
        limit = float(os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (AttributeError, ValueError, OSError):
        pass
    try:
        import resource
        soft, _ = resource.getrlimit(resource.RLIMIT_AS)
        if soft != resource.RLIM_INFINITY:
            limit = min(limit, float(soft))
    except (ImportError, ValueError, OSError):
        pass
    return limit


def _format_bytes(n):
    return f"{n / 2**30:.1f} GiB" if n >= 2**30 else f"{n / 2**20:.0f} MiB"


def check_film_memory(width, height):
    """ValueError saying how much a width x height film needs when that is more than half the
    memory (checked before anything is allocated; the native core checks the same)."""
    need = float(width) * float(height) * FILM_BYTES_PER_PIXEL
    have = 0.5 * memory_limit_bytes()  # the rest: scene, wavefront, light vertex cache
    if need > have:
        raise ValueError(f"a {width}x{height} film needs {_format_bytes(need)} for its buffers "
                         f"({FILM_BYTES_PER_PIXEL} bytes per pixel), more than the "
                         f"{_format_bytes(have)} a film may take (half the memory this process "
                         f"may use); lower the resolution")


def _value(attr):
    """A native attribute that may be bound as a property or as a method."""
    return attr() if callable(attr) else attr


def gpu_features(native_scene):
    """The features of gpu_selfcheck.FEATURE_CASES a scene (its `Scene.to_native()` dict) has,
    as the core tests them (scene/subsurface_input.h subsurface_reason, scene/medium_build.cpp
    media_reason): "subsurface", a principled material with subsurface weight and radius;
    "media", the world's volume or a material's."""
    out = set()
    world = native_scene.get("world") or {}
    if world.get("volume") is not None:
        out.add("media")
    for m in native_scene.get("materials") or []:
        if m.get("volume") is not None or m.get("volume_only"):
            out.add("media")
        radius = m.get("subsurface_radius")
        if (m.get("type") == "principled" and float(m.get("subsurface_weight") or 0.0) > 0.0
                and radius is not None and float(np.max(radius)) >= 1e-8):
            out.add("subsurface")
    return out


# session.h kGpuChecked*: SessionSettings::gpu_checked's bit of each feature
GPU_CHECKED_BITS = {"subsurface": 1, "media": 2}


def gpu_checked_bits(features):
    """SessionSettings::gpu_checked for the features (of gpu_selfcheck.FEATURE_CASES) whose
    GPU self-check cases passed."""
    return sum(bit for f, bit in GPU_CHECKED_BITS.items() if f in features)


def _has_hetero_media(scene):
    """Whether a material's volume is heterogeneous (a density grid or a density program):
    what the core's HostScene::add_lights tests before it starts soft lights' paths."""
    return any(isinstance(m, dict) and m.get("volume") is not None
               and (m.get("density_grid") is not None
                    or any(p.get("target") in ("density", "volume_color", "volume_emission_color",
                                             "volume_absorption_color", "volume_emission")
                        for p in (m.get("programs") or [])))
               for m in getattr(scene, "materials", []))


def camera_side_light_warnings(scene, integrator):
    """Point and spot lights with a radius and soft falloff on (Blender's default) are a disk
    facing each receiver. Light paths start at their centre and take the point on the disk that
    faces their first hit (docs/lvc_notes.md), through homogeneous media too, except in scenes
    with a heterogeneous medium: there bdpt, lvc and cis light them from the camera side only,
    as pt does. Say so where it costs the integrator what it was chosen for."""
    if integrator not in ("bdpt", "lvc", "cis") or not _has_hetero_media(scene):
        return []
    out = []
    for k, light in enumerate(getattr(scene, "lights", [])):
        if (light.get("type") in ("point", "spot") and float(light.get("radius", 0.0)) > 0.0
                and light.get("soft_falloff", True)):
            name = light.get("name") or f"lights[{k}]"
            out.append(f"light '{name}': soft falloff is on in a scene with a heterogeneous "
                       f"medium, so {integrator}'s light paths cannot start on it (it is lit from "
                       "the camera side only, as in pt); switch its Soft Falloff off for a "
                       "sphere light")
    return out


class Session:
    """A progressive render of one scene.

    `step()` runs one iteration (`spp_per_iteration` samples per pixel; the GIL is released);
    `image()` is the mean radiance so far, float32 (H, W, 3), top row first."""

    def __init__(self, scene, **settings):
        self.settings, self._warnings = resolve_settings(settings)
        for w in self._warnings:
            log.warning(w)
        if not hasattr(scene, "to_native"):
            raise TypeError(f"expected a lantern.Scene, got {type(scene).__name__}")
        native_scene = scene.to_native()  # scene errors first: they are the user's to fix
        check_film_memory(native_scene["film"]["width"], native_scene["film"]["height"])
        checked = 0
        if self.settings["backend"] == "auto":
            # a GPU is trusted only after the self-check passed on it (gpu_selfcheck.py), with
            # a subsurface or media scene only once those cases passed too
            info = cuda_info()
            veto = gpu_selfcheck.auto_backend_veto(
                info, gpu_features(native_scene) if info.get("available") else ())
            if veto:
                self.settings["backend"] = "cpu"
                self._warnings.append(veto)
                log.warning(veto)
            elif info.get("available"):
                # integrator auto may choose cis on the GPU in a scene with a feature whose
                # self-check cases passed there (session.cpp; a forced "cuda": pt there)
                checked = gpu_checked_bits(gpu_selfcheck.passed_features(info))
        core = require_core()
        self._scene = scene
        self._native = core.Session(native_scene, dict(self.settings, gpu_checked=checked))
        self._warnings += camera_side_light_warnings(scene, self.settings["integrator"])

    def step(self):
        """One iteration; returns the samples per pixel so far (unchanged when the step was
        cancelled). Safe from several threads: steps run one at a time."""
        self._native.step()
        return self.spp

    def image(self):
        return self._native.image()

    @property
    def spp(self):
        return int(_value(self._native.spp))

    def pixel_samples(self):
        """Each pixel's own samples, int32 (H, W), top row first: with adaptive sampling a
        converged pixel stops counting (Cycles' "Sample Count" debug pass); else all spp."""
        native = getattr(self._native, "pixel_samples", None)
        if native is None:
            h, w = self.image().shape[:2]
            return np.full((h, w), self.spp, np.int32)
        return np.asarray(native())

    @property
    def converged(self):
        """Adaptive sampling: True once every pixel has converged (a step adds nothing)."""
        return bool(_value(getattr(self._native, "converged", False)))

    @property
    def active_pixels(self):
        """Pixels that still sample (all of them without adaptive sampling)."""
        return int(_value(self._native.active_pixels))

    @property
    def noise_error(self):
        """The worst still-sampling pixel's error at the last check (-1 before one)."""
        return float(_value(self._native.noise_error))

    @property
    def stats(self):
        return dict(_value(self._native.stats))

    @property
    def backend(self):
        """The backend that really renders: "cpu" or "cuda" (after any fallback)."""
        native = getattr(self._native, "backend", None)
        if native is not None:
            return str(_value(native))
        stats_backend = self.stats.get("backend")
        return str(stats_backend) if stats_backend else self.settings["backend"]

    @property
    def warnings(self):
        return list(self._warnings) + list(_value(self._native.warnings))

    def update_camera(self, film, camera):
        """A new camera and film (dicts as in Scene.film / Scene.camera): sampling restarts
        with the scene and its acceleration structure kept, as a new Session of the moved
        camera would render (the viewport's view moves). False when this backend or core
        cannot (the GPU keeps its own copy of the scene): make a new Session then. Call it from
        the thread that reads image()."""
        update = getattr(self._native, "update_camera", None)
        if update is None:
            return False
        from .scene import Scene
        view = Scene()
        view.film, view.camera = dict(film), dict(camera)
        native = view.to_native()  # the same checks as a new scene's
        return bool(update({"film": native["film"], "camera": native["camera"]}))

    def set_connection_map(self, n, m=None):
        """lvc, cis: the connections N (and cis's candidates M) of each pixel for the next
        iterations, (H, W) integer arrays (N in 0..64; M in 1..64, default the session's
        `candidates`), the image kept: each iteration's counts are fixed before it, so the
        image stays unbiased (integrator/pixel_conn.h). None: the session's N and M everywhere.
        CPU and GPU (the GPU's path compiled, not yet run on a device); False where the native
        core has no such call."""
        setter = getattr(self._native, "set_connection_map", None)
        if setter is None:
            return False
        if n is None:
            return bool(setter(b""))
        n = np.asarray(n)
        if m is None:
            m = np.full(n.shape, int(self.settings.get("candidates", 10)))
        m = np.asarray(m)
        if n.ndim != 2 or m.shape != n.shape:
            raise ValueError("set_connection_map: N and M must be (height, width) arrays")
        if n.min() < 0 or n.max() > 64 or m.min() < 0 or m.max() > 64:
            raise ValueError("set_connection_map: N must be in [0, 64], M in [1, 64]")
        both = np.stack([n, np.where(n > 0, m, 0)], axis=-1).astype(np.uint8)
        return bool(setter(np.ascontiguousarray(both).tobytes()))

    def update_materials(self, materials, textures=()):
        """New materials and textures (lists as in Scene.materials / Scene.textures, the same
        number of materials), sampling restarted, the scene's geometry and acceleration
        structure kept: as a new Session of the edited scene would render. False, with
        nothing changed, when the edit reaches further (emission, alpha, textures, the
        number of materials) or this backend cannot: make a new Session then."""
        update = getattr(self._native, "update_materials", None)
        if update is None:
            return False
        from .scene import Scene
        edit = Scene()
        edit.materials, edit.textures = list(materials), list(textures)
        native = edit.to_native()
        if "node_programs" in native:  # the core's in-place edit converts no node-graph
            return False               # programs (HostScene::update_materials): a new Session
        return bool(update({"materials": native["materials"], "textures": native["textures"]}))

    def move_instance(self, index, matrix):
        """Place scene.meshes[index] by `matrix` (4x4, applied to the positions the mesh was
        given with; the identity puts it back), sampling restarted, no geometry re-exported and
        no bottom-level BVH built: as a new Session of the moved scene would render. Needs the
        setting instancing=True. False, with nothing changed, where the move reaches further (an
        emitting mesh, a mirroring or singular matrix, a vertex leaving the scene's bounding
        sphere) or this backend cannot (the GPU): make a new Session then."""
        move = getattr(self._native, "move_instance", None)
        if move is None or not self.settings.get("instancing"):
            return False
        m = np.asarray(matrix, dtype=np.float64)
        if m.shape != (4, 4):
            raise ValueError(f"move_instance needs a 4x4 matrix, got shape {m.shape}")
        if not 0 <= int(index) < len(self._scene.meshes):
            raise IndexError(f"mesh index {index} out of range ({len(self._scene.meshes)} meshes)")
        if not np.isfinite(m).all() or not np.allclose(m[3], (0, 0, 0, 1)):
            return False
        return bool(move(int(index), [float(x) for x in m.ravel()]))

    def cancel(self):
        """Thread-safe: a running `step()` returns early; the image stays at the last
        finished iteration. With no step running, the next one is cancelled: the flag stays
        set until a step has returned."""
        self._native.cancel()

    def __repr__(self):
        return (f"<lantern.Session {self.settings['integrator']}/{self.backend} "
                f"spp={self.spp}>")


def render(scene, spp=16, time_limit=None, progress=None, **settings):
    """Render `scene` to `spp` samples per pixel (or until `time_limit` seconds have passed,
    after at least one iteration); calls `progress(spp_done, spp_total)` after each iteration.
    Returns the float32 (H, W, 3) image.

    With `spp_per_iteration` not dividing `spp`, the last iteration may overshoot."""
    if isinstance(spp, bool) or not isinstance(spp, (int, np.integer)) or spp < 1:
        raise ValueError(f"spp must be a positive integer, got {spp!r}")
    if time_limit is not None and not time_limit > 0:
        raise ValueError(f"time_limit must be > 0 seconds, got {time_limit!r}")
    session = Session(scene, **settings)
    start = time.monotonic()
    while session.spp < spp:
        before = session.spp
        session.step()
        if progress is not None:
            progress(session.spp, int(spp))
        if session.spp <= before or session.converged:
            break  # cancelled, converged (adaptive sampling) or no progress: never spin
        if time_limit is not None and time.monotonic() - start >= time_limit:
            break
    return session.image()
