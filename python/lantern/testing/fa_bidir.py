"""False-alarm families of tests/python/test_bidirectional.py that false_alarm.py's own
families (cross: Cornell bdpt vs pt; fixture: lvc vs bdpt and cis(bsdf) vs lvc; scale: 1e-3;
analytic: the furnace in pt at other settings) leave out. Loaded by false_alarm.py
(load_family_modules); run as

    PYTHONPATH=python nice python -m lantern.testing.false_alarm --trials 20 --families bidir_scenes

Each family calls the test's own scenes, renders() and rule (compare_renders with block 8, as
check_agreement / check_paired), each trial with its own seeds; where a row says "cheaper" the
samples per seed are cut (the seeds, the shared reference and the rule stay the test's), which
changes the noise, not the null distribution:
- bidir_scenes: test_integrators_agree on cornell, glossy, principled, features, coat_normal
  (pt reference) and glass (bdpt reference), all six bidirectional variants against the one
  reference of the trial; cheaper: the reference 16 x REF_SPP, the others 16 x SPP;
- bidir_lights: test_delta_lights_agree (point over metal, sharp sun; bdpt, cis),
  test_world_light_agrees (bdpt, cis), test_soft_falloff_lights_agree (cis),
  test_sun_caustic_on_metal_matches_light_tracing (cis vs lt), all cheaper by LIGHTS_CUT;
  test_cache_budget_splits_the_iteration (16 x 16 spp a side where the test takes 64) and
  test_scale_invariance's 1e4 (paired, the test's settings);
- bidir_fixture: the rest of the fixture chain (_fixture_chain: lvc sorted, cis, cis unsorted
  against lvc, paired seeds), 16 x 16 spp as false_alarm.py's fixture family;
- bidir_analytic: test_furnace (pt and the six bidirectional variants) and
  test_integrating_sphere (pt, lt and the six) against their exact values, the tests' settings.
"""
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT / "tests" / "python"))

from lantern import metrics  # noqa: E402

REF_SPP, SPP = 64, 8   # bidir_scenes: the test's 512 (pt) / 256 (bdpt) and 64, cut by 8
LIGHTS_CUT = 8         # bidir_lights: the tests' samples per seed over this


def _tb():
    import test_bidirectional as tb
    return tb


def pairs_bidir_scenes(trial):
    tb = _tb()
    seed0 = 1000 * trial + 3000000
    for scene_name in ("cornell", "glossy", "principled", "features", "coat_normal", "glass"):
        ref_name = tb.REFERENCE.get(scene_name, "pt")
        cache = {}

        def ref(scene_name=scene_name, ref_name=ref_name, cache=cache):
            if "ref" not in cache:
                spp = REF_SPP if ref_name == "pt" else REF_SPP // 2  # the test: 512 / 256
                cache["ref"] = tb.renders(tb.SCENES[scene_name](), ref_name, spp, seed0)
            return cache["ref"]
        for i, (integrator, settings) in enumerate(tb.BIDIRECTIONAL):
            if integrator == ref_name and not settings:
                continue

            def run(scene_name=scene_name, integrator=integrator, settings=settings, i=i,
                    ref=ref):
                r = tb.renders(tb.SCENES[scene_name](), integrator, SPP, seed0 + 100 * (i + 1),
                               **settings)
                return r, ref(), {"block": 8}
            yield (f"{scene_name} {integrator} {settings} vs {ref_name} "
                   "(test_integrators_agree)", run)


