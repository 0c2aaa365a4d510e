"""What the render engine does: F12 renders stream each iteration into the render result; the
viewport re-exports on change and refines in a background thread that never touches bpy.

Errors never escape into Blender: they are reported with self.report and printed with their
traceback; a final render keeps whatever image was finished."""

import math
import threading
import time
import traceback
import weakref

import numpy as np

from . import farm
from .native import import_lantern

_live_states = weakref.WeakSet()


def _report_error(engine, what, error):
    traceback.print_exc()
    try:
        engine.report({"ERROR"}, f"Lantern: {what}: {error}")
    except Exception:  # the engine may be gone (viewport closed)
        pass


def _report_warnings(engine, messages):
    # engine.report prints to the console itself (background) and shows in the status bar and
    # the Info editor: one print per warning
    for message in messages:
        engine.report({"WARNING"}, f"Lantern: {message}")


def _report_info(engine, message):
    engine.report({"INFO"}, f"Lantern: {message}")  # printed by report, as warnings


def backend_message(session):
    """Which backend renders, in words for the render report: "rendering on the GPU (CUDA)"."""
    used = getattr(session, "backend", "cpu")
    return "rendering on the GPU (CUDA)" if used == "cuda" else "rendering on the CPU"


def to_rect(image, alpha=None):
    """Mean radiance (H, W, 3), top row first -> Blender's RGBA rect, bottom row first;
    `alpha` (H, W), top row first: the transparent film's coverage (None: opaque)."""
    h, w = image.shape[:2]
    rect = np.ones((h, w, 4), dtype=np.float32)
    rect[:, :, :3] = image[::-1]
    if alpha is not None:
        rect[:, :, 3] = alpha[::-1]
    return rect.reshape(h * w, 4)


def film_alpha(lantern, scene, target, settings):
    """The transparent film's alpha (lantern.film), or None for an opaque film."""
    if not scene.film.get("transparent"):
        return None
    try:
        from lantern.film import render_alpha
    except ImportError:  # an older lantern package: opaque, as before
        return None
    rest = {k: v for k, v in settings.items() if k in ("backend", "threads", "max_depth")}
    return render_alpha(scene, spp=min(max(1, target), 256), seed=int(settings.get("seed", 0)),
                        **rest)


def _write_result(engine, result, image, alpha=None):
    rect = to_rect(image, alpha)
    combined = result.layers[0].passes["Combined"]
    combined.rect.foreach_set(rect.ravel()) if hasattr(combined.rect, "foreach_set") else \
        setattr(combined, "rect", rect)
    engine.update_result(result)


class _Stepper:
    """Steps a native session in a worker thread (the core releases the GIL); the main thread
    polls and may cancel. The worker touches only the session, never bpy."""

    def __init__(self, session):
        self.session = session
        self.error = None
        self._thread = None

    def start_step(self):
        def run():
            try:
                self.session.step()
            except Exception as e:  # handed to the main thread
                self.error = e
        self._thread = threading.Thread(target=run, name="lantern-step", daemon=True)
        self._thread.start()

    def wait(self, timeout):
        self._thread.join(timeout)
        return not self._thread.is_alive()


# ---- F12 ----

def _final_reported(engine):
    """Warnings already shown in this F12 render (one RenderEngine serves every view layer)."""
    state = engine._lantern
    seen = getattr(state, "final_reported", None)
    if seen is None:
        seen = state.final_reported = set()
    return seen


def _warn_once(engine, messages):
    seen = _final_reported(engine)
    fresh = [m for m in dict.fromkeys(messages) if m not in seen]
    seen.update(fresh)
    if fresh:
        _report_warnings(engine, fresh)


