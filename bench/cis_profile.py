"""Where the bidirectional integrators' time goes, against pt (issue 27): callgrind instruction
counts of render steps, attributed to the stages of the schedule by inclusive cost per function
(a callgrind file parsed here: self cost plus the cost of every call made), one thread.

    PYTHONPATH=python .venv/bin/python bench/cis_profile.py --pkg /tmp/prof_pkg \\
        --scenes cornell_box,room_area_point --integrators pt,lvc,cis --size 32 --steps 1

--pkg: a folder holding a `lantern` package whose _core keeps its symbols: nanobind strips a
Release module, so build RelWithDebInfo with the Release flags, e.g. cmake -S . -B build/prof
-DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -DNDEBUG -g"
-DLANTERN_CUDA=OFF -DLANTERN_BUILD_PYTHON=ON (-g changes no code). The steps are counted
between two getsid() markers after a warm-up step (bench/cpu_speed_ab.py's child: start-up,
the BVH build and the first iteration's pilot are outside). --a PKG adds a second build's
column for every integrator (A/B), --keep DIR keeps the callgrind files."""
import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
from collections import defaultdict
from pathlib import Path

BENCH = Path(__file__).resolve().parent
sys.path.insert(0, str(BENCH))
import cpu_speed_ab  # noqa: E402


def parse_callgrind(path):
    """(names, self cost, edges (caller, callee) -> inclusive cost of the calls, inclusive
    cost, total) of a callgrind file with one event (Ir) and name compression."""
    names, self_cost, edges = {}, defaultdict(int), defaultdict(int)
    fn = cfn = None
    in_call = False
    total = None
    rx = re.compile(r"^(c?fn)=\((\d+)\)(?: (.*))?$")
    for line in open(path):
        line = line.rstrip("\n")
        if not line:
            continue
        c = line[0]
        if c.isdigit() or c in "+-*":
            parts = line.split()
            if len(parts) >= 2:
                if in_call:
                    edges[(fn, cfn)] += int(parts[1])
                else:
                    self_cost[fn] += int(parts[1])
            in_call = False
            continue
        m = rx.match(line)
        if m:
            kind, i, name = m.groups()
            if name:
                names[int(i)] = name
            if kind == "fn":
                fn = int(i)
            else:
                cfn = int(i)
        elif line.startswith("calls="):
            in_call = True
        elif line.startswith(("summary:", "totals:")):
            total = int(line.split()[1])
    incl = defaultdict(int, self_cost)
    for (a, b), v in edges.items():
        if a != b:
            incl[a] += v
    return names, self_cost, edges, incl, total


class Profile:
    def __init__(self, path):
        self.names, self.self_cost, self.edges, self.incl, self.total = parse_callgrind(path)

    def ids(self, rx):
        return [i for i, n in self.names.items() if re.search(rx, n)]

    def inclusive(self, rx):
        """Inclusive cost of the functions matching rx, none counted inside another."""
        ids = set(self.ids(rx))
        inner = sum(v for (a, b), v in self.edges.items() if a in ids and b in ids and a != b)
        return sum(self.incl.get(i, 0) for i in ids) - inner

    def calls(self, caller_rx, callee_rx):
        a, b = set(self.ids(caller_rx)), set(self.ids(callee_rx))
        return sum(v for (x, y), v in self.edges.items() if x in a and y in b)


