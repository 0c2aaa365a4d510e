"""bench/rmse.py end to end at toy size: a 32x32 Cornell box, pt for ~1 s, into a tmp folder.
Checks the harness (files, columns, RMSE falling), not the renderer's speed."""

import csv
import math
import os
import subprocess
import sys
from pathlib import Path

import pytest

import lantern

ROOT = Path(__file__).resolve().parents[2]
BENCH = ROOT / "bench"

pytestmark = pytest.mark.skipif(not lantern.native_available(),
                                reason=f"lantern._core not built ({lantern.native_error()})")


def run_bench(tmp_path, *extra):
    # rmse.py draws its plots with matplotlib (absent on the GPU machine)
    pytest.importorskip("matplotlib")
    cmd = [sys.executable, str(BENCH / "rmse.py"), "--quick", "--scenes", "cornell",
           "--res", "32x32", "--time", "1", "--ref-spp", "256", "--refs", str(tmp_path / "refs"),
           "--out", str(tmp_path / "out"), "--no-progress", *extra]
    env = dict(os.environ, MPLBACKEND="Agg")
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=60, env=env)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return proc


def test_quick_cornell_pt(tmp_path):
    proc = run_bench(tmp_path, "--integrators", "pt,nonesuch")
    out = tmp_path / "out"
    with open(out / "results.csv") as f:
        rows = list(csv.DictReader(f))
    pt = [r for r in rows if r["scene"] == "cornell" and r["integrator"] == "pt"]
    assert len(pt) >= 3, rows
    rmse = [float(r["rmse"]) for r in pt]
    spp = [int(r["spp"]) for r in pt]
    seconds = [float(r["seconds"]) for r in pt]
    assert all(math.isfinite(e) and e > 0 for e in rmse)
    assert all(math.isfinite(float(r["rel_rmse"])) for r in pt)
    assert spp == sorted(spp) and seconds == sorted(seconds)
    assert rmse[-1] < rmse[0], rmse
    assert 0.9 <= seconds[-1] < 5.0
    assert (out / "rmse_cornell.png").stat().st_size > 1000
    table = (out / "table.md").read_text()
    assert "| pt |" in table and "skipped nonesuch" in table
    assert "skipped cornell/nonesuch" in proc.stdout
    for name in ("machine.json", "runs.json", "image_cornell_pt.exr"):
        assert (out / name).exists(), name
    assert (tmp_path / "refs" / "cornell_32x32.npz").exists()


def test_reference_is_cached(tmp_path):
    run_bench(tmp_path, "--integrators", "pt", "--spp", "4")
    proc = run_bench(tmp_path, "--integrators", "pt", "--spp", "4")
    assert "cached" in proc.stdout and "rendering" not in proc.stdout


def test_missing_scene_is_skipped(monkeypatch):
    monkeypatch.syspath_prepend(str(BENCH))
    import bench_scenes
    import lantern.scenes

    monkeypatch.delattr(lantern.scenes, bench_scenes.SCENES["glass"].factory, raising=False)
    with pytest.raises(bench_scenes.SceneUnavailable, match="glass"):
        bench_scenes.build("glass", 8, 8)
    assert bench_scenes.build("cornell", 8, 8).film["width"] == 8


def test_blend_scene_with_cycles(tmp_path):
    """A blend_scenes builder through the add-on's exporter, Lantern's pt and Cycles (bpy) on
    the same .blend, each scored against its own reference."""
    pytest.importorskip("bpy")
    cmd = [sys.executable, str(BENCH / "rmse.py"), "--scenes", "blend:cornell_box",
           "--integrators", "pt,cycles", "--res", "24x24", "--time", "0.5", "--ref-spp", "64",
           "--ref-seeds", "4", "--refs", str(tmp_path / "refs"), "--out", str(tmp_path / "out"),
           "--no-progress"]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120,
                          env=dict(os.environ, MPLBACKEND="Agg"))
    assert proc.returncode == 0, proc.stdout + proc.stderr
    with open(tmp_path / "out" / "results.csv") as f:
        rows = list(csv.DictReader(f))
    cyc = [r for r in rows if r["integrator"] == "cycles"]
    assert len(cyc) >= 2 and [int(r["spp"]) for r in cyc][:2] == [1, 2]
    assert float(cyc[-1]["rmse"]) < float(cyc[0]["rmse"])
    assert any(r["integrator"] == "pt" for r in rows)
    assert (tmp_path / "refs" / "cycles_blend_cornell_box_24x24.npz").exists()