def pairs_bidir_lights(trial):
    tb = _tb()
    seed0 = 1000 * trial + 3100000
    cut = LIGHTS_CUT
    cases = [(f"delta {name}", scene) for name, scene in tb.delta_light_scenes().items()]
    cases.append(("world light", tb.world_light_scene()))
    for j, (name, scene) in enumerate(cases):
        cache = {}

        def pt(scene=scene, cache=cache, j=j):
            if "pt" not in cache:
                cache["pt"] = tb.renders(scene, "pt", tb.SPP_REF["pt"] // cut, seed0 + 100 * j)
            return cache["pt"]
        for integrator in ("bdpt", "cis"):
            def run(scene=scene, integrator=integrator, pt=pt, j=j):
                other = tb.renders(scene, integrator, 64 // cut,
                                   seed0 + 100 * j + (10 if integrator == "bdpt" else 30))
                return other, pt(), {"block": 8}
            yield f"{name} {integrator} vs pt (test_bidirectional)", run

    def soft():
        scene = tb.soft_falloff_scene()
        return (tb.renders(scene, "cis", 64 // cut, seed0 + 400),
                tb.renders(scene, "pt", tb.SPP_REF["pt"] // cut, seed0 + 450), {"block": 8})
    yield "soft falloff cis vs pt (test_bidirectional)", soft

    def caustic():
        scene = tb.sun_caustic_scene()
        return (tb.renders(scene, "cis", 128 // cut, seed0 + 500),
                tb.renders(scene, "lt", 1024 // cut, seed0 + 550), {"block": 8})
    yield "sun caustic cis vs lt (test_bidirectional)", caustic

    def split():
        imgs, whole = tb.cache_split_renders(seed0 + 600, seed0 + 650, spp=16)
        return imgs, whole, {"block": 8}
    yield "cache split into passes vs whole, cis cornell (test_bidirectional)", split

    def scale():
        ref = tb.renders(tb.scenes.glossy_box(tb.SIZE, tb.SIZE), "cis", 8, seed0 + 700)
        scaled = tb.renders(tb._scaled(tb.scenes.glossy_box(tb.SIZE, tb.SIZE), 1e4), "cis", 8,
                            seed0 + 700)
        return (*metrics.paired_sets(scaled, ref), {"block": 8})
    yield "scale invariance 1e4, paired seeds, glossy cis (test_scale_invariance)", scale


def pairs_bidir_fixture(trial):
    """_fixture_chain's comparisons false_alarm.py's fixture family leaves out: lvc sorted,
    cis (sorted), cis unsorted against lvc on the same seeds, 16 x 16 spp (the test: 64)."""
    tb = _tb()
    seed0 = 1000 * trial + 3200000
    cache = {}

    def lvc():
        if "lvc" not in cache:
            cache["lvc"] = tb.renders(tb.scenes.fixture_box(tb.SIZE, tb.SIZE), "lvc", 16, seed0)
        return cache["lvc"]
    for integrator, settings in tb.BIDIRECTIONAL:
        if (integrator in ("bdpt", "lvc") and not settings) or "cis_target" in settings:
            continue

        def run(integrator=integrator, settings=settings):
            r = tb.renders(tb.scenes.fixture_box(tb.SIZE, tb.SIZE), integrator, 16, seed0,
                           **settings)
            return (*metrics.paired_sets(r, lvc()), {"block": 8})
        yield f"fixture {integrator} {settings} vs lvc, paired seeds (_fixture_chain)", run


def pairs_bidir_analytic(trial):
    tb = _tb()
    seed0 = 1000 * trial + 3300000
    for j, (integrator, settings) in enumerate(tb.ALL):
        if integrator == "lt":
            continue  # test_furnace skips it

        def furnace(integrator=integrator, settings=settings, j=j):
            scene, expected = tb.furnace_case()
            return (tb.analytic_renders(scene, integrator, settings, seed0 + 50 * j),
                    expected, {"block": 8})
        yield f"furnace {integrator} {settings} vs exact (test_furnace)", furnace
    for j, (integrator, settings) in enumerate(tb.ALL):
        def sphere(integrator=integrator, settings=settings, j=j):
            scene, expected = tb.integrating_sphere_case()
            return (tb.analytic_renders(scene, integrator, settings, seed0 + 500 + 50 * j),
                    expected, {"block": 8})
        yield (f"integrating sphere {integrator} {settings} vs exact "
               "(test_integrating_sphere)", sphere)


FAMILIES = {"bidir_scenes": pairs_bidir_scenes, "bidir_lights": pairs_bidir_lights,
            "bidir_fixture": pairs_bidir_fixture, "bidir_analytic": pairs_bidir_analytic}
