"""The extension as a user gets it: tools/build_extension.sh's zip, installed with
bpy.ops.extensions.package_install_files into a clean user folder, in a Blender (bpy) process
that cannot see the checkout's `lantern` (nor one installed in the venv), then F12.

The zip is built once per session and reused while it is newer than every source it holds
(native/, python/lantern/, addon/, the build files). Where tools/setup.sh's build tree exists
(CI, a developer's checkout) the zip packages that tree's core (LANTERN_EXT_REUSE=1) rather than
compiling a second one."""

import json
import os
import subprocess
import sys
import textwrap
import tomllib
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
SOURCES = ("native", "python/lantern", "addon", "CMakeLists.txt", "pyproject.toml",
           "tools/build_extension.sh")


def _newest_source():
    newest = 0.0
    for rel in SOURCES:
        p = ROOT / rel
        paths = [p] if p.is_file() else [q for q in p.rglob("*") if q.is_file()]
        for q in paths:
            if "__pycache__" in q.parts or q.name.startswith("_core"):
                continue
            newest = max(newest, q.stat().st_mtime)
    return newest


@pytest.fixture(scope="session")
def extension_zip():
    version = tomllib.loads((ROOT / "addon/blender_manifest.toml").read_text())["version"]
    zip_path = ROOT / "dist" / f"lantern-{version}-linux-x64.zip"
    if not zip_path.exists() or zip_path.stat().st_mtime < _newest_source():
        env = dict(os.environ, PYTHON=sys.executable)
        if (ROOT / "build/py/CMakeCache.txt").is_file():
            # the core tools/setup.sh built (the tests' own), packaged by the same pip wheel:
            # a second, CPU-only compile of the core took minutes of CI on a clean clone
            env.setdefault("LANTERN_EXT_REUSE", "1")
        run = subprocess.run(["bash", str(ROOT / "tools/build_extension.sh")], cwd=ROOT, env=env,
                             capture_output=True, text=True, timeout=3600)
        assert run.returncode == 0, f"build_extension.sh failed:\n{run.stdout}\n{run.stderr}"
        assert run.stdout.strip().splitlines()[-1] == str(zip_path)
    return zip_path


# Runs in a fresh interpreter. The finder below lets `import lantern` find only the copy the
# extension installed under BLENDER_USER_EXTENSIONS.
_HIDE = textwrap.dedent(r'''
    import importlib.machinery, json, os, sys
    user_ext = os.path.realpath(os.environ["BLENDER_USER_EXTENSIONS"])

    class OnlyTheExtensionsLantern:
        @staticmethod
        def find_spec(name, path=None, target=None):
            if name != "lantern":
                return None
            dirs = [p for p in sys.path if os.path.realpath(p or ".").startswith(user_ext)]
            spec = importlib.machinery.PathFinder.find_spec(name, dirs)
            if spec is None:
                raise ModuleNotFoundError("lantern is hidden outside the extensions folder")
            return spec

    sys.meta_path.insert(0, OnlyTheExtensionsLantern)
''')
_CHILD = _HIDE + textwrap.dedent(r'''
    import bpy
    out = {}
    zip_path, exr = sys.argv[1], sys.argv[2]
    bpy.ops.wm.read_factory_settings(use_empty=False)
    res = bpy.ops.extensions.package_install_files(filepath=zip_path, repo="user_default",
                                                   enable_on_install=True)
    out["install"] = sorted(res)
    out["addons"] = sorted(a.module for a in bpy.context.preferences.addons)
    import lantern
    out["lantern_file"] = os.path.realpath(lantern.__file__)
    out["native"] = lantern.native_available()
    scene = bpy.context.scene
    scene.render.engine = "LANTERN"
    scene.render.resolution_x, scene.render.resolution_y = 40, 30
    scene.render.resolution_percentage = 100
    scene.lantern.samples = 4
    scene.lantern.backend = "cpu"
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    import numpy as np
    seeds = []
    for k in range(int(sys.argv[3])):   # F12 at seeds 0..K-1, read back through bpy
        scene.lantern.seed = k
        scene.render.filepath = exr if k == 0 else exr[:-4] + f"_{k}.exr"
        res = sorted(bpy.ops.render.render(write_still=True))
        out.setdefault("render", res)
        image = bpy.data.images.load(scene.render.filepath)
        w, h = image.size
        px = np.empty(w * h * 4, np.float32)
        image.pixels.foreach_get(px)
        bpy.data.images.remove(image)
        seeds.append(px.reshape(h, w, 4)[::-1])
    np.save(sys.argv[4], np.stack(seeds))
    world = scene.world.node_tree.nodes["Background"].inputs
    out["world"] = [c * world["Strength"].default_value for c in world["Color"].default_value[:3]]
    print("RESULT " + json.dumps(out))
''')


