"""`python -m lantern`: argument errors, info, render (through a stand-in core, and through
the real one when it is built)."""
import subprocess
import sys

import numpy as np
import pytest

import fake_core
import lantern
from lantern import cli, imageio, scenes, session


def run(*args):
    return subprocess.run([sys.executable, "-m", "lantern", *map(str, args)],
                          capture_output=True, text=True, timeout=120)


@pytest.fixture
def scene_file(tmp_path):
    path = tmp_path / "box.lantern"
    scene = scenes.cornell_box(width=16, height=12)
    scene.world["color"] = [0.25, 0.5, 1.0]
    scene.save(path)
    return path


@pytest.fixture
def fake(monkeypatch):
    monkeypatch.setattr(session, "_core", fake_core)
    monkeypatch.setattr(session, "_core_error", None)
    fake_core.Session.instances.clear()
    return fake_core


def test_info(scene_file):
    out = run("info", scene_file)
    assert out.returncode == 0, out.stderr
    assert "16x12" in out.stdout
    assert "34 triangles" in out.stdout
    assert "1 (1 area)" in out.stdout
    assert "materials:  3" in out.stdout


@pytest.mark.parametrize("args, code, message", [
    ([], 2, "a command is required"),
    (["render", "x.lantern"], 2, "-o/--output"),
    (["render", "x.lantern", "-o", "o.exr", "--spp", "0"], 2, "positive integer"),
    (["render", "x.lantern", "-o", "o.exr", "--max-depth", "abc"], 2, "positive integer"),
    (["render", "x.lantern", "-o", "o.exr", "--integrator", "mlt"], 2, "invalid choice"),
    (["render", "x.lantern", "-o", "o.exr", "--seed", "-3"], 2, ">= 0"),
    (["frobnicate"], 2, "invalid choice"),
])
def test_argument_errors(args, code, message):
    out = run(*args)
    assert out.returncode == code
    assert message in out.stderr


def test_missing_file_one_line(tmp_path):
    out = run("info", tmp_path / "missing.lantern")
    assert out.returncode == 1
    assert out.stderr.strip() == f"lantern: error: scene file not found: " \
                                 f"{tmp_path / 'missing.lantern'}"
    assert "Traceback" not in out.stderr


def test_bad_scene_one_line(tmp_path):
    bad = tmp_path / "bad.lantern"
    bad.write_text("not a zip")
    for args in (["info", bad], ["render", bad, "-o", tmp_path / "o.exr"]):
        out = run(*args)
        assert out.returncode == 1
        assert len(out.stderr.strip().splitlines()) == 1
        assert "not a Lantern scene file" in out.stderr


def test_debug_shows_traceback(tmp_path):
    out = run("--debug", "info", tmp_path / "missing.lantern")
    assert out.returncode != 0 and "Traceback" in out.stderr
    out = run("info", tmp_path / "missing.lantern", "--debug")
    assert out.returncode != 0 and "Traceback" in out.stderr


def test_bad_output_extension(scene_file, tmp_path):
    out = run("render", scene_file, "-o", tmp_path / "o.tiff")
    assert out.returncode == 1 and ".exr, .png or .npy" in out.stderr
    assert not (tmp_path / "o.tiff").exists()


def test_bad_connection_count(scene_file, tmp_path, fake, capsys):
    code = cli.main(["render", str(scene_file), "-o", str(tmp_path / "o.exr"),
                     "--integrator", "cis", "--connections", "100"])
    assert code == 1
    assert "connections" in capsys.readouterr().err


def test_render_through_stand_in_core(scene_file, tmp_path, fake, capsys):
    out = tmp_path / "o.exr"
    png = tmp_path / "o.png"
    code = cli.main(["render", str(scene_file), "-o", str(out), "--spp", "6", "--seed", "3",
                     "--threads", "2", "--max-depth", "5", "--spp-per-iteration", "2",
                     "--png", str(png)])
    err = capsys.readouterr().err
    assert code == 0, err
    s = fake.Session.instances[-1]
    assert s.settings == {"integrator": "auto", "backend": "cpu", "spp_per_iteration": 2,
                          "max_depth": 5, "seed": 3, "threads": 2, "rr_depth": 4,
                          "sort": None, "connections": 5, "candidates": 10,
                          "cis_target": "contribution", "naive_ris": False, "naive_map": False,
                          "connection_allocation": None,
                          "cache_budget_mb": 0, "light_candidates": 1,
                          "adaptive_threshold": 0.0, "adaptive_min_samples": 0,
                          "adaptive_step": 4, "instancing": False,
                          "auto_keep_pilot": False, "auto_media": True,
                          "light_path_fraction": 1.0,
                          "moment_channels": False, "soft_visibility": True,
                          "gpu_checked": 0}  # no GPU self-check on the CPU backend
    assert s.spp == 6 and s.stats()["iterations"] == 3
    assert "6/6 spp" in err and "Mrays/s" in err
    assert "backend cpu (asked: auto)" in err and "backend cpu)" in err
    img = imageio.read_image(out)
    assert img.shape == (12, 16, 3) and np.allclose(img, [0.25, 0.5, 1.0])
    assert imageio.read_image(png).shape == (12, 16, 3)


def test_session_wrapper_with_stand_in_core(fake):
    scene = scenes.furnace_sphere(subdivisions=1, width=8, height=4)
    s = lantern.Session(scene, spp_per_iteration=4, backend="cuda", seed=9, integrator="pt")
    assert s.spp == 0
    assert s.step() == 4 and s.spp == 4
    assert s.image().shape == (4, 8, 3)
    assert s.stats["iterations"] == 1
    assert any("CUDA" in w for w in s.warnings) and "fake core" in s.warnings
    s.cancel()
    s.step()
    assert s.spp == 4
    calls = []
    img = lantern.render(scene, spp=10, spp_per_iteration=3,
                         progress=lambda done, total: calls.append((done, total)), integrator="pt")
    assert calls == [(3, 10), (6, 10), (9, 10), (12, 10)]
    assert img.shape == (4, 8, 3)


def test_rays_from_stats():
    assert cli._rays({"rays_camera": 1, "rays_shadow": 2, "rays_total": 3}) == 3
    assert cli._rays({"rays_camera": 1, "rays_shadow": 2}) == 3
    assert cli._rays({"rays": {"camera": 4, "shadow": 1}}) == 5
    assert cli._rays({}) == 0


def test_render_stops_when_cancelled(fake, monkeypatch):
    # a core that makes no progress (cancelled) must not spin forever
    monkeypatch.setattr(fake.Session, "step", lambda self: None)
    img = lantern.render(lantern.Scene(), spp=5, integrator="pt")
    assert img.shape == (64, 64, 3)
