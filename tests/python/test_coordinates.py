"""Coordinates and sizes at the edge of what the core takes (issue 12): a camera or light 2e19 m
away (Embree asserted on ray origins beyond 1.844e18 and killed the process), a scene scaled by
1e19, triangles with 1e10 m edges (dropped as "degenerate" by a float overflow), a film too
large for memory. Every case: a warning or a clear error naming what and why, and an exact
image where one is known. Renders that aborted before run in a child process, once per CPU
accelerator (Embree and the built-in BVH)."""

import json
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import lantern
from lantern import Scene, Session, native_available
from lantern.scenes import cornell_box

pytestmark = pytest.mark.skipif(not native_available(), reason="lantern._core not built")

INTEGRATORS = ("pt", "bdpt", "lvc", "cis")  # lt: see test_far_camera_light_tracing


def child(code, accel="embree", timeout=180):
    """Runs `code` in a fresh interpreter with LANTERN_ACCEL=accel; returns its last stdout line
    parsed as JSON (the child prints one)."""
    import os
    env = dict(os.environ, LANTERN_ACCEL=accel)
    r = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True,
                       text=True, timeout=timeout, env=env)
    assert r.returncode == 0, f"child died ({r.returncode}): {r.stderr[-2000:]}"
    return json.loads(r.stdout.strip().splitlines()[-1])


FAR_WALL = """
    import json, numpy as np, lantern
    from lantern import Scene
    D, H = {distance}, 1e11        # a 2e11 m emissive wall seen from D, filling the view
    s = Scene(); s.film.update(width=8, height=8)
    s.look_at((0, -D, 0), (0, 0, {target}), up=(0, 0, 1),
              fov=float(np.degrees(2 * np.arctan(0.5 * H / D))))
    s.camera["clip"] = [1.0, 1e30]
    s.world["color"] = {world}
    m = s.add_material("glow", base_color=(0.5, 0.5, 0.5), emission=(2.0, 2.0, 2.0))
    pos = np.array([[-H, 0, -H], [H, 0, -H], [H, 0, H], [-H, 0, H]], np.float32)
    s.add_mesh(pos, np.array([[0, 1, 2], [0, 2, 3]], np.uint32), material=m, name="wall")
    out = {{}}
    for integ in {integrators}:
        ses = lantern.Session(s, integrator=integ, threads=2, backend="cpu", spp_per_iteration=2)
        ses.step()
        img = ses.image().astype(float)
        out[integ] = [bool(np.isfinite(img).all()), img.min(axis=(0, 1)).tolist(),
                      img.max(axis=(0, 1)).tolist(), ses.warnings]
    print(json.dumps(out))
"""


@pytest.mark.parametrize("accel", ["embree", "bvh"])
def test_far_camera_sees_the_scene(accel):
    """A camera 2e19 m away with a narrow view of a large emissive wall: a warning that names
    the camera and the limit, and every pixel the wall's radiance, 2, exactly (camera rays start
    where they reach the scene's bounds)."""
    if accel == "embree" and not lantern.session.require_core().embree_available():
        pytest.skip("Embree is not available")
    out = child(FAR_WALL.format(distance=2e19, target=0.0, integrators=INTEGRATORS,
                                  world=[0.0] * 3), accel)
    for integ, (finite, lo, hi, warnings) in out.items():
        assert finite, integ
        assert lo == [2.0] * 3 and hi == [2.0] * 3, (integ, lo, hi)
        assert any("the camera is 2e+19 m from the origin" in w for w in warnings), warnings


def test_far_camera_looking_past_the_scene_sees_the_world():
    """The same camera turned off the wall: the world colour exactly, in every pixel."""
    out = child(FAR_WALL.format(distance=2e19, target=1e19, integrators=INTEGRATORS,
                                  world=[0.25, 0.5, 0.75]))
    for integ, (finite, lo, hi, warnings) in out.items():
        assert finite and lo == hi == [0.25, 0.5, 0.75], (integ, lo, hi)


def test_far_camera_light_tracing():
    """Light tracing (the reference integrator "lt") cannot connect to a camera 2e19 m away (the
    squared distance overflows float): a finite, black image and the warning, never a crash."""
    out = child(FAR_WALL.format(distance=2e19, target=0.0, integrators=("lt",),
                                  world=[0.0] * 3))
    finite, lo, hi, warnings = out["lt"]
    assert finite and lo == hi == [0.0] * 3
    assert any("the camera" in w for w in warnings)