def render(engine, depsgraph):
    """One view layer (Blender calls render() once per layer, each with its depsgraph): its
    own result, Combined and the data passes it asks for, on the border when there is one."""
    from . import final_render, passes
    bscene = depsgraph.scene
    view_layer = depsgraph.view_layer
    settings = bscene.lantern
    preview = engine.is_preview
    target = settings.preview_samples if preview else settings.samples
    if not preview and getattr(view_layer, "samples", 0) > 0:
        target = view_layer.samples  # the view layer's own sample count (0: the scene's)
    time_limit = float(settings.time_limit)
    try:
        lantern = import_lantern()
        from .export import export_scene
        engine.update_stats("", f"Lantern: exporting {view_layer.name}")
        t0 = time.perf_counter()
        scene, report = export_scene(depsgraph, frame_set=engine.frame_set)
        report.messages.extend(passes.unsupported_pass_warnings(view_layer))
        full_w, full_h = scene.film["width"], scene.film["height"]
        rect = final_render.border_rect(bscene.render, full_w, full_h)
        if rect is not None:
            final_render.crop_scene(scene, rect)
        _warn_once(engine, report.messages)
        adaptive = settings.use_adaptive_sampling and not preview
        session = lantern.Session(scene, **settings.session_settings(),
                                  **final_render.adaptive_settings(settings, adaptive))
        _warn_once(engine, session.warnings)  # a CUDA fallback says why here
        info = backend_message(session)
        if ("info", info) not in _final_reported(engine):  # once per render, not per layer
            _final_reported(engine).add(("info", info))
            _report_info(engine, info)
        alpha = film_alpha(lantern, scene, target, settings.session_settings())
    except Exception as e:
        _report_error(engine, "could not start the render", e)
        return
    width, height = scene.film["width"], scene.film["height"]
    # coordinates are relative to the border rectangle, which is the result's whole size
    result = engine.begin_result(0, 0, width, height, layer=view_layer.name)
    try:
        layer = result.layers[0]
        if len(layer.passes["Combined"].rect) != width * height:
            raise RuntimeError(f"the render result is {len(layer.passes['Combined'].rect)} "
                               f"pixels, Lantern's film {width} x {height}")
        if passes.enabled_passes(view_layer):
            _data_passes(engine, scene, settings, target, layer, session)
            engine.update_result(result)
        noise = None  # the core stops each pixel; the GPU only the frame, checked here
        if adaptive and getattr(session, "backend", "cpu") != "cpu":
            noise = final_render.NoiseCheck(settings.adaptive_threshold,
                                            settings.adaptive_min_samples)
        _render_loop(engine, session, result, target, time_limit, t0, noise, alpha)
        if passes.sample_count_enabled(view_layer):
            passes.write_sample_count(layer, session.pixel_samples())
            engine.update_result(result)
    except Exception as e:
        _report_error(engine, "render failed", e)
    finally:
        engine.end_result(result)
        farm.stamp_chunk(engine, scene, session, settings)  # samples and scene, for merges


def _data_passes(engine, scene, settings, target, layer, session):
    """Depth, Normal, ... into the result layer; a failure here leaves them empty (said so) and
    the render goes on."""
    from . import passes
    engine.update_stats("", f"Lantern: data passes of {layer.name}")
    try:
        from lantern.aov import render_aovs
        # camera rays only (cheap): at least 16 per pixel, so that the denoiser's features are
        # smooth even when the image has few samples; at most 64
        aovs = render_aovs(scene, spp=min(max(16, target), 64), seed=settings.seed,
                           threads=settings.threads)
        _warn_once(engine, [w for w in aovs.pop("warnings", []) if w not in session.warnings])
        passes.write_data_passes(layer, aovs)
    except Exception as e:  # a warning: the render itself goes on and is fine
        traceback.print_exc()
        _warn_once(engine, [f"the data passes (Depth, Normal, ...) failed and stay empty: {e}"])


def _render_loop(engine, session, result, target, time_limit, t0, noise=None,
                 alpha=None):
    stepper = _Stepper(session)
    start = time.perf_counter()
    converged = False
    while session.spp < max(1, target):
        before = session.spp
        stepper.start_step()
        cancelled = False
        while not stepper.wait(0.05):
            # a time limit shorter than one sample still gives one (a black frame helps no one)
            if not cancelled and (engine.test_break() or
                                  (before > 0 and _past(time_limit, start))):
                session.cancel()
                cancelled = True
        if stepper.error is not None:
            raise stepper.error
        if session.spp > before:
            image = session.image()
            _write_result(engine, result, image, alpha)
            if noise is not None:
                converged = noise.add(image, session.spp)
        converged = converged or bool(getattr(session, "converged", False))
        elapsed = time.perf_counter() - start
        stats = session.stats
        mrays = stats.get("rays_total", 0) / max(elapsed, 1e-9) / 1e6
        noise_text = "" if noise is None or not math.isfinite(noise.error) else \
            f" | noise {noise.error:.4f}/{noise.threshold:g}"
        if noise is None and getattr(session, "settings", {}).get("adaptive_threshold", 0) > 0:
            from .final_render import adaptive_status
            noise_text = adaptive_status(session)
        engine.update_stats("", f"Sample {session.spp}/{target} | {elapsed:.1f} s | "
                                f"{mrays:.1f} Mrays/s | {getattr(session, 'backend', 'cpu')}"
                                f"{auto_status(stats)}{noise_text}")
        engine.update_progress(min(1.0, session.spp / max(1, target)))
        if cancelled or converged or session.spp <= before or engine.test_break() or \
                _past(time_limit, start):
            break
    why = " (noise threshold reached)" if converged else ""
    if noise is None and getattr(session, "settings", {}).get("adaptive_threshold", 0) > 0:
        why += f" (adaptive: {session.pixel_samples().mean():.1f} samples a pixel)"
    print(f"Lantern: {session.spp} spp in {time.perf_counter() - start:.2f} s on "
          f"{getattr(session, 'backend', 'cpu')}{why} (export and set-up {start - t0:.2f} s)")


