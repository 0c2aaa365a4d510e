"""Hair on the render path (docs/curves.md): strands in the scene, both CPU ray-query structures,
pt's strand hits with the Principled Hair lobe and ordinary BSDFs, bad input.

- Hair furnace: white strands that absorb nothing and have no cuticle tilt (Offset 0) scatter
  all the light they get (bsdf/hair.h: albedo 1), so in a uniform white world of radiance 1
  every pixel, strand or not, is exactly 1 (max_depth 64 cuts a negligible tail). Measured
  (16 seeds x 64 spp, 16x16): image mean 1.00007 +- 0.0006. Its negative control, absorption
  0.05 per radius, must fail the same comparison.
- Embree's ROUND_LINEAR_CURVE geometry against the built-in curve BVH on a fur ball (pt, the
  same seeds: paired, tests/README.md), hair and Principled BSDF on the strands."""
import numpy as np
import pytest

import lantern
from lantern import metrics
from lantern.scenes_hair import fur_ball, fur_strands, hair_furnace

K = 16


def render(scene, seed, spp, max_depth=64, integrator="pt"):
    s = lantern.Session(scene, integrator=integrator, seed=seed, backend="cpu",
                        max_depth=max_depth, spp_per_iteration=spp)
    s.step()
    return np.asarray(s.image(), np.float64), s.warnings


def furnace_renders(**kw):
    return [render(hair_furnace(**kw), seed=k, spp=64)[0] for k in range(K)]


def test_hair_furnace_is_exactly_the_world(core):
    imgs = furnace_renders()
    metrics.assert_agreement("hair furnace (pt)", imgs, [1.0] * 3, block=4, se_floor=1e-6)


def test_hair_furnace_sees_absorption(core):
    """Negative control: strands absorbing 0.05 per radius darken the same comparison."""
    scene = hair_furnace()
    scene.materials[0]["absorption"] = [0.05] * 3
    imgs = [render(scene, seed=k, spp=64)[0] for k in range(K)]
    res = metrics.compare_renders(imgs, [1.0] * 3, block=4, se_floor=1e-6)
    print(res)
    assert not res.passed


@pytest.mark.parametrize("material", ["hair", "principled"])
def test_embree_and_builtin_bvh_agree_on_fur(core, monkeypatch, material):
    if not core.embree_available():
        pytest.skip(f"no Embree to compare against ({core.embree_version()})")
    kind = {} if material == "hair" else {"material_type": "principled"}
    out = {}
    for accel in ("embree", "bvh"):
        monkeypatch.setenv("LANTERN_ACCEL", accel)
        out[accel] = [render(fur_ball(24, 24, **kind), seed=10 + k, spp=8, max_depth=8)[0]
                      for k in range(K)]
    assert all(np.isfinite(r).all() for r in out["bvh"])
    metrics.assert_agreement(f"fur ({material}) bvh vs embree, paired seeds",
                             *metrics.paired_sets(out["bvh"], out["embree"]), block=8)


def test_strands_are_seen_and_cast_shadows(core):
    """The fur changes the image where it is (against the bare ball), and a strand set with
    visible_camera and cast_shadow off leaves the camera's view of the ball untouched."""
    bare = fur_ball(24, 24)
    bare.curves = []
    furry, _ = render(fur_ball(24, 24), 1, 16, max_depth=8)
    plain, _ = render(bare, 1, 16, max_depth=8)
    assert np.abs(furry - plain).mean() > 0.02
    hidden = fur_ball(24, 24)
    hidden.curves[0]["visible_camera"] = False
    hidden.curves[0]["cast_shadow"] = False
    seen, _ = render(hidden, 1, 16, max_depth=1)   # camera rays and direct light only
    ref, _ = render(bare, 1, 16, max_depth=1)
    np.testing.assert_allclose(seen, ref, rtol=1e-5, atol=1e-6)