def test_far_light_is_left_out_by_name():
    """A light 2e19 m away is left out with a warning naming it; the image is bit for bit the
    image without it (it would add less than 1e-36 of its power per square metre)."""
    base = cornell_box(width=8, height=8)
    far = cornell_box(width=8, height=8)
    far.add_light("point", position=[0.0, -2e19, 1.0], power=[1e3] * 3, radius=0.1,
                  name="Far Lamp")
    far.add_light("area", to_world=[[1, 0, 0, 3e19], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]],
                  size=[1.0, 1.0], power=[1e3] * 3)
    for integ in ("pt", "cis"):
        a = Session(base, integrator=integ, threads=2, backend="cpu")
        b = Session(far, integrator=integ, threads=2, backend="cpu")
        a.step()
        b.step()
        assert b.image().tobytes() == a.image().tobytes()
        assert "light 'Far Lamp' is 2e+19 m from the origin" in " ".join(b.warnings)
        assert "light 2 (area) is 3e+19 m from the origin" in " ".join(b.warnings)


def test_scene_scaled_by_1e19():
    """Everything 1e19 times larger: each mesh named as left out, the lights too; a finite image
    of the world colour, and no crash (Embree asserted on the camera rays)."""
    out = child("""
        import json, numpy as np, lantern
        from lantern.scenes import cornell_box
        s = cornell_box(width=8, height=8)
        s.world["color"] = [0.1, 0.2, 0.3]
        for m in s.meshes:
            m["positions"] = (np.asarray(m["positions"], np.float64) * 1e19).astype(np.float32)
        for l in s.lights:
            t = np.array(l["to_world"], np.float64); t[:3, 3] *= 1e19; l["to_world"] = t.tolist()
        c = np.array(s.camera["to_world"], np.float64); c[:3, 3] *= 1e19
        s.camera["to_world"] = c.tolist()
        s.camera["clip"] = [1.0, 1e30]
        out = {"meshes": [m["name"] for m in s.meshes]}
        for integ in ("pt", "cis"):
            ses = lantern.Session(s, integrator=integ, threads=2, backend="cpu")
            ses.step()
            img = ses.image().astype(float)
            out[integ] = [bool(np.isfinite(img).all()), img.min(axis=(0, 1)).tolist(),
                          img.max(axis=(0, 1)).tolist(), ses.warnings]
        print(json.dumps(out))
    """)
    for integ in ("pt", "cis"):
        finite, lo, hi, warnings = out[integ]
        world = [float(np.float32(v)) for v in (0.1, 0.2, 0.3)]
        assert finite and lo == hi == world, (integ, lo, hi)
        text = " ".join(warnings)
        for name in out["meshes"]:
            assert f"mesh '{name}': " in text and "they were left out" in text, name
        assert "light 0 (area) is" in text and "the camera is" in text


def test_mesh_partly_beyond_the_limit():
    s = cornell_box(width=8, height=8)
    tri = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [5e18, 0, 0], [5e18, 1, 0], [5e18, 0, 1]],
                   np.float32)
    s.add_mesh(tri, np.array([[0, 1, 2], [3, 4, 5]], np.uint32), material=0, name="Straddle")
    w = " ".join(Session(s, backend="cpu", threads=1).warnings)
    assert "mesh 'Straddle': 1 of 2 triangle(s) reach 5e+18 m from the origin" in w


def _sunlit_triangle(edge, emission=(0.0, 0.0, 0.0), sun=True):
    s = Scene()
    s.film.update(width=8, height=8)
    s.look_at((0, 0, edge / 10), (0, 0, 0), up=(0, 1, 0), fov=30)
    s.camera["clip"] = [1.0, edge * 100]
    m = s.add_material("white", base_color=(0.8, 0.8, 0.8), emission=emission)
    pos = np.array([[-edge, -edge, 0], [edge, -edge, 0], [0, edge, 0]], np.float32)
    s.add_mesh(pos, np.array([[0, 1, 2]], np.uint32), material=m, name="Huge")
    if sun:
        s.add_light("sun", direction=[0, 0, -1], strength=[3.0, 3.0, 3.0], angle=0.0)
    return s


@pytest.mark.parametrize("integrator", ["pt", "cis"])
def test_triangle_with_1e10_m_edges_renders_exactly(integrator):
    """Edges of 2e10 m: kept (the area test is in double) and shaded with a true normal. Lit
    straight down by a sun of 3 W/m^2, a white diffuse (0.8) surface is 0.8 * 3 / pi in every
    pixel; unlit but emitting 2 (its area, 2e20 m^2, in the light tables), it is 2. No
    "degenerate" warning."""
    for emission, sun, expected in ((0.0, True, 0.8 * 3 / np.pi), (2.0, False, 2.0)):
        s = Session(_sunlit_triangle(1e10, (emission,) * 3, sun), integrator=integrator,
                    threads=2, backend="cpu", max_depth=2, spp_per_iteration=2)
        s.step()
        img = s.image()
        np.testing.assert_allclose(img, expected, rtol=1e-5)
        assert not any("degenerate" in w for w in s.warnings), s.warnings


