"""Renders of independent seeds for the tests that compare sets of them (test_cis_camera_parity,
test_cis_direct_light): one Session step of `spp` samples per seed."""
import lantern


def render_once(scene, integrator, seed, spp, **settings):
    """The image of one Session step of `spp` samples with `seed`."""
    s = lantern.Session(scene, integrator=integrator, seed=seed, spp_per_iteration=spp,
                        **settings)
    s.step()
    return s.image()


def render_seeds(scene, integrator, seeds, spp, **settings):
    """render_once for each seed of `seeds`."""
    return [render_once(scene, integrator, seed, spp, **settings) for seed in seeds]