def test_other_integrators_keep_hair_and_cuda_takes_it(core):
    """lt, bdpt, lvc and cis render strands with Principled Hair themselves (test_hair_bidir.py;
    strands with another material still go to pt there), and so may auto; the CUDA backend
    traces strands too (accel/scene_query.h on the device)."""
    scene = fur_ball(8, 8, num_strands=20)
    for integ in ("bdpt", "lvc", "cis", "lt"):
        _, w = render(scene, 1, 1, max_depth=4, integrator=integ)
        assert not any("rendering with pt" in x for x in w), w
    s = lantern.Session(scene, integrator="auto", backend="cpu", seed=1)
    assert not any("path tracing" in x and "strands" in x for x in s.warnings), s.warnings
    # no strand hand-over for the CUDA backend any more; without a GPU here the session says
    # only that none is available
    s = lantern.Session(scene, integrator="pt", backend="cuda", seed=1)
    assert not any("does not trace strands" in x for x in s.warnings), s.warnings
    if not lantern._core.cuda_info()["available"]:
        assert s.backend == "cpu"
        assert any("CUDA backend is not available" in x for x in s.warnings), s.warnings


def test_bad_strands(core):
    """NaN, negative and zero radii: the bad points' segments are left out with a message, the
    zero ones silently (no surface, as Cycles); the image stays finite. Offsets that do not
    index the points are refused."""
    scene = fur_ball(8, 8, num_strands=30)
    rad = scene.curves[0]["radius"]
    rad[:5] = np.nan
    rad[5:10] = -1.0
    rad[10:20] = 0.0
    img, w = render(scene, 1, 4, max_depth=4)
    assert np.isfinite(img).all()
    assert any("NaN, infinite or negative radius" in x for x in w), w
    pts, r, off = fur_strands(4, keys=3)
    with pytest.raises(ValueError, match="offsets"):
        lantern.Scene().add_curves(pts, r, off[::-1].copy())
    with pytest.raises(ValueError, match="radius"):
        lantern.Scene().add_curves(pts, r[:-1], off)


def test_scene_file_keeps_strands_and_hair(core, tmp_path):
    scene = fur_ball(8, 8, num_strands=10)
    path = tmp_path / "fur.lantern"
    scene.save(path)
    back = lantern.load_scene(path)
    assert len(back.curves) == 1
    for key in ("points", "radius", "offsets", "material_ids"):
        np.testing.assert_array_equal(back.curves[0][key], scene.curves[0][key])
    assert back.materials[1]["type"] == "hair"
    assert back.materials[1]["hair_parametrization"] == "melanin"
    a, _ = render(scene, 3, 2, max_depth=4)
    b, _ = render(back, 3, 2, max_depth=4)
    np.testing.assert_array_equal(a, b)


def test_strand_memory_checked_from_the_counts(core):
    """Under a 1.5 GiB address-space limit, 8 million segments (about 1.3 GiB once built) are
    refused from their counts with what they need, before anything is built; the points
    themselves (100 MB) fit."""
    import json
    import subprocess
    import sys
    import textwrap
    code = textwrap.dedent("""
        import json, resource, numpy as np, lantern
        from lantern.scenes_hair import fur_ball
        s = fur_ball(8, 8, num_strands=4)
        n = 8_000_000
        s.curves[0].update(points=np.zeros((n + 1, 3), np.float32),
                           radius=np.full(n + 1, 0.01, np.float32),
                           offsets=np.array([0, n + 1], np.uint32),
                           material_ids=np.zeros(1, np.uint32))
        vm = [int(l.split()[1]) * 1024 for l in open("/proc/self/status")
              if l.startswith("VmSize")][0]
        soft, hard = resource.getrlimit(resource.RLIMIT_AS)
        resource.setrlimit(resource.RLIMIT_AS, (vm + (1536 << 20), hard))
        try:
            lantern.Session(s, backend="cpu", threads=1, integrator="pt")
            print(json.dumps("built"))
        except ValueError as e:
            print(json.dumps(str(e)))
    """)
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr[-2000:]
    msg = json.loads(r.stdout.strip().splitlines()[-1])
    assert "strands (8000000 segments) need" in msg, msg


def test_passes_see_strands(core):
    """The passes (integrator/aov.cpp) shade strand hits: the fur's Depth lies in front of the
    bare ball's where strands cover it, every pass stays finite."""
    from lantern.aov import render_aovs
    furry = render_aovs(fur_ball(16, 16), spp=4, threads=1)
    bare_scene = fur_ball(16, 16)
    bare_scene.curves = []
    bare = render_aovs(bare_scene, spp=4, threads=1)
    for name, img in furry.items():
        assert np.isfinite(img).all(), name
    depth_key = next(k for k in furry if "depth" in k.lower())
    assert (furry[depth_key] < bare[depth_key] - 1e-3).mean() > 0.05
