"""Soft falloff decides what a point light with a radius is (docs/lvc_notes.md): off, a sphere
light; on (Blender's default), a disk facing each receiver. bdpt, lvc and cis start light paths
on both (a soft light's from its centre, integrator/soft_light_path.h; through homogeneous media,
soft_light_medium.h), except on soft lights in scenes with a heterogeneous medium, which they
light from the camera side only, and the session says so (test_soft_light_media.py)."""

import pytest

import lantern
from lantern import scenes

pytestmark = pytest.mark.skipif(not lantern.native_available(), reason="native core not built")


def _session(soft, integrator):
    scene = scenes.fixture_box(16, 16)
    scene.lights[0]["soft_falloff"] = soft
    s = lantern.Session(scene, integrator=integrator, spp_per_iteration=1, backend="cpu")
    s.step()
    return s


@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis"])
def test_sphere_light_starts_light_paths(integrator):
    s = _session(False, integrator)
    assert s.stats["cache_vertices"] > 0 and s.stats["rays_light"] > 0
    assert not any("soft falloff" in w for w in s.warnings)


@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis"])
def test_soft_falloff_light_starts_light_paths(integrator):
    s = _session(True, integrator)
    assert s.stats["cache_vertices"] > 0 and s.stats["rays_light"] > 0
    assert not any("soft falloff" in w for w in s.warnings)


@pytest.mark.parametrize("integrator", ["bdpt", "lvc", "cis"])
def test_soft_falloff_light_in_homogeneous_media_starts_light_paths(integrator):
    """Through homogeneous media too (integrator/soft_light_medium.h); heterogeneous media keep
    them camera-side and say so (test_soft_light_media.py)."""
    scene = scenes.fixture_box(16, 16)
    scene.lights[0]["soft_falloff"] = True
    scene.world["volume"] = {"sigma_s": [0.01] * 3, "sigma_a": [0.0] * 3}
    s = lantern.Session(scene, integrator=integrator, spp_per_iteration=1, backend="cpu")
    s.step()
    assert s.stats["cache_vertices"] > 0 and s.stats["rays_light"] > 0
    assert not any("soft falloff" in w for w in s.warnings)


def test_pt_is_not_warned():
    assert not any("soft falloff" in w for w in _session(True, "pt").warnings)
