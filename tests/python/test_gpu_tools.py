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


def fake_prebuilt(folder, stamp=None):
    """A carried prebuilt backend (tools/gpu_prebuild.sh's layout) with the stamp of these
    sources, or the one given."""
    (folder / "objects").mkdir(parents=True)
    (folder / "objects" / "cuda_renderer.cu.o").write_bytes(b"\0")
    nvcc = "Build cuda_13.0.r13.0/compiler.test_0"
    if stamp is None:
        stamp = run(sys.executable, ROOT / "tools" / "gpu_prebuilt_stamp.py", "--nvcc",
                    nvcc).stdout.strip()
    (folder / "stamp.txt").write_text(f"{stamp}\n{nvcc}\narchs 90-real;90-virtual, built "
                                      f"2026-12-04T00:00:00Z in 1 s on test\n")
    return folder


def test_gpu_check_prebuilt_without_gpu_exits_in_seconds_and_never_builds(tmp_path):
    pre = fake_prebuilt(tmp_path / "pre")
    build = tmp_path / "build"
    p = run("bash", ROOT / "tools" / "gpu_check.sh", "--prebuilt", pre,
            env={"GPU_CHECK_NVIDIA_SMI": "/nonexistent/nvidia-smi", "OUT": str(tmp_path / "o"),
                 "GPU_CHECK_BUILD_DIR": str(build), "PYTHON": sys.executable}, timeout=30)
    assert p.returncode == 3, p.stdout + p.stderr
    assert "--prebuilt: " in p.stdout and "stamp" in p.stdout and "no NVIDIA GPU" in p.stdout
    assert not build.exists()


@pytest.mark.parametrize("layout", ["stale", "empty"])
def test_gpu_check_refuses_a_stale_or_missing_prebuilt(tmp_path, layout):
    pre = tmp_path / "pre"
    if layout == "stale":
        fake_prebuilt(pre, stamp="0123456789abcdef0123")
    p = run("bash", ROOT / "tools" / "gpu_check.sh", "--prebuilt", pre,
            env={"GPU_CHECK_NVIDIA_SMI": "/nonexistent/nvidia-smi", "OUT": str(tmp_path / "o"),
                 "PYTHON": sys.executable}, timeout=30)
    assert p.returncode == 1, p.stdout + p.stderr
    assert ("is stale" if layout == "stale" else "gpu_prebuild.sh") in p.stdout


@pytest.mark.skipif(subprocess.run("command -v nvcc", shell=True).returncode != 0,
                    reason="no nvcc")
def test_kernel_check_fails_an_unbounded_kernel_it_cannot_measure(tmp_path):
    """tools/cuda_kernel_check.py (CI's check of every kernel): a kernel without a launch bound
    passes when ptxas measures it here, fails when it is too large to measure here (the
    negative control), and a bounded one passes either way."""
    src = tmp_path / "k.cu"
    src.write_text("__global__ void unbounded(float* a) { a[threadIdx.x] = 1.0f; }\n"
                   "__global__ void __launch_bounds__(256, 2) bounded(float* a) "
                   "{ a[threadIdx.x] = 2.0f; }\n")
    (tmp_path / "ptx").mkdir()
    subprocess.run(["nvcc", "-ptx", "-arch=compute_90", str(src), "-o",
                    str(tmp_path / "ptx" / "k.ptx")], check=True, timeout=120)
    tool = ROOT / "tools" / "cuda_kernel_check.py"
    p = run(sys.executable, tool, tmp_path / "ptx", "-j", "1")
    assert p.returncode == 0, p.stdout + p.stderr
    assert "2 kernels: 0 failing, 2 measured" in p.stdout
    p = run(sys.executable, tool, tmp_path / "ptx", "--max-lines", "0")
    assert p.returncode == 1, p.stdout + p.stderr
    assert "`unbounded(float*)` **FAIL: not measured here and no launch bound" in p.stdout
    assert "2 kernels: 1 failing, 0 measured" in p.stdout