LAST_AUTO = {"text": ""}  # what "auto" chose in the last render, for the Lantern panel


def auto_status(stats):
    """' | Auto: ...' for the status bar while integrator "auto" renders (native/src/integrator/
    allocation.h): measuring, or which integrator it chose and its estimate of cis's efficiency
    against pt's (light paths per iteration: one per pixel sample under cis, none under pt), and
    under cis the mean connections per pixel its allocation chose. Empty for the other
    integrators."""
    choice = stats.get("auto_choice")
    if choice is None:
        return ""
    ratio = float(stats.get("auto_cis_over_pt", 0.0))
    if choice == "pilot":
        text = "Auto: measuring path tracing and CIS-LBDPT"
    elif choice == "cis":
        text = f"Auto: CIS-LBDPT (estimated {ratio:.3g}x path tracing's efficiency"
        # what its allocation chose (integrator/pixel_alloc.h): a light path per pixel sample,
        # and the connections per camera vertex over the image (measuring: still its pilot)
        mean = stats.get("mean_connections")
        if mean is not None:
            text += ("; a light path per sample, " + (
                f"{float(mean):.2g} connections a pixel on average"
                if int(stats.get("connection_choices", 0)) > 0 else "measuring connections"))
        text += ")"
    elif ratio > 0.0:
        text = f"Auto: path tracing (CIS-LBDPT estimated at {ratio:.2g}x its efficiency)"
    else:
        text = "Auto: path tracing"
    LAST_AUTO["text"] = text
    return " | " + text


def _past(time_limit, start):
    return time_limit > 0 and time.perf_counter() - start >= time_limit


# ---- Viewport ----
# view_update notes what changed (export/changes.py); view_draw brings the exported scene up to
# date (export/sync.py) and either replaces the session's camera (a view move: no export, no
# rebuild) or starts a new session of the patched scene. The first iteration after a change
# renders a quarter of the resolution when the region is large, so an image answers at once.

COARSE_MIN_PIXELS = 256 * 256  # regions from this size get a coarse first iteration
COARSE_FACTOR = 4


