"""What the status bar and the Lantern panel say while integrator "auto" renders
(addon/engine.py auto_status): the choice, and under CIS-LBDPT what its connection allocation
chose (a light path per pixel sample, the mean connections a pixel: issue 27 item 4), from a
real session's stats, before and after the allocation's first choice."""
import lantern
from lantern import scenes


def test_status_names_the_choice_and_the_connections(addon):
    from lantern_blender.engine import LAST_AUTO, auto_status
    scene = scenes.fixture_box(16, 16)
    s = lantern.Session(scene, integrator="auto", seed=3, backend="cpu", max_depth=8,
                        threads=1)
    texts = []
    for _ in range(12):
        s.step()
        texts.append(auto_status(s.stats))
    st = s.stats
    assert st["auto_choice"] == "cis", st["auto_choice"]  # the fixture: cis on 15 of 16 seeds
    assert st["connection_choices"] > 0 and st["mean_connections"] >= 0.0
    want = f"{st['mean_connections']:.2g} connections a pixel on average"
    assert want in texts[-1] and "a light path per sample" in texts[-1], texts[-1]
    assert LAST_AUTO["text"] == texts[-1][len(" | "):]
    # before the allocation's first choice it says it is measuring
    assert any("measuring connections" in t for t in texts[:-1]) or \
        texts[0].startswith(" | Auto: measuring"), texts


def test_status_is_empty_for_a_chosen_integrator(addon):
    from lantern_blender.engine import auto_status
    s = lantern.Session(scenes.cornell_box(8, 8), integrator="pt", seed=1, backend="cpu")
    s.step()
    assert auto_status(s.stats) == ""
