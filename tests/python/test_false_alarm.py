"""lantern.testing's false-alarm runner (issue 31): every family module registers its families
once, a name given twice is an error, and the runner counts the failures of a fair pair near
alpha and of a biased pair in every trial (its negative control). Synthetic images: no render."""
import json

import numpy as np
import pytest

from lantern import agreement
from lantern.testing import false_alarm as fa

TRIALS = 20


def _images(rng, mean, k=12, shape=(16, 16, 3)):
    return [rng.normal(mean, 0.05, shape).astype(np.float32) for _ in range(k)]


def _null(trial):
    rng = np.random.default_rng(1000 + trial)
    yield "synthetic fair pair", lambda: (_images(rng, 1.0), _images(rng, 1.0), {})


def _biased(trial):
    rng = np.random.default_rng(5000 + trial)
    yield "synthetic pair 3 % apart", lambda: (_images(rng, 1.0), _images(rng, 1.03), {})


@pytest.fixture
def families(monkeypatch):
    monkeypatch.setattr(fa, "FAMILIES", {})
    fa.load_family_modules()
    return fa.FAMILIES


def test_every_family_module_registers_once(families):
    for name in ("cross", "layers", "dof", "bidir_scenes", "bl_direct", "cycles_refs",
                 "anisotropy", "lt_scenes"):   # one from each fa_*.py
        assert callable(families[name]), name
    n = len(families)
    fa.load_family_modules()                    # a second load changes nothing
    assert len(fa.FAMILIES) == n == 53


def test_a_family_given_twice_is_an_error(families):
    families["cross"] = _null                   # another function under a module's name
    with pytest.raises(SystemExit, match="defined twice"):
        fa.load_family_modules()


def test_the_runner_counts_false_alarms(families, tmp_path, capsys):
    families.update(synthetic_null=_null, synthetic_biased=_biased)
    out = tmp_path / "fa.json"
    assert fa.main(["--trials", str(TRIALS), "--families", "synthetic_null,synthetic_biased",
                    "--out", str(out)]) == 0
    rows = json.loads(out.read_text())["rows"]
    fair, biased = rows["synthetic fair pair"], rows["synthetic pair 3 % apart"]
    assert fair["trials"] == biased["trials"] == TRIALS
    for alpha in fa.ALPHAS:
        assert fair[f"fails@{alpha:g}"] <= agreement.false_alarm_bound(TRIALS, alpha), fair
    assert biased["fails@0.001"] == TRIALS, biased   # the negative control: caught every time
    assert len(fair["worst_p_x_n"]) == TRIALS
