"""The limb ratio of tests/cycles/test_coat_normal.py over independent seed sets (the renders of
false_alarm.py's coat_normal family, each trial its own seeds on both sides): counts the
trials whose ratio misses the test's LIMB_RATIO by more than its allowance, at the test's alpha
(1e-3) and at 0.05 and 0.2, and runs the family's interior comparison on the same renders.

    PYTHONPATH=python nice python -m lantern.testing.false_alarm_coat_limb [--trials 20]
        [--first 0] [--out tests/false_alarm_coat.json]
"""

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT / "tools"))
sys.path.insert(0, str(ROOT / "tests" / "cycles"))

from lantern.testing import fa_bl_scenes as fa  # noqa: E402
from lantern import metrics  # noqa: E402

ALPHAS = (1e-3, 0.05, 0.2)


def limb(lan, cyc, mask, k):
    """(ratio, se): the test's limb ratio and its delta-method standard error."""
    ratio = np.stack(lan)[:, mask].mean() / np.stack(cyc)[:, mask].mean()
    ls = np.stack(lan)[:, mask].reshape(k, -1).mean(axis=1)
    cs = np.stack(cyc)[:, mask].reshape(k, -1).mean(axis=1)
    se = ratio * math.sqrt((ls.var(ddof=1) / ls.mean() ** 2 + cs.var(ddof=1) / cs.mean() ** 2) / k)
    return float(ratio), float(se)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--trials", type=int, default=20)
    p.add_argument("--first", type=int, default=0, help="first trial (its seeds): 20 continues")
    p.add_argument("--out", default=None)
    args = p.parse_args(argv)
    import test_coat_normal as tc
    t0 = time.perf_counter()
    rows = {"limb": {f"fails@{a:g}": 0 for a in ALPHAS},
            "interior": {f"fails@{a:g}": 0 for a in ALPHAS}, "trials": 0, "ratios": [],
            "worst_p_x_n": []}
    for trial in range(args.first, args.first + args.trials):
        lan, cyc, interior, mask = fa.coat_normal_renders(trial)
        ratio, se = limb(lan, cyc, mask, tc.K)
        rows["ratios"].append([round(ratio, 5), round(se, 5)])
        for a in ALPHAS:
            allowed = metrics.z_threshold(1, a, tc.K - 1) * math.hypot(se, tc.LIMB_SE)
            rows["limb"][f"fails@{a:g}"] += int(abs(ratio - tc.LIMB_RATIO) > allowed)
            r = metrics.compare_renders(lan, cyc, block=4, mask=interior, rel_floor=1e-3,
                                        alpha=a)
            rows["interior"][f"fails@{a:g}"] += int(not r.passed)
        res = metrics.compare_renders(lan, cyc, block=4, mask=interior, rel_floor=1e-3)
        rows["worst_p_x_n"].append(round(float(res.blocks.p.min() * res.blocks.n), 4))
        rows["trials"] += 1
        rows["seconds"] = round(time.perf_counter() - t0, 1)
        print(f"trial {trial}: limb {ratio:.5f} +- {se:.5f}; interior "
              f"{'ok' if res.passed else 'FALSE ALARM'} ({rows['seconds']:.0f} s)", flush=True)
        if args.out:
            Path(args.out).write_text(json.dumps(rows, indent=1))
    print(json.dumps({k: v for k, v in rows.items() if k not in ("ratios",)}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
