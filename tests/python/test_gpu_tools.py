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


def test_compare_keeps_going_after_a_raising_session(tmp_path, monkeypatch):
    """A session that raises (on a GPU: a launch error) fails its row; the next rows still run
    and the tables are written (tools/gpu_check.sh reads them after a timeout too). The Skin
    sphere with lt beside pt: the feature scenes' group, built on the CPU."""
    monkeypatch.syspath_prepend(str(ROOT / "tools"))
    import gpu_compare
    real = gpu_compare.render_set

    def flaky(scene, backend, integrator, *args):
        if integrator == "pt":
            raise RuntimeError("CUDA error: an illegal memory access was encountered")
        return real(scene, backend, integrator, *args)
    monkeypatch.setattr(gpu_compare, "render_set", flaky)
    assert gpu_compare.main(["--backends", "cpu,cpu", "--quick", "--scenes", "subsurface_skin",
                             "--integrators", "pt", "--out", str(tmp_path)]) == 1
    rows = json.loads((tmp_path / "compare.json").read_text())["rows"]
    assert [(r["integrator"], r["passed"]) for r in rows] == [("pt", False), ("lt", True)], rows
    assert "illegal memory access" in (tmp_path / "compare.md").read_text()


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


NO_NVCC = subprocess.run("command -v nvcc && command -v ptxas", shell=True,
                         capture_output=True).returncode != 0

# Kernels for tools/cuda_kernel_check.py: one bounded, one without a bound, one whose 4 KB local
# array is over the 2 KB stack limit (the negative control), one whose inline assembly closes
# a brace at the start of a PTX line (CUB's do: a body must not end there), and device
# functions out of line (a kernel's own module must carry its callees, each defined before
# its callers: nvcc writes no prototype for them).
FIXTURE = r"""
__device__ __noinline__ float callee(float x) { return x * x + 1.0f; }
__global__ void unbounded(float* a) { a[threadIdx.x] = callee(a[threadIdx.x]); }
__global__ void __launch_bounds__(256, 2) bounded(float* a) { a[threadIdx.x] = 2.0f; }
__device__ __noinline__ float bb(float x) { return x * 3.0f; }
__device__ __noinline__ float aa(float x) { return bb(x) + 1.0f; }
__global__ void calls_two(float* a) { a[threadIdx.x] = aa(a[0]) + bb(a[1]); }
__global__ void over_stack(float* a, int i, int j) {
    float buf[1024];
    for (int k = 0; k < 1024; ++k) buf[k] = a[k] * float(k);
    a[j] = buf[i & 1023];
}
__global__ void with_asm(unsigned* a) {
    unsigned x;
    asm volatile("{\n\t.reg .pred p;\n\tsetp.ne.u32 p, %1, 0;\n\tselp.u32 %0, 1, 0, p;\n}"
                 : "=r"(x) : "r"(a[threadIdx.x]));
    a[threadIdx.x + 1] = x + 7u;
}
"""


@pytest.fixture(scope="module")
def kernel_ptx(tmp_path_factory):
    """The fixture's PTX twice (two translation units with the same kernels) in ptx/."""
    tmp = tmp_path_factory.mktemp("kernels")
    (tmp / "k.cu").write_text(FIXTURE)
    (tmp / "ptx").mkdir()
    subprocess.run(["nvcc", "-ptx", "-arch=compute_90", str(tmp / "k.cu"), "-o",
                    str(tmp / "ptx" / "a.ptx")], check=True, timeout=300)
    (tmp / "ptx" / "b.ptx").write_text((tmp / "ptx" / "a.ptx").read_text())
    return tmp / "ptx"


def kernel_rows(stdout):
    return {line.split("`")[1]: line for line in stdout.splitlines() if line.startswith("| `")}


@pytest.mark.skipif(NO_NVCC, reason="no nvcc / ptxas")
def test_kernel_check_measures_every_kernel_and_fails_one_over_the_stack_limit(kernel_ptx):
    """tools/cuda_kernel_check.py (CI's check of every kernel) measures each kernel's code once
    (the two files' copies are one row each), passes the ones within 128 registers and 2 KB,
    and fails the kernel with a 4 KB frame (the negative control), naming it."""
    p = run(sys.executable, ROOT / "tools" / "cuda_kernel_check.py", kernel_ptx, "-j", "2",
            timeout=300)
    assert p.returncode == 1, p.stdout + p.stderr
    assert "10 kernels, 5 distinct: 1 failing, 5 measured" in p.stdout, p.stdout
    rows = kernel_rows(p.stdout)
    over = rows["over_stack(float*, int, int)"]
    assert "**FAIL: over 128 registers or 2048 B of stack**" in over
    assert int(over.split("|")[6]) >= 4096, over
    for name in ("unbounded(float*)", "bounded(float*)", "with_asm(unsigned int*)",
                 "calls_two(float*)"):
        assert "FAIL" not in rows[name] and "(also 1 more)" in rows[name], rows[name]


