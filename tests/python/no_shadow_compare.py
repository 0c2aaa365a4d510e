"""The render-and-compare body of the Cast Shadow off tests against pt (test_no_shadow_media.py,
test_no_shadow_strands.py): K seeds of test_linking_shadow_media.render (one Session step of
32 samples at max_depth 4, the first 3 channels) of a builder `build(on)`, pt's from seed 1000,
the integrator's from 2000 and its control's (`build(False)`: the scene without the property)
from 3000. compare_renders' block means and Student t (lantern.metrics)."""
from lantern import metrics

from test_linking_shadow_media import render

K = 16  # seeds (tests/README.md: Welch dof >= 15)


def renders(build, integrator, seed0, on=True):
    out, warnings = [], []
    for k in range(K):
        img, warnings = render(build(on), integrator, seed0 + k)
        out.append(img)
    return out, warnings


def pt_ref(pt_refs, cases, name):
    """pt's renders of cases[name], kept in the module's pt_refs (a dict fixture)."""
    if name not in pt_refs:
        pt_refs[name] = renders(cases[name], "pt", 1000)[0]
    return pt_refs[name]


def assert_matches_pt(label, pt_refs, cases, case, integrator):
    """`integrator` renders cases[case] itself (no warning), agrees with pt (block 4, image bias
    2.5 %, block bias 10 %), and tells the control apart from pt's image."""
    ref = pt_ref(pt_refs, cases, case)
    imgs, warnings = renders(cases[case], integrator, 2000)
    assert not warnings, warnings  # rendered by the integrator itself
    metrics.assert_agreement(f"{label}, {integrator} vs pt", imgs, ref, block=4,
                             image_bias=0.025, block_bias=0.1)
    # the control: the property off (the scene without it) is seen
    free, _ = renders(cases[case], integrator, 3000, on=False)
    assert not metrics.compare_renders(free, ref, block=4).passed
