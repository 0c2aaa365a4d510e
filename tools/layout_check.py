"""The house's layout rules (issue 31), checked: no source file over 600 lines in native/src,
python/lantern or addon; no import circle among the modules of python/lantern or of addon
(every import counts, those inside functions too: a circle there still ties the modules'
loading together); no source file in bench/results.

    python3 tools/layout_check.py [--max-lines 600]

Files still over the limit are listed in LONG_FILES with the issue that splits them: a listed
file that shrank under the limit, or one not listed that grew over it, fails, so the list only
shrinks. Exit 1 on any failure; tests/python/test_layout.py runs it in CI."""
import argparse
import ast
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SOURCE_DIRS = ("native/src", "python/lantern", "addon")
SOURCE_EXT = (".py", ".h", ".cpp", ".cu", ".cuh", ".c", ".hpp", ".sh", ".patch")
PACKAGES = {"python/lantern": "lantern", "addon": "lantern_blender"}
# files allowed past the limit while an issue splits them (none left: issue 31 split the last,
# integrator/bdpt.h); the count is the file's length when it was listed
LONG_FILES = {}
# import circles still to break, as sets of modules: a circle must stay inside one of them, so
# the list can only shrink (issue 31 broke the add-on's: native.py loads the core, program_builder
# and node_ops let the node handlers register without importing back)
KNOWN_CIRCLE = set()


def long_files(limit):
    out = {}
    for top in SOURCE_DIRS:
        for d, dirs, names in os.walk(os.path.join(ROOT, top)):
            dirs[:] = [x for x in dirs if not x.startswith((".", "__"))]
            for n in names:
                if n.endswith(SOURCE_EXT):
                    p = os.path.join(d, n)
                    with open(p, "rb") as f:
                        count = sum(1 for _ in f)
                    if count > limit:
                        out[os.path.relpath(p, ROOT).replace(os.sep, "/")] = count
    return out


def modules(pkg_dir, pkg):
    """{module name: path} of a package's .py files."""
    out = {}
    base = os.path.join(ROOT, pkg_dir)
    for d, dirs, names in os.walk(base):
        dirs[:] = [x for x in dirs if not x.startswith((".", "__"))]
        for n in names:
            if n.endswith(".py"):
                rel = os.path.relpath(os.path.join(d, n), base)[:-3].replace(os.sep, ".")
                name = pkg if rel == "__init__" else f"{pkg}.{rel}"
                out[name[:-len(".__init__")] if name.endswith(".__init__") else name] = \
                    os.path.join(d, n)
    return out


def imports(name, path, known, is_package):
    """The modules of `known` that module `name` imports (anywhere in its body)."""
    tree = ast.parse(open(path, encoding="utf-8").read(), path)
    here = name if is_package else name.rpartition(".")[0]
    out = set()
    for node in ast.walk(tree):
        targets = []
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = here.split(".")
                up = parts[:len(parts) - (node.level - 1)]
                base = ".".join(up + ([node.module] if node.module else []))
            # `from . import x` of a submodule x imports x, not the package's __init__ (that
            # one runs before any of its submodules whatever the form; see import_cycles)
            names = [f"{base}.{a.name}" for a in node.names]
            targets = names if all(n in known for n in names) else [base] + names
        for t in targets:
            while t and t not in known:
                t = t.rpartition(".")[0]
            if t and t != name and t in known:
                out.add(t)
    return out


def cycles(graph):
    """Strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, out, n = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = n[0]
        n[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))
    sys.setrecursionlimit(10000)
    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def import_cycles():
    found = []
    for pkg_dir, pkg in PACKAGES.items():
        mods = modules(pkg_dir, pkg)
        graph = {m: imports(m, p, mods, p.endswith("__init__.py")) for m, p in mods.items()}
        # a package's __init__ importing its own submodules is how packages work, not a circle
        for m in graph:
            graph[m] = {t for t in graph[m] if not (m in mods and mods[m].endswith("__init__.py")
                                                    and t.startswith(m + "."))}
        # the package itself is imported by its submodules for its API: a submodule that
        # imports the package's __init__ depends on everything the __init__ imports
        found += cycles(graph)
    return found


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--max-lines", type=int, default=600)
    a = ap.parse_args()
    bad = 0
    long = long_files(a.max_lines)
    for path, count in sorted(long.items()):
        if path not in LONG_FILES:
            print(f"FAIL {path}: {count} lines (the limit is {a.max_lines}): split it along "
                  f"its seams")
            bad += 1
        else:
            print(f"known {path}: {count} lines (issue 31 splits it)")
    for path in sorted(set(LONG_FILES) - set(long)):
        print(f"FAIL {path} is no longer over {a.max_lines} lines: take it off LONG_FILES")
        bad += 1
    for comp in import_cycles():
        if set(comp) <= KNOWN_CIRCLE:
            print(f"known import circle ({len(comp)} modules; issue 31 breaks it): "
                  f"{' <-> '.join(comp)}")
            continue
        print(f"FAIL import circle: {' <-> '.join(comp)}")
        bad += 1
    for d, _, names in os.walk(os.path.join(ROOT, "bench", "results")):
        for n in names:
            if n.endswith(SOURCE_EXT):
                print(f"FAIL {os.path.relpath(os.path.join(d, n), ROOT)}: bench/results holds "
                      f"results and the commands that made them, not source files")
                bad += 1
    print(f"layout_check: {bad} failure(s)")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
