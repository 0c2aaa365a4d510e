"""A volume boundary in the plane of an opaque face (scene/medium_inset.cpp): a fog box standing
on the Cornell box's floor, its bottom face in the floor's plane, must render as the same fog box
reaching below the floor (where no ray goes: the two scenes are one in expectation). Before the
inset, a ray that met the boundary first was restarted past it and past the floor, into the space
below, and the floor read dark in blotches (a Blender scene of this kind read 10 % dark against
Cycles). pt and lt (both cross boundaries by restarting the ray), with the project's agreement
test and its negative controls."""
import numpy as np
import pytest

import lantern
from lantern import metrics, scenes
from lantern.scenes import aabb_mesh

SIZE = 32
K = 8
SPP = 128


def fog_on_floor(bottom):
    """The Cornell box (no inner boxes) with a scattering fog box whose bottom is at z = bottom
    (the floor's plane is z = 0)."""
    scene = scenes.cornell_box(SIZE, SIZE, boxes=False)
    m = scene.add_material("fog")
    scene.materials[m]["volume"] = {"sigma_s": [0.8, 0.8, 0.8], "sigma_a": [0.05, 0.1, 0.2]}
    scene.materials[m]["volume_only"] = True
    p, idx = aabb_mesh((-0.8, -0.8, bottom), (0.8, 0.8, 1.2))
    scene.add_mesh(p, idx, material=m, name="fog")
    return scene


def renders(scene, integrator, seed0):
    out = []
    for k in range(K):
        s = lantern.Session(scene, integrator=integrator, seed=seed0 + k, backend="cpu",
                            max_depth=8, spp_per_iteration=SPP // 2, threads=1)
        s.step()
        s.step()
        assert not any("rendering with pt" in w for w in s.warnings), s.warnings
        out.append(np.asarray(s.image())[..., :3])
    return out


@pytest.mark.parametrize("integrator", ["pt", "lt"])
def test_fog_box_on_the_floor_renders_as_one_through_it(core, integrator):
    on = renders(fog_on_floor(0.0), integrator, 100)
    below = renders(fog_on_floor(-0.3), integrator, 500)
    metrics.assert_agreement(f"fog on the floor vs through it ({integrator})", on, below,
                             block=8, image_bias=0.02, block_bias=0.08)
