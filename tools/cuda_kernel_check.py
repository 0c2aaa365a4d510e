"""CI's check of every CUDA kernel's resources (issue 30: at most 128 registers and 2 KB of
stack), on the PTX the build kept (CMake LANTERN_CUDA_KEEP_PTX; tools/setup.sh keeps it in
build/ptx), without the SASS build: ptxas (`ptxas -arch=sm_90 -v`, the build's -O3) measures
every kernel, registers and stack frame (with its callees': the cumulative stack), one kernel at
a time, each from a PTX module of its own (ptx_parse.kernel_ptx: reading a whole translation
unit's 38 MB of PTX cost ptxas 5 s of CPU per kernel), the same code once (ptx_parse.
code_digest: the trace kernel is compiled in six places), the largest first, -j at a time.

    python3 tools/cuda_kernel_check.py build/ptx [-j 2] [--max-lines N] [--record] [--update]

--max-lines N leaves kernels of more PTX lines to the record tools/cuda_kernel_resources.json
(keyed by the code digest, written by --update); a kernel neither measured nor in the record
fails, named, with the command that refreshes the record. --record takes every kernel whose code
digest is in the record from it (ptxas measured that same code when the record was written) and
measures only the others here: CI's check then costs ptxas only for kernels changed since the
last --update. --update measures every kernel (up to --max-lines when given) and rewrites the
record; with --record as well it measures only the kernels the record lacks and rewrites it with
the current kernels (recorded or measured; digests no longer built are dropped): the refresh
after a merge costs the changed kernels' ptxas, not all of it. A kernel's launch bound
(`.maxnreg`, `.maxntid` x `.minnctapersm`) is listed.

Exit 1 when a kernel measures over the limits or could not be measured."""

import argparse
import concurrent.futures
import json
import os
import re
import resource
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cuda_kernel_resources import label  # noqa: E402
from cuda_resource_table import demangle  # noqa: E402
from ptx_parse import closure, code_digest, kernel_ptx, split_module  # noqa: E402

RECORD = os.path.join(os.path.dirname(os.path.abspath(__file__)), "cuda_kernel_resources.json")
MAX_REGS, MAX_STACK = 128, 2048
FRAME = re.compile(r"(\d+) bytes stack frame, (\d+) bytes spill stores, (\d+) bytes spill loads")
REGS = re.compile(r"Used (\d+) registers")
CUMULATIVE = re.compile(r"(\d+) bytes cumulative stack size")
PROPS = re.compile(r"Function properties for ([\w$]+)")