@pytest.mark.skipif(NO_NVCC, reason="no nvcc / ptxas")
def test_kernel_module_is_what_ptxas_compiles_in_the_whole_file(kernel_ptx, tmp_path):
    """A kernel's own module (ptx_parse.kernel_ptx) holds its whole body (inline assembly's
    braces included) and its callee, and ptxas measures it as in the whole file."""
    sys.path.insert(0, str(ROOT / "tools"))
    from ptx_parse import kernel_ptx as own_module
    from ptx_parse import split_module
    whole = kernel_ptx / "a.ptx"
    module, defs = split_module(whole.read_text())
    for k in ("_Z9unboundedPf", "_Z8with_asmPj", "_Z10over_stackPfii", "_Z9calls_twoPf"):
        tail = [line.strip() for line in defs[k][1] if line.strip()][-2:]
        assert tail == ["ret;", "}"], tail
        (tmp_path / "k.ptx").write_text(own_module(module, defs, k))
        got = [subprocess.run(["ptxas", "-arch=sm_90", "-v", f"--entry={k}", str(f), "-o",
                               os.devnull], capture_output=True, text=True, timeout=120)
               for f in (whole, tmp_path / "k.ptx")]
        assert got[1].returncode == 0, got[1].stderr
        used = [[line for line in g.stderr.splitlines() if "Used" in line or "stack frame" in line]
                for g in got]
        assert used[0] == used[1] and used[0], used


@pytest.mark.skipif(NO_NVCC, reason="no nvcc / ptxas")
def test_kernel_check_names_a_kernel_missing_from_its_record(kernel_ptx, tmp_path):
    """With --max-lines, kernels over it come from the record (--update writes it); a kernel
    whose code is not in it (changed since) fails, named, with the command that refreshes it."""
    import shutil
    sys.path.insert(0, str(ROOT / "tools"))
    tools = tmp_path / "tools"
    shutil.copytree(ROOT / "tools", tools, ignore=shutil.ignore_patterns("*.json", "__pycache__"))
    tool = tools / "cuda_kernel_check.py"
    p = run(sys.executable, tool, kernel_ptx, "--max-lines", "1", timeout=300)
    assert p.returncode == 1, p.stdout + p.stderr
    assert "10 kernels, 5 distinct: 5 failing, 0 measured" in p.stdout, p.stdout
    assert "not measured: larger than --max-lines and its code is not in the record" in p.stdout
    assert f"`python3 tools/cuda_kernel_check.py {kernel_ptx} --update --max-lines 1`" in p.stdout
    p = run(sys.executable, tool, kernel_ptx, "--max-lines", "1", "--bounded-unmeasured-ok",
            timeout=300)
    rows = kernel_rows(p.stdout)
    assert "launch bound only" in rows["bounded(float*)"] and "FAIL" not in rows["bounded(float*)"]
    assert "FAIL: not measured" in rows["unbounded(float*)"], p.stdout
    p = run(sys.executable, tool, kernel_ptx, "--update", timeout=300)
    assert (tools / "cuda_kernel_resources.json").exists(), p.stdout + p.stderr
    p = run(sys.executable, tool, kernel_ptx, "--max-lines", "1", timeout=300)
    assert "5 distinct: 1 failing, 5 measured" in p.stdout, p.stdout  # over_stack, recorded
    # a changed kernel: its code's digest is not in the record
    changed = tmp_path / "changed"
    changed.mkdir()
    text = (kernel_ptx / "a.ptx").read_text()
    from ptx_parse import definitions
    body = "\n".join(definitions(text)["_Z8with_asmPj"][1])
    assert ", 7;" in body  # a[threadIdx.x + 1] = x + 7u, now + 8u
    (changed / "a.ptx").write_text(text.replace(body, body.replace(", 7;", ", 8;")))
    p = run(sys.executable, tool, changed, "--max-lines", "1", timeout=300)
    rows = kernel_rows(p.stdout)
    assert p.returncode == 1 and "not measured" in rows["with_asm(unsigned int*)"], p.stdout
    assert "not measured" not in rows["bounded(float*)"], p.stdout
    # --record (CI): kernels in the record come from it, only the changed one is measured here,
    # and the recorded kernel over the stack limit still fails
    p = run(sys.executable, tool, changed, "--record", timeout=300)
    rows = kernel_rows(p.stdout)
    assert rows["with_asm(unsigned int*)"].endswith("| ptxas here |"), p.stdout
    assert rows["bounded(float*)"].endswith("| record |"), p.stdout
    assert "5 distinct: 1 failing, 5 measured" in p.stdout, p.stdout
    # --update --record (the refresh after a merge): only the changed kernel is measured, and
    # the record holds the current five (the old with_asm's digest dropped)
    import json
    before = json.loads((tools / "cuda_kernel_resources.json").read_text())["kernels"]
    p = run(sys.executable, tool, changed, "--update", "--record", timeout=300)
    rows = kernel_rows(p.stdout)
    assert rows["with_asm(unsigned int*)"].endswith("| ptxas here |"), p.stdout
    assert rows["bounded(float*)"].endswith("| record |"), p.stdout
    after = json.loads((tools / "cuda_kernel_resources.json").read_text())["kernels"]
    assert len(after) == 5 and len(set(after) & set(before)) == 4, (before, after)
    p = run(sys.executable, tool, changed, "--max-lines", "1", timeout=300)
    assert "5 distinct: 1 failing, 5 measured" in p.stdout, p.stdout
