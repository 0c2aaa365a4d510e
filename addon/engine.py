"""What the render engine does: F12 renders stream each iteration into the render result; the
viewport re-exports on change and refines in a background thread that never touches bpy.

Errors never escape into Blender: they are reported with self.report and printed with their
traceback; a final render keeps whatever image was finished."""

import threading
import time
import traceback
import weakref

import numpy as np

_live_states = weakref.WeakSet()


def import_lantern():
    """The `lantern` package, or a RuntimeError that says how to get it."""
    try:
        import lantern
    except ImportError as e:
        raise RuntimeError(f"the 'lantern' Python package is not importable in Blender's "
                           f"Python ({e}); install it (pip install . from the Lantern "
                           f"repository) into the Python Blender runs") from e
    return lantern


def _report_error(engine, what, error):
    traceback.print_exc()
    try:
        engine.report({"ERROR"}, f"Lantern: {what}: {error}")
    except Exception:  # the engine may be gone (viewport closed)
        pass


def _report_warnings(engine, messages):
    for message in messages:
        print(f"Lantern warning: {message}")
        engine.report({"WARNING"}, f"Lantern: {message}")


def _report_info(engine, message):
    print(f"Lantern: {message}")
    engine.report({"INFO"}, f"Lantern: {message}")


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
    rest = {k: v for k, v in settings.items() if k in ("backend", "threads")}
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

def render(engine, depsgraph):
    bscene = depsgraph.scene
    settings = bscene.lantern
    preview = engine.is_preview
    target = settings.preview_samples if preview else settings.samples
    time_limit = float(settings.time_limit)
    try:
        lantern = import_lantern()
        from .export import export_scene
        engine.update_stats("", "Lantern: exporting scene")
        t0 = time.perf_counter()
        scene, report = export_scene(depsgraph)
        _report_warnings(engine, report.messages)
        session = lantern.Session(scene, **settings.session_settings())
        _report_warnings(engine, session.warnings)  # a CUDA fallback says why here
        _report_info(engine, backend_message(session))
        alpha = film_alpha(lantern, scene, target, settings.session_settings())
    except Exception as e:
        _report_error(engine, "could not start the render", e)
        return
    width, height = scene.film["width"], scene.film["height"]
    result = engine.begin_result(0, 0, width, height)
    try:
        _render_loop(engine, session, result, target, time_limit, t0, alpha)
    except Exception as e:
        _report_error(engine, "render failed", e)
    finally:
        engine.end_result(result)


def _render_loop(engine, session, result, target, time_limit, t0, alpha=None):
    stepper = _Stepper(session)
    start = time.perf_counter()
    while session.spp < max(1, target):
        before = session.spp
        stepper.start_step()
        cancelled = False
        while not stepper.wait(0.05):
            if not cancelled and (engine.test_break() or _past(time_limit, start)):
                session.cancel()
                cancelled = True
        if stepper.error is not None:
            raise stepper.error
        if session.spp > before:
            _write_result(engine, result, session.image(), alpha)
        elapsed = time.perf_counter() - start
        stats = session.stats
        mrays = stats.get("rays_total", 0) / max(elapsed, 1e-9) / 1e6
        engine.update_stats("", f"Sample {session.spp}/{target} | {elapsed:.1f} s | "
                                f"{mrays:.1f} Mrays/s | {getattr(session, 'backend', 'cpu')}")
        engine.update_progress(min(1.0, session.spp / max(1, target)))
        if cancelled or session.spp <= before or engine.test_break() or _past(time_limit, start):
            break
    print(f"Lantern: {session.spp} spp in {time.perf_counter() - start:.2f} s on "
          f"{getattr(session, 'backend', 'cpu')} (export and set-up {start - t0:.2f} s)")


def _past(time_limit, start):
    return time_limit > 0 and time.perf_counter() - start >= time_limit


# ---- Viewport ----

class EngineState:
    """Per-engine viewport state: the session, its refining thread, the drawn texture."""

    def __init__(self):
        self.session = None
        self.thread = None
        self.stop = threading.Event()
        self.lock = threading.Lock()
        self.image = None          # latest image from the worker (numpy), guarded by lock
        self.image_serial = 0
        self.view_key = None
        self.dirty = True
        self.target = 0
        self.draw = None           # viewport.ImageDraw
        self.scene = None          # the last exported lantern.Scene (reused when only the view moves)
        self.error = None
        self.failed = False        # the last export failed: wait for a change before retrying
        # image pixels read by earlier viewport exports, by image name (export/texture.py):
        # an edit elsewhere re-exports the scene without re-reading unchanged images
        self.texture_cache = {}
        self.reported = set()      # session warnings already shown (a CUDA fallback: once)
        _live_states.add(self)

    def stop_session(self):
        self.stop.set()
        if self.session is not None:
            try:
                self.session.cancel()
            except Exception:
                pass
        if self.thread is not None:
            self.thread.join(5.0)
        self.thread = None
        self.session = None
        self.stop = threading.Event()

    def start_session(self, session, target):
        self.stop_session()
        self.session = session
        self.target = target
        stop = self.stop

        def refine():
            try:
                while not stop.is_set() and (target <= 0 or session.spp < target):
                    before = session.spp
                    session.step()
                    if stop.is_set() or session.spp <= before:
                        break
                    image = session.image()
                    with self.lock:
                        self.image = image
                        self.image_serial += 1
            except Exception as e:
                self.error = e
        self.thread = threading.Thread(target=refine, name="lantern-viewport", daemon=True)
        self.thread.start()

    def refining(self):
        return self.thread is not None and self.thread.is_alive()

    def free(self):
        self.stop_session()
        self.draw = None
        self.scene = None
        self.texture_cache = {}


def stop_all():
    for state in list(_live_states):
        state.free()


def view_update(engine, context, depsgraph):
    state = engine._lantern
    # full re-export on any change (simple and correct); only images that changed are read again
    for update in depsgraph.updates:
        uid = getattr(update, "id", None)
        if uid is not None and getattr(uid, "bl_rna", None) is not None and \
                uid.bl_rna.identifier == "Image":
            state.texture_cache.pop(getattr(uid.original, "name_full", uid.name_full), None)
    state.dirty, state.failed = True, False


def view_draw(engine, context, depsgraph):
    from . import viewport
    from .export.camera import ViewportView
    state = engine._lantern
    view = None
    try:
        view = ViewportView(context)
        export_needed = state.dirty or (state.scene is None and not state.failed)
        if export_needed or (state.scene is not None and view.key() != state.view_key):
            lantern = import_lantern()
            from .export import export_scene
            state.stop_session()
            if export_needed:
                state.scene = None
                scene, report = export_scene(depsgraph, region_view=view,
                                             texture_cache=state.texture_cache)
                _report_warnings(engine, report.messages)
                state.scene = scene
            else:  # only the view moved: keep the exported scene, swap camera and film
                scene = state.scene
                scene.film, scene.camera = view.film(), view.camera()
            settings = context.scene.lantern
            state.view_key, state.dirty, state.error = view.key(), False, None
            session = lantern.Session(scene, **settings.session_settings())
            _report_warnings(engine, [w for w in session.warnings if w not in state.reported])
            state.reported.update(session.warnings)
            state.start_session(session, settings.preview_samples)  # old image shows meanwhile
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
        state.dirty, state.failed = False, True
        state.scene = None
        if view is not None:
            state.view_key = view.key()
        _report_error(engine, "viewport", e)
