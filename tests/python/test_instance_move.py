"""Session.move_instance (instancing=True): a mesh moved in a running session renders as a fresh
session of the moved scene (statistically: another accelerator layout and rounding of the moved
vertices), on the built-in BVH and on Embree, without a bottom-level BVH build; what it cannot
move in place it refuses, and the session goes on."""
import copy

import numpy as np
import pytest

from lantern import metrics, scenes, session

pytestmark = pytest.mark.skipif(not session.native_available(),
                                reason=f"lantern._core not built ({session.native_error()})")

BOX = 5  # the short box of the Cornell box
# 16 seeds of 8 spp at 32 x 32 (16 blocks): the samples of the 8 x 64 at 16 x 16 it took
# before. Paired seeds (tests/README.md): the moved session and the fresh render of the moved
# scene take the same seed, so they trace the same paths up to the rounding of the moved
# vertices and the accelerator's layout, and the comparison sees the spread of the per-seed
# differences, not the renders' noise (independent seeds resolved only 5 % / 15 % here)
K, SPP, SIZE = 16, 8, 32


def _matrix():
    """Rotation about z by 0.5 rad about the box's centre, scale (1.2, 0.9, 1.1), a lift."""
    c, s = np.cos(0.5), np.sin(0.5)
    centre = np.array([0.33, -0.3, 0.0])
    lin = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) @ np.diag([1.2, 0.9, 1.1])
    m = np.eye(4)
    m[:3, :3] = lin
    m[:3, 3] = centre - lin @ centre + np.array([-0.1, 0.05, 0.1])
    return m


def _moved(scene, m):
    """The scene with mesh BOX placed by m, as the add-on exports a moved object."""
    out = copy.deepcopy(scene)
    mesh = dict(out.meshes[BOX])
    p = mesh["positions"].astype(np.float64)
    mesh["positions"] = (p @ m[:3, :3].T + m[:3, 3]).astype(np.float32)
    if mesh.get("normals") is not None:
        n = mesh["normals"].astype(np.float64) @ np.linalg.inv(m[:3, :3])
        mesh["normals"] = (n / np.linalg.norm(n, axis=1, keepdims=True)).astype(np.float32)
    out.meshes[BOX] = mesh
    return out


def _accel(monkeypatch, accel):
    if accel == "embree" and not session.require_core().embree_available():
        pytest.skip("no Embree")
    monkeypatch.setenv("LANTERN_ACCEL", accel)


@pytest.mark.parametrize("accel", ["bvh", "embree"])
def test_moved_instance_renders_as_a_fresh_render_of_the_moved_scene(monkeypatch, accel):
    _accel(monkeypatch, accel)
    scene = scenes.cornell_box(width=SIZE, height=SIZE)
    m = _matrix()
    moved = _moved(scene, m)
    renders, fresh = [], []
    for k in range(K):
        s = session.Session(scene, backend="cpu", seed=100 + k, instancing=True, integrator="pt")
        assert any("built-in BVH" in w for w in s.warnings) == (accel == "bvh")
        s.step()
        builds = s.stats["accel_bottom_builds"]
        assert builds >= len(scene.meshes)  # one bottom level per mesh
        assert s.move_instance(BOX, m)
        assert s.spp == 0
        for _ in range(SPP):
            s.step()
        st = s.stats
        assert st["accel_bottom_builds"] == builds and st["instance_moves"] == 1
        renders.append(s.image().astype(np.float64))
        f = session.Session(moved, backend="cpu", seed=100 + k, integrator="pt")
        for _ in range(SPP):  # the same seed and steps: the same paths
            f.step()
        fresh.append(f.image().astype(np.float64))
    assert not all(np.array_equal(r, f) for r, f in zip(renders, fresh)), \
        "the moved and the fresh renders are the same bits: the pairing tests nothing"
    # paired: E[moved_k - fresh_k] = 0, as moved_k - fresh_k + mean(fresh) against mean(fresh)
    metrics.assert_agreement(f"moved box ({accel}) vs fresh render of the moved scene, "
                             "paired seeds", *metrics.paired_sets(renders, fresh), block=8)
    # and the move took effect: the unmoved scene's renders are told apart
    unmoved = [session.render(scene, spp=SPP // 4, backend="cpu", seed=300 + k, integrator="pt")
               .astype(np.float64) for k in range(K)]
    assert not metrics.compare_renders(renders, unmoved, block=8).passed


@pytest.mark.parametrize("accel", ["bvh", "embree"])
def test_moving_back_renders_the_given_scene_bit_for_bit(monkeypatch, accel):
    _accel(monkeypatch, accel)
    scene = scenes.cornell_box(width=12, height=12)
    s = session.Session(scene, backend="cpu", seed=7, instancing=True, integrator="pt")
    for _ in range(2):
        s.step()
    before = s.image()
    assert s.move_instance(BOX, _matrix())
    s.step()
    assert s.move_instance(BOX, np.eye(4))
    for _ in range(2):
        s.step()
    np.testing.assert_array_equal(s.image(), before)


def test_moves_that_reach_further_are_refused_and_the_session_goes_on():
    scene = scenes.cornell_box(width=8, height=8)
    s = session.Session(scene, backend="cpu", instancing=True, integrator="pt")
    s.step()
    mirror = np.diag([-1.0, 1.0, 1.0, 1.0])
    assert not s.move_instance(BOX, mirror)        # the winding would flip: export again
    assert not s.move_instance(BOX, np.zeros((4, 4)))  # singular
    far = np.eye(4)
    far[0, 3] = 10.0                               # out of the scene's bounding sphere
    assert not s.move_instance(BOX, far)
    nan = np.eye(4)
    nan[1, 1] = np.nan
    assert not s.move_instance(BOX, nan)
    with pytest.raises(ValueError):
        s.move_instance(BOX, np.eye(3))
    with pytest.raises(IndexError):
        s.move_instance(len(scene.meshes), np.eye(4))
    assert s.spp == 1 and s.stats["instance_moves"] == 0  # nothing changed
    s.step()
    assert s.spp == 2
    flat = session.Session(scene, backend="cpu", integrator="pt")  # instancing off: flat
    assert not flat.move_instance(BOX, _matrix())


def test_an_emitting_mesh_is_not_moved_in_place():
    scene = scenes.cornell_box(width=8, height=8)
    glowing = copy.deepcopy(scene)
    glowing.materials.append({"type": "diffuse", "base_color": [0.5, 0.5, 0.5],
                              "emission": [2.0, 2.0, 2.0]})
    mesh = dict(glowing.meshes[BOX])
    mesh["material_ids"] = np.full_like(mesh["material_ids"], len(glowing.materials) - 1)
    glowing.meshes[BOX] = mesh
    s = session.Session(glowing, backend="cpu", instancing=True, integrator="pt")
    assert not s.move_instance(BOX, _matrix())     # the lights would change: a new session
