"""Stands in for the `blender` binary where only bpy as a Python module is installed (this
machine, CI): `python tools/bpy_blender.py -b file.blend -E LANTERN -f 1` does what
`blender -b file.blend -E LANTERN -f 1` does, so farm jobs and tests run the same command line.

Arguments are processed in order, as Blender does: a .blend path opens it; -E/--engine,
-o/--render-output, -F/--render-format, -S/--scene, -s/-e (frame range), --python-expr run on
the open file (--python-exit-code N: a failing expression exits with N, else it is printed
and the arguments go on); -f/--render-frame N (comma lists, ranges a..b) and -a/--render-anim
render and write. -b/--background and -y/--enable-autoexec are implied; everything after `--`
is left to scripts (sys.argv).

Like Blender, it starts by loading the user's preferences (BLENDER_USER_CONFIG), which enables
the add-ons and extensions installed there: a worker with the Lantern extension installed
renders with that. Only when no engine "LANTERN" is registered after that does it register the
add-on of this checkout (tests, a checkout without the extension).
Unlike Blender, the exit status is 1 when a frame wrote no file (so that jobs see failures)."""

import importlib.util
import os
import sys
import traceback

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _load_user_preferences(bpy):
    """What Blender does at start-up and bpy as a module does not: read userpref.blend, which
    enables the add-ons and extensions the user installed (no file: the defaults)."""
    try:
        bpy.ops.wm.read_userpref()
    except RuntimeError as e:
        print(f"bpy_blender: user preferences not loaded ({e})", file=sys.stderr)


def _lantern_registered(bpy):
    return any(getattr(c, "bl_idname", None) == "LANTERN"
               for c in bpy.types.RenderEngine.__subclasses__())


def _ensure_lantern_engine(bpy):
    if _lantern_registered(bpy) or "lantern_blender" in sys.modules:
        return
    try:
        import lantern  # noqa: F401  (an installed wheel, or PYTHONPATH)
    except ImportError:
        sys.path.insert(0, os.path.join(ROOT, "python"))
    addon = os.path.join(ROOT, "addon")
    spec = importlib.util.spec_from_file_location(
        "lantern_blender", os.path.join(addon, "__init__.py"),
        submodule_search_locations=[addon])
    module = importlib.util.module_from_spec(spec)
    sys.modules["lantern_blender"] = module
    spec.loader.exec_module(module)
    module.register()


def _frames(text):
    out = []
    for part in text.split(","):
        if ".." in part:
            a, b = part.split("..")
            out.extend(range(int(a), int(b) + 1))
        else:
            out.append(int(part))
    return out


def _render_frames(bpy, frames):
    scene = bpy.context.scene
    missing = []
    for frame in frames:
        scene.frame_start = scene.frame_end = frame
        bpy.ops.render.render(animation=True, scene=scene.name)
        path = scene.render.frame_path(frame=frame)
        if not os.path.exists(path):
            missing.append(path)
            print(f"bpy_blender: frame {frame} wrote no file ({path})", file=sys.stderr)
    return missing


def main(argv):
    import bpy
    _load_user_preferences(bpy)
    _ensure_lantern_engine(bpy)
    if "--" in argv:
        cut = argv.index("--")
        argv, sys.argv = argv[:cut], [sys.argv[0]] + argv[cut:]
    missing, i, exit_code = [], 0, 0
    while i < len(argv):
        arg = argv[i]
        value = argv[i + 1] if i + 1 < len(argv) else None
        scene = bpy.context.scene
        if arg in ("-b", "--background", "-y", "--enable-autoexec"):
            i += 1
            continue
        if arg.endswith(".blend"):
            bpy.ops.wm.open_mainfile(filepath=os.path.abspath(arg))
            i += 1
            continue
        if value is None and arg not in ("-a", "--render-anim"):
            raise SystemExit(f"bpy_blender: {arg} needs a value")
        if arg in ("-E", "--engine"):
            try:
                scene.render.engine = value
            except TypeError as e:  # the enum's message lists the registered engines
                raise SystemExit(f"bpy_blender: render engine {value!r} not found ({e})") \
                    from None
        elif arg in ("-o", "--render-output"):
            scene.render.filepath = value
        elif arg in ("-F", "--render-format"):
            scene.render.image_settings.file_format = value
        elif arg in ("-s", "--frame-start"):
            scene.frame_start = int(value)
        elif arg in ("-e", "--frame-end"):
            scene.frame_end = int(value)
        elif arg in ("-S", "--scene"):
            if value not in bpy.data.scenes:
                raise SystemExit(f"bpy_blender: no scene {value!r} in the file")
            if scene.name != value:
                if bpy.context.window is None:
                    raise SystemExit(f"bpy_blender: bpy without a window cannot switch to "
                                     f"scene {value!r}")
                bpy.context.window.scene = bpy.data.scenes[value]
        elif arg == "--python-exit-code":
            exit_code = int(value)
        elif arg == "--python-expr":
            try:
                exec(compile(value, "<python-expr>", "exec"), {"bpy": bpy})
            except Exception:
                traceback.print_exc()
                if exit_code:
                    return exit_code
        elif arg in ("-f", "--render-frame"):
            missing += _render_frames(bpy, _frames(value))
        elif arg in ("-a", "--render-anim"):
            missing += _render_frames(bpy, range(scene.frame_start, scene.frame_end + 1))
            i += 1
            continue
        else:
            raise SystemExit(f"bpy_blender: unsupported argument {arg!r}")
        i += 2
    return 1 if missing else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