CHUNK = r"^void lantern::wf::(camera_chunk|pt_chunk)<"
# (label, how): how = ("incl", rx) | ("calls", caller_rx, callee_rx); indented labels are parts
ROWS = [
    ("light pass", ("incl", r"^void lantern::wf::light_chunk<")),
    ("  trace", ("calls", r"light_chunk<", r"^void lantern::wf::trace<")),
    ("  shade (store, light tracing set-up, next)", ("incl", r"^lantern::bdpt_light_shade\(")),
    ("  light tracing: camera segments", ("calls", r"light_chunk<", r"camera_segments<")),
    ("  light tracing: splats", ("incl", r"^void lantern::splat_at<")),
    ("  generate", ("incl", r"^lantern::bdpt_light_generate\(")),
    ("cache index / build", ("incl", r"^void lantern::wf::index_cache_by_path<")),
    ("camera pass", ("incl", CHUNK)),
    ("  trace", ("calls", CHUNK, r"^void lantern::wf::trace<")),
    ("  sort", ("calls", CHUNK, r"^void lantern::wf::sort_queue<")),
    ("  shade (all)", ("incl", r"^lantern::(bdpt_camera_shade|pt_shade)\(")),
    ("    emission (s = 0)", ("incl", r"^lantern::bdpt_camera_emission\(")),
    ("    next event (s = 1)", ("incl", r"^lantern::bdpt_camera_nee\(")),
    ("    connections (s >= 2)", ("incl", r"^lantern::bdpt_camera_connect\(")),
    ("      candidate evaluation", ("incl", r"^lantern::bdpt_connect_in\(")),
    ("      shadow segments", ("incl", r"^lantern::bdpt_queue_connection\(")),
    ("  shadow rays (next event + connections)", ("calls", r"camera_chunk<|pt_chunk<",
                                                   r"EmbreeAccel::occluded\(")),
    ("  compact (both passes)", ("incl", r"^lantern::CpuExec::select_flagged\(")),
    ("  film", ("calls", CHUNK, r"^void lantern::wf::film<")),
]


def row_value(p, how):
    return p.inclusive(how[1]) if how[0] == "incl" else p.calls(how[1], how[2])


def callgrind(pkg, integ, scene, size, steps, keep=None):
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "cg.out")
        subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}",
                        "--instr-atstart=no", "--dump-before=getsid", sys.executable, "-c",
                        cpu_speed_ab.CHILD, pkg, integ, scene, str(size), str(steps), "1"],
                       capture_output=True, text=True, check=True,
                       env=dict(cpu_speed_ab.ENV, CG_INSTR_ON="1"))
        part = os.path.join(tmp, "cg.out.2")
        if keep:
            Path(keep).mkdir(parents=True, exist_ok=True)
            shutil.copy(part, Path(keep) / f"cg_{cpu_speed_ab.label(scene)}_{integ}.out")
        return Profile(part)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--pkg", required=True, help="the build to profile (B when --a is given)")
    ap.add_argument("--a", default=None, help="a second build, shown first (before)")
    ap.add_argument("--scenes", default="cornell_box,room_area_point")
    ap.add_argument("--integrators", default="pt,lvc,cis")
    ap.add_argument("--size", type=int, default=32)
    ap.add_argument("--steps", type=int, default=1)
    ap.add_argument("--keep", default=None)
    args = ap.parse_args(argv)
    builds = [("A", args.a), ("B", args.pkg)] if args.a else [("", args.pkg)]
    integs = args.integrators.split(",")
    for scene in args.scenes.split(","):
        cols = []
        for integ in integs:
            for tag, pkg in builds:
                keep = os.path.join(args.keep, tag or ".") if args.keep else None
                cols.append((f"{integ} {tag}".strip(),
                             callgrind(pkg, integ, scene, args.size, args.steps, keep)))
        base = cols[0][1].total
        print(f"\n# {cpu_speed_ab.label(scene)}: {args.size} px, {args.steps} step(s) x 4 spp, "
              "1 thread: instructions, millions (share of the column's steps)")
        print("| stage | " + " | ".join(c for c, _ in cols) + " |")
        print("|---|" + "---:|" * len(cols))
        print("| steps | " + " | ".join(f"{p.total / 1e6:.1f}" for _, p in cols) + " |")
        for label, how in ROWS:
            cells = []
            for _, p in cols:
                v = row_value(p, how)
                cells.append(f"{v / 1e6:.1f} ({100 * v / p.total:.0f} %)" if v else "-")
            if any(c != "-" for c in cells):
                print(f"| {label.replace('  ', '&nbsp;&nbsp;')} | " + " | ".join(cells) + " |")
        print(f"| steps / {cols[0][0]} | " +
              " | ".join(f"{p.total / base:.2f}x" for _, p in cols) + " |")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