class EngineState:
    """Per-engine viewport state: the incremental export, the session, its refining thread,
    the drawn texture."""

    def __init__(self):
        from .export.sync import ViewportSync
        self.session = None
        self.thread = None
        self.stop = threading.Event()
        self.lock = threading.Lock()
        self.image = None          # latest image from the worker (numpy), guarded by lock
        self.image_serial = 0
        self.view_key = None
        self.target = 0
        self.draw = None           # viewport.ImageDraw
        self.sync = ViewportSync()  # the exported lantern.Scene, its caches, pending changes
        self.error = None
        self.failed = False        # the last export failed: wait for a change before retrying
        self.reported = set()      # session warnings already shown (a CUDA fallback: once)
        self.export_reported = set()  # export warnings shown since the last full export
        self.camera_updates = 0    # view moves served without a new session
        self.material_updates = 0  # material edits served without a new session
        self.instance_moves = 0    # transform edits served by moving instances (no new session)
        self.building = False      # the refining thread is building its session
        self.new_warnings = []     # the new session's warnings, reported by view_draw
        _live_states.add(self)

    @property
    def scene(self):
        return self.sync.scene

    @property
    def texture_cache(self):
        return self.sync.texture_cache

    def pause(self):
        """Stop the refining thread (cancelling its step); the session stays."""
        self.stop.set()
        if self.session is not None and self.refining():  # a cancel outlives no step
            try:
                self.session.cancel()
            except Exception:
                pass
        if self.thread is not None:
            self.thread.join(5.0)
        self.thread = None
        self.stop = threading.Event()

    def stop_session(self):
        self.pause()
        self.session = None

    def _publish(self, image):
        with self.lock:
            self.image = image
            self.image_serial += 1

    def start_session(self, session, target, coarse=None, make=None):
        """Refine `session` to `target` samples (0: until stopped) in a thread. `coarse`:
        (small film, full film, camera) for a first iteration at a fraction of the pixels.
        `make`: a function that builds the session, called in the thread (session None), so
        that the acceleration structure is built off Blender's main thread."""
        if session is not self.session or make is not None:
            self.stop_session()
        elif self.refining():
            self.pause()
        self.session = session
        self.target = target
        self.building = make is not None
        stop = self.stop

        def refine():
            s = session
            try:
                if make is not None:
                    try:
                        s = make()
                    finally:
                        self.building = False
                    if stop.is_set():
                        return
                    self.session, self.new_warnings = s, list(s.warnings)
                if coarse is not None and _update_camera(s, coarse[0], coarse[2]):
                    s.step()
                    if stop.is_set():
                        return
                    if s.spp > 0:
                        self._publish(s.image())
                    if not s.update_camera(coarse[1], coarse[2]):
                        raise RuntimeError("the session could not return to the full view")
                while not stop.is_set() and (target <= 0 or s.spp < target):
                    before = s.spp
                    s.step()
                    if stop.is_set() or s.spp <= before:
                        break
                    self._publish(s.image())
            except Exception as e:
                self.error = e
                self.failed = self.failed or s is None  # a scene that cannot start: wait
        self.thread = threading.Thread(target=refine, name="lantern-viewport", daemon=True)
        self.thread.start()

    def refining(self):
        return self.thread is not None and self.thread.is_alive()

    def free(self):
        self.stop_session()
        self.draw = None
        self.sync = type(self.sync)()


def stop_all():
    for state in list(_live_states):
        state.free()


def _update(session, method, *args):
    """session.update_camera / update_materials where the session has it (an older lantern
    does not); False when it has not or cannot."""
    update = getattr(session, method, None)
    return bool(update is not None and update(*args))


def _update_camera(session, film, camera):
    return _update(session, "update_camera", film, camera)


