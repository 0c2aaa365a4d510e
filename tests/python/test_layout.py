"""The house's layout rules (tools/layout_check.py, issue 31): no new source file over 600
lines, no new import circle in python/lantern or addon, no source file in bench/results; the
known exceptions may only shrink. The checker itself must see what it checks for."""
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))
import layout_check  # noqa: E402


def test_the_layout_keeps_to_its_rules():
    p = subprocess.run([sys.executable, str(ROOT / "tools" / "layout_check.py")],
                       capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stdout + p.stderr


def test_the_checker_finds_a_circle_and_none_in_a_line():
    assert layout_check.cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == \
        [["a", "b", "c"]]
    assert layout_check.cycles({"a": {"b"}, "b": set(), "c": {"a", "b"}}) == []


def test_python_lantern_has_no_import_circle():
    """lantern.metrics re-exports blocks and agreement, which import neither it nor each
    other back; gpu_selfcheck imports no other lantern module (issue 31)."""
    mods = layout_check.modules("python/lantern", "lantern")
    graph = {m: layout_check.imports(m, p, mods, p.endswith("__init__.py"))
             for m, p in mods.items()}
    graph = {m: {t for t in ts if not (mods[m].endswith("__init__.py") and
                                       t.startswith(m + "."))} for m, ts in graph.items()}
    assert layout_check.cycles(graph) == []
    assert "lantern.metrics" not in graph["lantern.agreement"]
    assert graph["lantern.gpu_selfcheck"] == set()


def test_the_checker_reads_relative_imports(tmp_path):
    """`from . import b` of a submodule b depends on b; `from . import f` of a name defined in
    the package's __init__ depends on the __init__ (and so on all it imports)."""
    pkg = tmp_path / "p"
    pkg.mkdir()
    (pkg / "__init__.py").write_text("from .a import g\n\ndef f():\n    pass\n")
    (pkg / "a.py").write_text("from . import b\n\ndef g():\n    from . import f\n")
    (pkg / "b.py").write_text("from .c import x\n")
    (pkg / "c.py").write_text("x = 1\n")
    known = {"p": str(pkg / "__init__.py"), "p.a": str(pkg / "a.py"),
             "p.b": str(pkg / "b.py"), "p.c": str(pkg / "c.py")}
    assert layout_check.imports("p.a", known["p.a"], known, False) == {"p", "p.b"}
    assert layout_check.imports("p.b", known["p.b"], known, False) == {"p.c"}
    (pkg / "a.py").write_text("from . import b\n")
    assert layout_check.imports("p.a", known["p.a"], known, False) == {"p.b"}


def test_the_addon_has_no_import_circle():
    """engine imports export, never back (native.py loads the core); the node handlers read
    node_ops and program_builder and import neither node_eval nor material_compile back."""
    mods = layout_check.modules("addon", "lantern_blender")
    graph = {m: layout_check.imports(m, p, mods, p.endswith("__init__.py"))
             for m, p in mods.items()}
    graph = {m: {t for t in ts if not (mods[m].endswith("__init__.py") and
                                       t.startswith(m + "."))} for m, ts in graph.items()}
    assert layout_check.cycles(graph) == []
    assert "lantern_blender.engine" not in graph["lantern_blender.export"]
    assert "lantern_blender.engine" not in graph["lantern_blender.export.sync"]
    for handlers in ("node_handlers", "node_spectral", "node_textures"):
        assert not {"lantern_blender.export.node_eval", "lantern_blender.export.material_compile"} \
            & graph[f"lantern_blender.export.{handlers}"], handlers