def test_triangle_beyond_the_float_tests_is_named():
    """Edges past 1e12 m: the float ray-triangle tests overflow (measured: 2.2e13 m missed by
    both accelerators), so the triangle is named in a warning, not silently lost."""
    s = Session(_sunlit_triangle(1e13), backend="cpu", threads=1)
    w = " ".join(s.warnings)
    assert "mesh 'Huge': 1 triangle(s) with edges up to 2.24e+13 m" in w
    assert "rays may miss them" in w
    s.step()
    assert np.isfinite(s.image()).all()


# ---- A film too large for memory ----

def test_film_too_large_is_refused_before_allocation():
    need = 65536 * 65536 * lantern.session.FILM_BYTES_PER_PIXEL
    if need <= 0.5 * lantern.session.memory_limit_bytes():
        pytest.skip("this machine could hold a 65536x65536 film")
    scene = cornell_box(width=8, height=8)
    scene.film.update(width=65536, height=65536)
    with pytest.raises(ValueError, match=r"a 65536x65536 film needs 240\.0 GiB .*lower the "):
        Session(scene, backend="cpu", threads=1, integrator="pt")
    native = cornell_box(width=8, height=8).to_native()
    native["film"].update(width=65536, height=65536)
    core = lantern.session.require_core()
    with pytest.raises(ValueError, match=r"65536x65536 film needs 240\.0 GiB"):
        core.Session(native, {"backend": "cpu", "threads": 1})


def test_film_checked_against_the_address_space_limit():
    """Under a 1.5 GiB address-space limit an 8192x8192 film (3.8 GiB of buffers) is refused
    with what it needs, by Session and by the native core, instead of a bad_alloc."""
    out = child("""
        import json, resource, lantern
        from lantern.scenes import cornell_box
        vm = [int(l.split()[1]) * 1024 for l in open("/proc/self/status")
              if l.startswith("VmSize")][0]
        soft, hard = resource.getrlimit(resource.RLIMIT_AS)
        resource.setrlimit(resource.RLIMIT_AS, (vm + (1536 << 20), hard))
        s = cornell_box(width=8192, height=8192)
        out = []
        try:
            lantern.Session(s, backend="cpu", threads=1)
        except ValueError as e:
            out.append(str(e))
        n = cornell_box(width=8, height=8).to_native()
        n["film"].update(width=8192, height=8192)
        try:
            lantern.session.require_core().Session(n, {"backend": "cpu", "threads": 1})
        except ValueError as e:
            out.append(str(e))
        print(json.dumps(out))
    """)
    assert len(out) == 2, out
    for msg in out:
        assert msg.startswith("a 8192x8192 film needs 3.8 GiB for its buffers"), msg


def test_non_finite_input_straight_to_the_native_core():
    """Input that the Python checks would refuse, given to _core.Session directly: NaN and
    infinite light positions, camera matrices and vertices. Each is a ValueError or a finite
    image; none reaches Embree's assert (the child would die)."""
    out = child("""
        import json, numpy as np, lantern
        from lantern.scenes import cornell_box
        core = lantern.session.require_core()
        nan, inf = float("nan"), float("inf")

        def light_pos(n):
            n["lights"].append({"type": "point", "position": [nan, 0.0, 1.0],
                                "power": [10.0] * 3, "radius": 0.0, "soft_falloff": False})
        def light_inf(n):
            n["lights"].append({"type": "point", "position": [0.0, inf, 1.0],
                                "power": [10.0] * 3, "radius": 0.0, "soft_falloff": False})
        def camera_nan(n):
            n["camera"]["to_world"] = np.full((4, 4), nan, np.float32)
        def camera_far(n):
            m = n["camera"]["to_world"].copy(); m[:3, 3] = [3e38, -3e38, 3e38]
            n["camera"]["to_world"] = m
        def vertices(n):
            p = n["meshes"][0]["positions"].copy(); p[0] = [1e30, nan, -inf]
            n["meshes"][0]["positions"] = p
        def sun_nan(n):
            n["lights"].append({"type": "sun", "direction": [nan, nan, nan],
                                "strength": [1.0] * 3, "angle": 0.1})
        out = {}
        for case in (light_pos, light_inf, camera_nan, camera_far, vertices, sun_nan):
            for integ in ("pt", "bdpt", "cis", "lt"):
                n = cornell_box(width=8, height=8).to_native()
                case(n)
                try:
                    s = core.Session(n, {"backend": "cpu", "threads": 2, "integrator": integ})
                    s.step()
                    out[case.__name__ + "/" + integ] = bool(np.isfinite(s.image()).all())
                except ValueError as e:
                    out[case.__name__ + "/" + integ] = "ValueError: " + str(e)
        print(json.dumps(out))
    """)
    assert len(out) == 24
    for case, result in out.items():
        assert result is True or str(result).startswith("ValueError"), (case, result)
