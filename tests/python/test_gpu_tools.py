"""The GPU check's pieces, on the CPU at toy size (seconds): tools/gpu_compare.py agrees with
itself on cpu vs cpu and fails on a scaled or non-finite image; bench/gpu_bench.py writes its
tables; tools/gpu_check.sh stops with a clear message and a non-zero status without a GPU."""
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import lantern

ROOT = Path(__file__).resolve().parents[2]

pytestmark = pytest.mark.skipif(not lantern.native_available(),
                                reason=f"lantern._core not built ({lantern.native_error()})")


def run(*args, env=None, timeout=120):
    return subprocess.run([*map(str, args)], capture_output=True, text=True, timeout=timeout,
                          cwd=ROOT, env=dict(os.environ, **(env or {})))


def compare(tmp_path, *extra):
    return run(sys.executable, ROOT / "tools" / "gpu_compare.py", "--backends", "cpu,cpu",
               "--quick", "--seeds", "6", "--integrators", "pt,cis", "--out", tmp_path, *extra)


def test_compare_agrees_on_cpu_and_writes_its_files(tmp_path):
    p = compare(tmp_path)
    assert p.returncode == 0, p.stdout + p.stderr
    result = json.loads((tmp_path / "compare.json").read_text())
    assert result["passed"] and len(result["rows"]) == 2
    assert all(r["finite"] and not r["fell_back"] for r in result["rows"])
    assert (tmp_path / "compare.md").exists() and list(tmp_path.glob("compare_*.png"))


@pytest.mark.parametrize("scale", ["3", "nan"])
def test_compare_can_fail(tmp_path, scale):
    p = compare(tmp_path, "--scale-b", scale)
    assert p.returncode == 1, p.stdout + p.stderr
    assert "FAIL" in p.stdout


def test_compare_refuses_an_unavailable_backend(tmp_path):
    from lantern import session
    if session.backend_unavailable("cuda") is None:
        pytest.skip("CUDA is usable here")
    p = run(sys.executable, ROOT / "tools" / "gpu_compare.py", "--quick", "--out", tmp_path)
    assert p.returncode == 2 and "unavailable" in p.stderr


def test_bench_quick_on_cpu(tmp_path):
    p = run(sys.executable, ROOT / "bench" / "gpu_bench.py", "--backend", "cpu", "--quick",
            "--out", tmp_path)
    assert p.returncode == 0, p.stdout + p.stderr
    result = json.loads((tmp_path / "gpu_bench.json").read_text())
    entry = result["scenes"]["bench_glossy"]
    assert entry["res"] == [64, 36]
    rays = entry["rays"]
    assert rays["camera"] > 0 and rays["shadow"] > 0 and rays["backend"] == "cpu"
    assert set(entry["table1"]) == {"lvc", "cis-nosort", "cis"}
    assert all(len(v["ms"]) == 2 and v["ms"][1] > v["ms"][0] for v in entry["table1"].values())
    assert entry["table1"]["cis"]["sorted_bounces"] > 0
    assert entry["table1"]["cis-nosort"]["sorted_bounces"] == 0
    assert "Table 1" in (tmp_path / "gpu_bench.md").read_text()
    assert p.stdout.strip().splitlines()[-2].split()[0] == "scene"  # the table comes last


def test_gpu_check_without_gpu_says_so(tmp_path):
    p = run("bash", ROOT / "tools" / "gpu_check.sh",
            env={"GPU_CHECK_NVIDIA_SMI": "/nonexistent/nvidia-smi", "OUT": str(tmp_path)},
            timeout=30)
    assert p.returncode == 3, p.stdout + p.stderr
    assert "no NVIDIA GPU" in p.stdout and "docs/gpu.md" in p.stdout
    assert "no NVIDIA GPU" in (tmp_path / "summary.txt").read_text()