def _user_env(tmp_path):
    """A clean Blender user folder (config, extensions, ...) and no PYTHON* variables."""
    user = tmp_path / "user"
    env = {k: v for k, v in os.environ.items() if not k.startswith(("PYTHON", "BLENDER_"))}
    for kind in ("RESOURCES", "CONFIG", "SCRIPTS", "EXTENSIONS", "DATAFILES"):
        d = user / kind.lower()
        d.mkdir(parents=True)
        env[f"BLENDER_USER_{kind}"] = str(d)
    env["LANTERN_DISABLE_CUDA"] = "1"
    return env


EXT_SEEDS = 8   # F12s of 4 spp at 40 x 30 on each side (~0.1 s each)


def _settings(scene):
    """The child's settings (_CHILD, _INSTALL) on this process's scene."""
    scene.render.engine = "LANTERN"
    scene.render.resolution_x, scene.render.resolution_y = 40, 30
    scene.render.resolution_percentage = 100
    scene.lantern.samples = 4
    scene.lantern.backend = "cpu"


def _checkout_f12s(tmp_path, seeds):
    """F12 of the default scene at `seeds` in this process: the checkout's add-on and core
    (conftest), the child's settings; (K, H, W, 4), top row first."""
    import bpy
    from blender_helpers import render_exr
    bpy.ops.wm.read_factory_settings(use_empty=False)
    scene = bpy.context.scene
    _settings(scene)
    out = []
    for k in seeds:
        scene.lantern.seed = k
        out.append(render_exr(scene, tmp_path, f"checkout_{k}.exr"))
    return np.stack(out)


def _assert_same_renders(name, installed, checkout):
    """The installed core's F12s against the checkout's, seed by seed (paired: the same
    sources trace the same paths from the same seed, so the noise is what differs between
    the two builds, float rounding where nothing diverges), with the 1 % / 5 % controls."""
    from lantern import metrics
    paired, level = metrics.paired_sets(installed[..., :3], checkout[..., :3])
    metrics.assert_agreement(name, paired, level, block=5)   # 6 x 8 blocks