def _coarse(view):
    """(small film, full film, camera) for the first iteration, or None for small regions."""
    film = view.film()
    if film["width"] * film["height"] < COARSE_MIN_PIXELS:
        return None
    small = dict(film, width=max(1, film["width"] // COARSE_FACTOR),
                 height=max(1, film["height"] // COARSE_FACTOR))
    return small, film, view.camera()


def view_update(engine, context, depsgraph):
    from .export.changes import FULL, Changes, classify
    state = engine._lantern
    try:
        changes = classify(depsgraph.updates)
    except Exception:  # an update we cannot read: export everything rather than fail
        traceback.print_exc()
        changes = Changes(FULL)
    state.sync.note(changes)
    state.failed = False


def _snapshot(scene, lantern):
    """A copy of the scene's containers for a session built in the refining thread: the sync
    replaces or patches them (a material in its slot) while the thread reads."""
    copy = lantern.Scene()
    copy.film, copy.camera, copy.world = dict(scene.film), dict(scene.camera), dict(scene.world)
    copy.materials, copy.textures = list(scene.materials), list(scene.textures)
    copy.meshes, copy.lights = list(scene.meshes), list(scene.lights)
    copy.grids = list(getattr(scene, "grids", []))   # Volume objects (export/volume_objects.py)
    copy.curves = list(getattr(scene, "curves", []))  # hair (export/strands.py)
    copy.attribute_channels = list(getattr(scene, "attribute_channels", []))  # node_attributes
    return copy


def _new_session(engine, state, lantern, settings, view, patch=None, moved=True):
    """Build the session in the refining thread. `patch`: a running session whose scene
    differs in its materials only: it takes them in place (colours, roughness, ...: no scene
    rebuild, no BVH build) when their emission, alpha and textures stay."""
    scene, kwargs = _snapshot(state.sync.scene, lantern), settings.session_settings()
    if "instancing" in getattr(lantern.session, "DEFAULT_SETTINGS", {}):
        kwargs["instancing"] = True  # transform edits then move instances (_move_instances)
    base = state.sync.session_base()

    def make():
        if patch is not None and _update(patch, "update_materials", scene.materials,
                                         scene.textures) and (
                not moved or _update(patch, "update_camera", scene.film, scene.camera)):
            state.material_updates += 1
            return patch
        session = lantern.Session(scene, **kwargs)
        state.sync.base = base
        return session
    state.start_session(None, settings.preview_samples, _coarse(view), make=make)


def _report_new_warnings(engine, state):
    warnings, state.new_warnings = state.new_warnings, []
    _report_warnings(engine, [w for w in warnings if w not in state.reported])
    state.reported.update(warnings)


def _sync_viewport(engine, context, depsgraph, view, key):
    """Export what changed and (re)start the render; returns nothing, raises on failure."""
    from .export import ExportReport
    state = engine._lantern
    settings = context.scene.lantern
    lantern = import_lantern()
    if state.sync.needs_sync() or state.session is None:
        from .export.changes import FULL, MATERIALS, TRANSFORM, VIEW
        session = state.session
        state.pause()  # the old image shows meanwhile
        report = ExportReport()
        todo = state.sync.sync(depsgraph, view, report)
        # each walk warns again (a move walks every instance): shown once until a full export
        if todo.flags & FULL:
            state.export_reported.clear()
        fresh = [m for m in report.messages if m not in state.export_reported]
        state.export_reported.update(fresh)
        _report_warnings(engine, fresh)
        moved = key != state.view_key
        state.view_key, state.error = key, None
        if not todo.flags & ~VIEW and session is not None:
            # an object tagged for shading only whose settings the scene does not read (its
            # material's edit is MATERIALS): the same scene, the running session goes on
            if not moved or _update_camera(session, state.sync.scene.film,
                                           state.sync.scene.camera):
                state.start_session(session, settings.preview_samples,
                                    _coarse(view) if moved else None)
                return
        patch = session if todo.flags & ~VIEW == MATERIALS else None
        if todo.flags & ~VIEW == TRANSFORM and _move_instances(state, session, view, moved,
                                                            settings.preview_samples):
            return
        _new_session(engine, state, lantern, settings, view, patch, moved)
    elif key != state.view_key:  # only the view moved: the same scene, a new camera
        state.pause()
        scene = state.sync.scene
        scene.film, scene.camera = view.film(), view.camera()
        state.sync.pending.flags = 0  # a camera object's tags: served by the new camera
        state.view_key, state.error = key, None
        if _update_camera(state.session, scene.film, scene.camera):
            state.camera_updates += 1
            state.start_session(state.session, settings.preview_samples, _coarse(view))
        else:  # a backend that keeps its own copy of the scene (the GPU)
            _new_session(engine, state, lantern, settings, view)


def _move_instances(state, session, view, moved, samples):
    """A transform edit served by the running session: each moved instance placed again
    (Session.move_instance: no geometry sent, no bottom-level BVH built), sampling restarted.
    False when it cannot (the meshes' list changed, a move the core refuses, an older core):
    then a new session is built, from the scene the sync has just placed."""
    moves = state.sync.session_moves() if session is not None else None
    move = getattr(session, "move_instance", None)
    if moves is None or move is None:
        return False
    try:
        if not all(move(k, m) for k, m in moves):
            return False  # partly moved: the new session replaces it
    except (ValueError, IndexError):
        return False
    scene = state.sync.scene
    if moved and not _update_camera(session, scene.film, scene.camera):
        return False
    state.instance_moves += 1
    state.start_session(session, samples, _coarse(view))
    return True


def view_draw(engine, context, depsgraph):
    from . import viewport
    from .export.camera import ViewportView
    state = engine._lantern
    view = None
    try:
        view = ViewportView(context)
        key = (view.key(), view.filter_width)
        # while the thread builds a session, changes wait (they accumulate) and the old image
        # shows: the main thread never waits for a build
        if not state.failed and not state.building and (
                state.sync.needs_sync() or state.session is None or key != state.view_key):
            _sync_viewport(engine, context, depsgraph, view, key)
        if state.new_warnings:
            _report_new_warnings(engine, state)
        if state.error is not None:
            error, state.error = state.error, None
            _report_error(engine, "viewport render failed", error)
        with state.lock:
            image, serial = state.image, state.image_serial
        if image is not None:
            if state.draw is None:
                state.draw = viewport.ImageDraw()
            state.draw.update(image, serial)
            state.draw.draw(engine, context.scene, context.region.width, context.region.height)
        if state.refining():
            engine.tag_redraw()
    except Exception as e:
        # do not retry a failing export on every redraw: wait for the next change
        from .export.changes import FULL, Changes
        state.stop_session()
        state.failed = True
        state.sync.pending |= Changes(FULL)
        if view is not None:
            state.view_key = (view.key(), view.filter_width)
        _report_error(engine, "viewport", e)
