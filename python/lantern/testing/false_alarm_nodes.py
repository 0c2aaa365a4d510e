"""False alarms of tests/cycles/test_nodes.py's rule over independent seed sets: every case of
the file (node outputs, bumps, graph-fed normal maps) rendered again with Lantern seed
1000 + trial and Cycles seed 2000 + trial, through the test functions themselves (their
tolerances and negative controls), counting the trials in which a case fails. The rule has no
alpha: a fair pair either agrees within the float rounding or it does not.

    PYTHONPATH=python nice python -m lantern.testing.false_alarm_nodes [--trials 20]
        [--out tests/false_alarm_nodes.json]
"""

import argparse
import functools
import importlib.util
import json
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT / "tests" / "cycles"))


def load_test_module():
    spec = importlib.util.spec_from_file_location(
        "test_nodes", ROOT / "tests" / "cycles" / "test_nodes.py")
    tn = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tn)
    tn.st.addon()
    return tn


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--trials", type=int, default=20)
    p.add_argument("--out", default=None)
    args = p.parse_args(argv)
    tn = load_test_module()
    lantern_render, cycles_render = tn.render_lantern, tn.render_cycles
    tests = ([(c, tn.test_node_output_matches_cycles) for c in sorted(tn.CASES)]
             + [(c, tn.test_bump_matches_cycles) for c in sorted(tn.BUMPS)]
             + [(c, tn.test_normal_map_from_a_graph_matches_cycles)
                for c in sorted(tn.NORMAL_MAP_COLORS)])
    t0 = time.perf_counter()
    out = {"cases": len(tests), "trials": 0, "trials_with_a_fail": 0, "fails": {}}
    for trial in range(args.trials):
        tn.render_lantern = functools.partial(lantern_render, seed=1000 + trial)
        tn.render_cycles = functools.partial(cycles_render, seed=2000 + trial)
        failed = []
        for case, test in tests:
            try:
                test(case, Path(tempfile.mkdtemp()))
            except AssertionError as e:
                failed.append(case)
                out["fails"].setdefault(case, []).append(str(e).splitlines()[0][:200])
        out["trials"] += 1
        out["trials_with_a_fail"] += int(bool(failed))
        out["seconds"] = round(time.perf_counter() - t0, 1)
        print(f"trial {trial}: {len(failed)} of {len(tests)} cases failed {failed} "
              f"({out['seconds']:.0f} s)", flush=True)
        if args.out:
            Path(args.out).write_text(json.dumps(out, indent=1))
    print(json.dumps(out, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