def test_installed_extension_renders_f12(extension_zip, tmp_path, addon):
    """The extension installed in a clean Blender renders the default cube by F12 as this
    checkout's add-on and core do in-process: EXT_SEEDS seeds a side, paired (was: the centre
    brighter than the world and its std above 0.01)."""
    env = _user_env(tmp_path)
    exr = tmp_path / "f12.exr"
    seeds = tmp_path / "seeds.npy"
    run = subprocess.run([sys.executable, "-c", _CHILD, str(extension_zip), str(exr),
                          str(EXT_SEEDS), str(seeds)],
                         cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    lines = [ln for ln in run.stdout.splitlines() if ln.startswith("RESULT ")]
    assert run.returncode == 0 and lines, f"child failed:\n{run.stdout}\n{run.stderr}"
    out = json.loads(lines[-1][len("RESULT "):])
    assert out["install"] == ["FINISHED"]
    assert "bl_ext.user_default.lantern" in out["addons"]
    assert out["lantern_file"].startswith(os.path.realpath(env["BLENDER_USER_EXTENSIONS"]))
    assert out["native"] is True
    assert "Lantern: could not start" not in run.stdout + run.stderr
    assert "render failed" not in run.stdout + run.stderr

    from multilayer import read_passes
    px = read_passes(exr)[("", "Combined")][..., :3]
    assert px.shape == (30, 40, 3)
    assert np.isfinite(px).all()
    # the corners see the world only: exactly its colour (a camera ray that misses)
    world = np.array(out["world"], dtype=np.float32)
    for corner in (px[0, 0], px[0, -1], px[-1, 0], px[-1, -1]):
        np.testing.assert_allclose(corner, world, rtol=1e-5)
    installed = np.load(seeds)
    np.testing.assert_array_equal(installed[0, ..., :3], px)   # the EXR, read another way
    _assert_same_renders("installed extension's F12 vs the checkout's, paired seeds",
                         installed, _checkout_f12s(tmp_path, range(EXT_SEEDS)))


# A farm worker: the extension was installed once (Preferences saved), then every frame is a
# fresh `blender -b file.blend -E LANTERN -f N` (tools/bpy_blender.py stands in for the binary
# and, like Blender, starts by loading the user's preferences). `lantern` stays hidden outside
# the extensions folder, so the checkout's add-on cannot stand in for the extension.
_INSTALL = _HIDE + textwrap.dedent(r'''
    import bpy
    zip_path, blend = sys.argv[1], sys.argv[2]
    bpy.ops.wm.read_factory_settings(use_empty=False)
    res = bpy.ops.extensions.package_install_files(filepath=zip_path, repo="user_default",
                                                   enable_on_install=True)
    assert res == {"FINISHED"}, res
    assert bpy.ops.wm.save_userpref() == {"FINISHED"}
    scene = bpy.context.scene
    scene.render.resolution_x, scene.render.resolution_y = 40, 30
    scene.render.resolution_percentage = 100
    scene.lantern.samples = 4
    scene.lantern.backend = "cpu"
    # an F12 of the frame the worker renders (seed 0), through bpy: what the worker must write
    # (the file keeps the factory engine: the worker's -E picks Lantern)
    engine, scene.render.engine = scene.render.engine, "LANTERN"
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = sys.argv[3]
    assert bpy.ops.render.render(write_still=True) == {"FINISHED"}
    import numpy as np
    image = bpy.data.images.load(sys.argv[3])
    w, h = image.size
    px = np.empty(w * h * 4, np.float32)
    image.pixels.foreach_get(px)
    bpy.data.images.remove(image)
    np.save(sys.argv[4], px.reshape(h, w, 4)[::-1])
    scene.render.image_settings.file_format = "PNG"  # the command line asks for EXR
    scene.render.image_settings.color_depth = "8"    # PNG's default (so -F gives a full EXR)
    scene.render.engine = engine
    bpy.ops.wm.save_as_mainfile(filepath=blend)
    world = scene.world.node_tree.nodes["Background"].inputs
    print("RESULT " + json.dumps([c * world["Strength"].default_value
                                  for c in world["Color"].default_value[:3]]))
''')
_WORKER = _HIDE + textwrap.dedent(r'''
    import runpy
    script = sys.argv[1]
    sys.argv = [script] + sys.argv[2:]
    runpy.run_path(script, run_name="__main__")
''')


def test_installed_extension_renders_headless(extension_zip, tmp_path):
    env = _user_env(tmp_path)
    blend = tmp_path / "farm.blend"
    f12 = tmp_path / "install_f12.npy"
    run = subprocess.run([sys.executable, "-c", _INSTALL, str(extension_zip), str(blend),
                          str(tmp_path / "install_f12.exr"), str(f12)],
                         cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    lines = [ln for ln in run.stdout.splitlines() if ln.startswith("RESULT ")]
    assert run.returncode == 0 and lines, f"install failed:\n{run.stdout}\n{run.stderr}"
    world = np.array(json.loads(lines[-1][len("RESULT "):]), dtype=np.float32)

    which = ("import lantern, os; print('LANTERN_FILE', os.path.realpath(lantern.__file__)); "
             "print('ENGINE', bpy.context.scene.render.engine)")
    out = tmp_path / "frame_####"
    run = subprocess.run([sys.executable, "-c", _WORKER, str(ROOT / "tools/bpy_blender.py"),
                          "-b", str(blend), "-E", "LANTERN", "-o", str(out), "-F", "OPEN_EXR",
                          "--python-exit-code", "3", "--python-expr", which, "-f", "1"],
                         cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
    text = run.stdout + run.stderr
    assert run.returncode == 0, f"worker failed:\n{text}"
    files = [ln.split(" ", 1)[1] for ln in run.stdout.splitlines()
             if ln.startswith("LANTERN_FILE ")]
    assert files and files[0].startswith(os.path.realpath(env["BLENDER_USER_EXTENSIONS"])), text
    assert "ENGINE LANTERN" in run.stdout
    assert "Lantern: could not start" not in text and "render failed" not in text

    from multilayer import read_passes
    px = read_passes(tmp_path / "frame_0001.exr")[("", "Combined")][..., :3]
    assert px.shape == (30, 40, 3)
    assert np.isfinite(px).all()
    for corner in (px[0, 0], px[0, -1], px[-1, 0], px[-1, -1]):  # camera rays that miss
        np.testing.assert_allclose(corner, world, rtol=1e-5)
    # the frame is the installed core's F12 of the same file and seed, bit for bit (that core
    # test_installed_extension_renders_f12 checks against the checkout's; was: the centre
    # brighter than the world and its std above 0.01)
    np.testing.assert_array_equal(px, np.load(f12)[..., :3])
