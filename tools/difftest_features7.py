"""The seventh batch of features in the differential tester's "full" profile (docs/difftest.md,
2026-12-07 difftest8): a mesh volume that casts no shadow (its object's Ray Visibility > Shadow
off), which bdpt / lvc / cis render since volcast (integrator/bidir_no_shadow_medium.h) and no
drawn case had: difftest_features6 puts Cast Shadow off on surfaces only.

draw() adds it to a drawn case from a stream of its own (the case's key + ":features7"), after
difftest_features6.draw, reading only the case's mesh volumes (which no later batch than the
first adds or changes), so every "ci" case and every full case without it draws as before,
with any earlier batch made a no-op as well (tests/cycles/difftest_batch.draws_as_before). The
case holds it as difftest_features6 does: o["cast_shadow"] = False on the volume's object
entry (built by difftest_features6.build_object, taken off by its shrink edit "object i:
casts shadows"). Tags: FEATURES (features(case))."""

import random

FEATURES = {
    "volume no shadow": "a mesh volume whose object casts no shadow (Ray Visibility > Shadow "
                        "off)",
}
P_VOLUME_SHADOW = 0.4


def _volumes(case):
    """The object entries of mesh volumes (not a Volume object's grid)."""
    return [o for o in case["objects"] if o.get("volume") in case.get("volumes", {})
            and o["kind"] != "vdb"]


def draw(key, case, avoid):
    """Add the feature to `case` (full profile, after difftest_features6.draw)."""
    r = random.Random(key + ":features7")
    vols = [o for o in _volumes(case) if o.get("cast_shadow") is not False]
    if vols and r.random() < P_VOLUME_SHADOW and "volume no shadow" not in avoid and \
            "object no shadow" not in avoid and "object no shadow in fog" not in avoid:
        r.choice(vols)["cast_shadow"] = False
    return case


def features(case):
    return {"volume no shadow"} if any(o.get("cast_shadow") is False
                                       for o in _volumes(case)) else set()
