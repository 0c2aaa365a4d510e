"""What the differential tester's batch tests share (test_difftest_features5.py,
test_difftest_features6.py; tools/difftest_features*.py, docs/difftest.md): the full cases of
earlier seeds drawn with a batch's draw made a no-op, a case that has some tags, and the
shrinker's edits of a case. No render: the generator's data only."""

import copy
import json
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import difftest_features as df  # noqa: E402
import difftest_scene as ds  # noqa: E402


def draws_as_before(monkeypatch, batch, gained_tags=None, seeds=range(60)):
    """(same, gained) over the full cases of `seeds`: with batch.draw a no-op (the generator
    before the batch) each seed draws the same case, or one that gains a tag (one of
    gained_tags, where given), asserted per seed."""
    new = {s: ds.generate(s, "full") for s in seeds}
    monkeypatch.setattr(batch, "draw", lambda key, case, *a: case)
    same = gained = 0
    for s in seeds:
        old = ds.generate(s, "full")
        if json.dumps(old, sort_keys=True) == json.dumps(new[s], sort_keys=True):
            same += 1
        else:
            tags = df.features(new[s]) - df.features(old)
            assert tags & set(gained_tags) if gained_tags is not None else tags, s
            gained += 1
    return same, gained


def case_with(tags, seeds=range(20000, 20400)):
    """The first full case of `seeds` with every tag of `tags`."""
    for s in seeds:
        case = ds.generate(s, "full")
        if set(tags) <= df.features(case):
            return case
    raise AssertionError(f"no seed draws {tags}")


def assert_shrinker_takes_off(tags):
    """Each tag of `tags` has a shrink edit (of case_with it) whose case no longer has it."""
    for tag in tags:
        case = case_with({tag})
        edits = [c for _, c in df.shrink_edits(copy.deepcopy(case))]
        assert any(tag not in df.features(c) for c in edits), tag