def reg_bound(body):
    """The most registers ptxas may give a kernel with these directives (None: unbounded)."""
    text = "\n".join(body[:40])
    m = re.search(r"\.maxnreg\s+(\d+)", text)
    if m:
        return int(m.group(1))
    t = re.search(r"\.maxntid\s+(\d+)(?:,\s*(\d+))?(?:,\s*(\d+))?", text)
    b = re.search(r"\.minnctapersm\s+(\d+)", text)
    if t and b:
        threads = int(t.group(1)) * int(t.group(2) or 1) * int(t.group(3) or 1)
        return min(255, 65536 // (threads * int(b.group(1))))
    return None


def kernels(ptx_dir):
    """One row per distinct kernel code (the same code in several files or lambdas counts once;
    `names` lists them all), with the text of its own PTX module."""
    rows = {}
    for f in sorted(os.listdir(ptx_dir)):
        if not f.endswith(".ptx"):
            continue
        path = os.path.join(ptx_dir, f)
        module, defs = split_module(open(path).read())
        entries = [n for n, (k, _) in defs.items() if k == "entry"]
        for e, pretty in zip(entries, demangle(entries)):
            digest = code_digest(e, defs)
            name = label(pretty, e)
            if digest in rows:
                rows[digest]["files"].append(f[:-4])
                rows[digest]["names"].append(name)
                continue
            rows[digest] = {"mangled": e, "name": name, "names": [name], "files": [f[:-4]],
                            "lines": sum(len(defs[p][1]) for p in closure(e, defs)),
                            "bound": reg_bound(defs[e][1]), "digest": digest,
                            "ptx": kernel_ptx(module, defs, e)}
    return list(rows.values())


def ptxas(row, tmp, arch, timeout):
    """Registers, cumulative stack and spills of one kernel, from ptxas on its own module."""
    path = os.path.join(tmp, row["digest"] + ".ptx")
    with open(path, "w") as f:
        f.write(row["ptx"])
    t0 = time.monotonic()
    r = subprocess.run(["timeout", str(timeout), "ptxas", f"-arch={arch}", "-v",
                        f"--entry={row['mangled']}", path, "-o", os.devnull],
                       capture_output=True, text=True)
    os.unlink(path)
    out = {"rc": r.returncode, "seconds": time.monotonic() - t0}
    text = r.stdout + r.stderr
    cur, frames = None, {}
    for line in text.splitlines():
        m = PROPS.search(line)
        if m:
            cur = m.group(1)
            continue
        m = FRAME.search(line)
        if m and cur:
            frames[cur] = tuple(map(int, m.groups()))
            cur = None
            continue
        m = REGS.search(line)
        if m:
            out["regs"] = int(m.group(1))
        m = CUMULATIVE.search(line)
        if m:
            out["cumulative"] = int(m.group(1))
    if r.returncode != 0 or "regs" not in out:
        out.pop("regs", None)
        out["error"] = ("ptxas timed out" if r.returncode in (124, 137) else
                        f"ptxas rc {r.returncode}: {text.strip().splitlines()[-1:] or ''}")
        return out
    own = frames.get(row["mangled"], (0, 0, 0))
    callee = max((v[0] for k, v in frames.items() if k != row["mangled"]), default=0)
    # the frame the kernel needs: ptxas's cumulative size (own frame and its deepest callee
    # chain) where it reports one, else the own frame and the largest callee's
    out["stack"] = out.pop("cumulative", own[0] + callee)
    out["frame"], out["spill_st"], out["spill_ld"] = own
    out["spill_st"] += sum(v[1] for k, v in frames.items() if k != row["mangled"])
    out["spill_ld"] += sum(v[2] for k, v in frames.items() if k != row["mangled"])
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("ptx_dir")
    ap.add_argument("--max-lines", type=int, default=None,
                    help="measure only kernels of at most this many PTX lines (the larger ones "
                         "from the record); default: every kernel")
    ap.add_argument("--update", action="store_true",
                    help="measure every kernel (up to --max-lines when given; with --record only "
                         "those the record lacks) and write the record")
    ap.add_argument("--record", action="store_true",
                    help="take every kernel whose code digest is in the record from it; "
                         "measure only the others")
    ap.add_argument("--bounded-unmeasured-ok", action="store_true",
                    help="a kernel not measured (over --max-lines, not in the record) passes when "
                         "a launch bound holds it to 128 registers (listed as bound only: its "
                         "stack is unchecked)")
    ap.add_argument("--arch", default="sm_90")
    ap.add_argument("--timeout", type=int, default=1800, help="seconds per kernel")
    ap.add_argument("-j", type=int, default=2, help="ptxas processes at once")
    ap.add_argument("--one-at-a-time", type=int, default=300000, metavar="LINES",
                    help="kernels of more PTX lines run one after another in one lane, "
                         "never beside each other (ptxas passed 7 and 8.7 GB on the pt and camera "
                         "shade kernels, 414,000 and 443,000 lines, and the OOM killer took it at "
                         "23.7 GB on main's 753,000-line pt shade)")
    a = ap.parse_args()
    if not os.path.isdir(a.ptx_dir) or not any(f.endswith(".ptx") for f in os.listdir(a.ptx_dir)):
        print(f"cuda_kernel_check: no PTX in {a.ptx_dir} (a build without CUDA?): nothing to check")
        return 0
    t0 = time.monotonic()
    rows = kernels(a.ptx_dir)
    record = {}
    if os.path.exists(RECORD) and (a.record or not a.update):
        record = json.load(open(RECORD)).get("kernels", {})
    todo = [r for r in rows if a.max_lines is None or r["lines"] <= a.max_lines]
    if a.record:  # the same code was measured when the record was written
        todo = [r for r in todo if r["digest"] not in record]
    todo.sort(key=lambda r: -r["lines"])  # the largest first: the pool's lanes end together
    with tempfile.TemporaryDirectory() as tmp, \
            concurrent.futures.ThreadPoolExecutor(max_workers=a.j) as pool:
        def measure(rs):  # one after another
            for r in rs:
                r.update(ptxas(r, tmp, a.arch, a.timeout), source="ptxas here")
                print(f"cuda_kernel_check: {r['name']} ({r['lines']:,} lines): {r.get('regs')} "
                      f"registers, {r.get('stack')} B stack, {r['seconds']:.0f} s",
                      file=sys.stderr, flush=True)
        # the largest kernels in one lane, one after another, the rest in the others
        big = [r for r in todo if r["lines"] > a.one_at_a_time]
        jobs = ([big] if big else []) + [[r] for r in todo if r not in big]
        for fut in [pool.submit(measure, rs) for rs in jobs]:
            fut.result()
    cpu = resource.getrusage(resource.RUSAGE_CHILDREN)
    failed = 0
    refresh = f"python3 tools/cuda_kernel_check.py {a.ptx_dir} --update" + (
        f" --max-lines {a.max_lines}" if a.max_lines is not None else "")
    print("| kernel | files | PTX lines | bound | registers | stack (B) | spill stores / loads (B) "
          "| ptxas (s) | from |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---|")
    for r in sorted(rows, key=lambda r: -r["lines"]):
        if "regs" not in r and "error" not in r and r["digest"] in record:
            rec = record[r["digest"]]
            r.update(regs=rec["regs"], stack=rec["stack"], spill_st=rec.get("spill_st", ""),
                     spill_ld=rec.get("spill_ld", ""), source="record")
        why = []
        if "error" in r:
            why.append(r["error"])
        elif "regs" not in r and a.bounded_unmeasured_ok and (r["bound"] or 999) <= MAX_REGS:
            r["source"] = "NOT MEASURED: launch bound only (--bounded-unmeasured-ok)"
        elif "regs" not in r:
            why.append(f"not measured: larger than --max-lines and its code is not in the "
                       f"record (stale after a change): refresh it with `{refresh}`")
        if r.get("regs", 0) > MAX_REGS or r.get("stack", 0) > MAX_STACK:
            why.append(f"over {MAX_REGS} registers or {MAX_STACK} B of stack")
        failed += bool(why)
        also = f" (also {len(r['names']) - 1} more)" if len(r["names"]) > 1 else ""
        secs = f"{r['seconds']:.1f}" if "seconds" in r else ""
        print(f"| `{r['name']}`{also}{' **FAIL: ' + '; '.join(why) + '**' if why else ''} | "
              f"{', '.join(sorted(set(r['files'])))} | {r['lines']:,} | {r['bound']} | "
              f"{r.get('regs', '')} | {r.get('stack', '')} | "
              f"{r.get('spill_st', '')} / {r.get('spill_ld', '')} | {secs} | "
              f"{r.get('source', 'not measured')} |")
    measured = sum("regs" in r for r in rows)
    kernels_all = sum(len(r["names"]) for r in rows)
    print(f"\n{kernels_all} kernels, {len(rows)} distinct: {failed} failing, {measured} measured "
          f"(ptxas here or the record); {time.monotonic() - t0:.0f} s, ptxas CPU "
          f"{cpu.ru_utime + cpu.ru_stime:.0f} s, -j {a.j}")
    if a.update:
        keep = {r["digest"]: {"name": r["name"], "regs": r["regs"], "stack": r["stack"],
                              "spill_st": r["spill_st"], "spill_ld": r["spill_ld"]}
                for r in rows if r.get("source") in ("ptxas here", "record") and "regs" in r}
        with open(RECORD, "w") as f:
            json.dump({"arch": a.arch, "kernels": keep}, f, indent=1, sort_keys=True)
            f.write("\n")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
