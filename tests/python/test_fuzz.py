"""The scene fuzzer (tools/fuzz_scene.py) in CI: a fixed-seed set of mutated scene files, each
loaded and rendered in a child under time and memory limits. None may crash, hang, raise an
unexpected exception, render a non-finite pixel or pass the memory limit. A long run:
tools/README.md."""
import os
import sys

import pytest

import lantern
from lantern import scenes

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "tools"))
import fuzz_scene  # noqa: E402

pytestmark = pytest.mark.skipif(not lantern.native_available(),
                                reason=f"needs lantern._core ({lantern.native_error()})")
CI_SEED, CI_CASES = 12, 100


def test_fixed_seed_set(tmp_path):
    report = fuzz_scene.run(seed=CI_SEED, cases=CI_CASES, jobs=2, timeout_s=90.0,
                            render_s=15.0, work=tmp_path)
    counts = report["counts"]
    assert sum(counts.values()) == CI_CASES
    # both ends are exercised: files that render and files that are refused
    assert counts["image"] >= CI_CASES // 10 and counts["error"] >= CI_CASES // 4, counts
    lines = [f"case {f['case']} {f['class']}: {f['label']} | {f['message'][:200]}"
             for f in report["failures"]]
    assert not lines, f"{counts}\n" + "\n".join(lines)


def test_cases_are_reproducible(tmp_path):
    seeds = fuzz_scene.build_seeds(tmp_path / "seeds")
    for index in range(5):
        a = fuzz_scene.make_case(seeds, CI_SEED, index, tmp_path / "a")
        b = fuzz_scene.make_case(seeds, CI_SEED, index, tmp_path / "b")
        assert a[1:] == b[1:] and a[0].read_bytes() == b[0].read_bytes()


@pytest.mark.parametrize("kind, expected", [("crash", "crash"), ("hang", "hang"),
                                            ("traceback", "traceback"), ("rss", "memory"),
                                            ("alloc", "memory"), ("vague", "vague"),
                                            (None, "image")])
def test_classifier(tmp_path, kind, expected):
    """The classes are told apart: a child that aborts, sleeps, raises, takes memory, or says
    only 'std::bad_cast'."""
    path = tmp_path / "box.lantern"
    scenes.cornell_box(width=8, height=8).save(path)
    settings = {"integrator": "pt", "max_depth": 2, "threads": 1, "backend": "cpu"}
    if kind:
        settings["_selftest"] = kind
    result = fuzz_scene.run_case(path, settings, "auto", timeout_s=4.0 if kind == "hang" else 60,
                                 mem_mb=256, render_s=10.0)
    assert result["class"] == expected, result


def test_memory_is_the_child_own(tmp_path):
    """A large parent does not count against the child: ru_maxrss carries the forked parent's
    RSS across exec (CI's pytest process passed 256 MB and an 8x8 render was called 'memory')."""
    ballast = bytearray(320 << 20)
    ballast[::4096] = b"x" * len(range(0, 320 << 20, 4096))
    path = tmp_path / "box.lantern"
    scenes.cornell_box(width=8, height=8).save(path)
    settings = {"integrator": "pt", "max_depth": 2, "threads": 1, "backend": "cpu"}
    result = fuzz_scene.run_case(path, settings, "auto", timeout_s=60, mem_mb=256, render_s=10.0)
    del ballast
    assert result["class"] == "image" and result["rss_mb"] < 256, result
