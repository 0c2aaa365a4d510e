"""Registers and stack frame of every CUDA kernel of every CUDA object (the backend, the compile
checks, the conformance test), one kernel at a time, without the SASS build.

The full SASS build runs ptxas over every kernel of a translation unit in one process (1690 s
for the schedule on a 2-core VM). This script instead compiles each CUDA translation unit of a
configured build to PTX with the build's own nvcc flags (from `ninja -t commands`), then runs
ptxas on one entry at a time (`--entry`) under a timeout, so one slow kernel costs only itself
and a change can be measured on the kernels it touches (run it under `nice`; it adds none of
its own, so its ptxas runs share the machine as evenly as the other niced work):

    cmake -S . -B build/ptx -G Ninja -DLANTERN_CUDA=ON -DCMAKE_CUDA_ARCHITECTURES=90-virtual \
          -DLANTERN_BUILD_TESTS=OFF -DLANTERN_BUILD_PYTHON=OFF
    nice python tools/cuda_kernel_resources.py build/ptx --ptx-dir /tmp/ptx      # all kernels
    nice python tools/cuda_kernel_resources.py build/ptx --ptx-dir /tmp/ptx --only pt_chunk
    nice python tools/cuda_kernel_resources.py --reuse --ptx-dir /tmp/ptx --tu cuda_schedule_pt

Prints the Markdown table of tools/cuda_resource_table.py (largest stack frame first) with a
column for the largest stack frame among the functions a kernel calls (non-inlined device
functions have frames of their own, which the driver adds along the deepest call chain).
"""
import argparse
import concurrent.futures
import os
import re
import shlex
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cuda_resource_table import demangle, short  # noqa: E402
from ptx_parse import depots  # noqa: E402

OWNER = re.compile(r"lantern::((?:wf|CudaExec|cuda_detail::Renderer)::\w+)")
LAMBDA = re.compile(r"\{lambda\([^)]*\)#(\d+)\}")

ENTRY = re.compile(r"^(?:\.visible |\.weak )*\.entry\s+([\w$]+)\(", re.M)
FUNC = re.compile(r"Function properties for ([\w$]+)")
FRAME = re.compile(r"(\d+) bytes stack frame, (\d+) bytes spill stores, (\d+) bytes spill loads")
REGS = re.compile(r"Used (\d+) registers")


def mangled_names(mangled):
    """The source names of an Itanium-mangled symbol, in order (<length><identifier> runs)."""
    out, i = [], 0
    while i < len(mangled):
        m = re.match(r"(\d+)", mangled[i:])
        if not m:
            i += 1
            continue
        n, j = int(m.group(1)), i + len(m.group(1))
        word = mangled[j:j + n]
        if n and re.fullmatch(r"[A-Za-z_]\w*", word):
            out.append(word)
            i = j + n
        else:
            i = j
    return out


def label(name, mangled):
    """A kernel's name in the table: the schedule function (and executor primitive) that
    launches it and the lambda's number in each, e.g. `wf::pt_chunk #2.1`; CUB's by CUB name."""
    if "each_kernel" not in name and "each_kernel" not in mangled:
        return short(name)
    if name.startswith("_Z"):  # c++filt could not: the names alone
        words = mangled_names(mangled)
        own = [f"{a}::{b}" for a, b in zip(words, words[1:])
               if a in ("wf", "CudaExec", "Renderer")]
        return " via ".join(dict.fromkeys(own[::-1])) or name[:60]
    own = list(dict.fromkeys(OWNER.findall(name)))
    lam = LAMBDA.findall(name.split("(int, ")[0])
    own = [o.replace("cuda_detail::", "") for o in own]
    text = own[-1] if own else name[:60]
    if len(own) > 1:
        text = f"{own[-1]} via {own[0]}" if own[0].startswith("CudaExec") else own[0]
    return text + (f" #{'.'.join(lam)}" if lam else "")


def ptx_commands(build_dir):
    """nvcc commands of the build's .cu sources, rewritten to write PTX."""
    out = subprocess.run(["ninja", "-C", build_dir, "-t", "commands"], capture_output=True,
                         text=True, check=True).stdout
    cmds = {}
    for line in out.splitlines():
        if "nvcc" not in line or " -c " not in line:
            continue  # every CUDA object: the core's and the compile checks' and tests''
        args = shlex.split(line)
        src = args[args.index("-c") + 1]
        keep, skip = [], 0
        for a in args:
            if skip:
                skip -= 1
                continue
            if a in ("-MD",):
                continue
            if a in ("-MT", "-MF", "-o", "-c"):
                skip = 1
                continue
            if a.startswith("--generate-code") or a.startswith("-gencode"):
                keep.append("-arch=compute_90")
                continue
            keep.append(a)
        keep = [a for a in keep if a != src]
        cmds[os.path.basename(src).rsplit(".", 1)[0]] = keep + ["-ptx", src]
    return cmds


def build_ptx(build_dir, ptx_dir, only_tu):
    os.makedirs(ptx_dir, exist_ok=True)
    for name, cmd in sorted(ptx_commands(build_dir).items()):
        if only_tu and name not in only_tu:
            continue
        path = os.path.join(ptx_dir, name + ".ptx")
        print(f"nvcc -ptx {name}", file=sys.stderr, flush=True)
        subprocess.run(cmd + ["-o", path], check=True)


def ptxas(ptx, entry, arch, timeout):
    cmd = ["timeout", str(timeout), "ptxas", f"-arch={arch}", "-v", f"--entry={entry}",
           ptx, "-o", os.devnull]
    r = subprocess.run(cmd, capture_output=True, text=True)
    text = r.stdout + r.stderr
    row = {"mangled": entry, "tu": os.path.basename(ptx)[:-4], "rc": r.returncode,
           "callee_stack": 0}
    cur = None
    for line in text.splitlines():
        m = FUNC.search(line)
        if m:
            cur = m.group(1)
            continue
        m = FRAME.search(line)
        if m:
            stack, st, ld = map(int, m.groups())
            if cur is not None and cur != entry:
                row["callee_stack"] = max(row["callee_stack"], stack)
            else:
                row["stack"], row["spill_st"], row["spill_ld"] = stack, st, ld
            cur = None
            continue
        m = REGS.search(line)
        if m:
            row["regs"] = int(m.group(1))
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("build_dir", nargs="?", help="a configured CUDA build (Ninja)")
    ap.add_argument("--ptx-dir", required=True)
    ap.add_argument("--reuse", action="store_true", help="use the PTX already in --ptx-dir")
    ap.add_argument("--tu", action="append", help="only this translation unit (repeatable)")
    ap.add_argument("--only", help="only kernels whose table name contains this")
    ap.add_argument("--skip", action="append", help="not the kernels whose table name contains "
                    "this (repeatable)")
    ap.add_argument("--arch", default="sm_90")
    ap.add_argument("--timeout", type=int, default=900, help="seconds per kernel")
    ap.add_argument("-j", type=int, default=1, help="ptxas processes at once")
    a = ap.parse_args()
    if not a.reuse:
        if not a.build_dir:
            sys.exit("give a build dir, or --reuse")
        build_ptx(a.build_dir, a.ptx_dir, a.tu)
    jobs, depot = [], {}
    for f in sorted(os.listdir(a.ptx_dir)):
        if not f.endswith(".ptx") or (a.tu and f[:-4] not in a.tu):
            continue
        path = os.path.join(a.ptx_dir, f)
        text = open(path).read()
        entries = ENTRY.findall(text)
        depot.update(depots(text))
        for e, name in zip(entries, demangle(entries)):
            if a.only and a.only not in label(name, e):
                continue
            if any(x in label(name, e) for x in a.skip or []):
                continue
            jobs.append((path, e, name))
    rows = []
    with concurrent.futures.ThreadPoolExecutor(max_workers=a.j) as pool:
        futs = {pool.submit(ptxas, p, e, a.arch, a.timeout): n for p, e, n in jobs}
        for fut in concurrent.futures.as_completed(futs):
            r = fut.result()
            r["name"] = label(futs[fut], r["mangled"])
            rows.append(r)
            print(f"{r['name']} ({r['tu']}): {r.get('regs')} registers, {r.get('stack')} B stack, "
                  f"callees {r['callee_stack']} B, spills {r.get('spill_st')} / "
                  f"{r.get('spill_ld')} B, rc {r['rc']}", file=sys.stderr, flush=True)
    print("| kernel | file | registers | stack frame (B) | callees' largest frame (B) | "
          "spill stores / loads (B) | PTX depot (B) |")
    print("|---|---|---:|---:|---:|---:|---:|")
    for r in sorted(rows, key=lambda r: (-r.get("stack", depot.get(r["mangled"], 0)),
                                         -r.get("regs", 0), r["name"])):
        d = f"{depot.get(r['mangled'], 0):,}"
        if "regs" not in r:
            why = "ptxas timed out" if r["rc"] in (124, -9, 137) else f"ptxas failed (rc {r['rc']})"
            print(f"| `{r['name']}` | {r['tu']} | {why} | | | | {d} |")
            continue
        print(f"| `{r['name']}` | {r['tu']} | {r['regs']} | {r.get('stack', 0):,} | "
              f"{r['callee_stack']:,} | {r.get('spill_st', 0)} / {r.get('spill_ld', 0)} | {d} |")
    over = [r for r in rows if r.get("regs", 999) > 128 or
            r.get("stack", 0) + r["callee_stack"] > 2048]
    print(f"\n{len(rows)} kernels; {len(over)} over 128 registers or 2 KB of stack "
          f"(own frame + largest callee's)")


if __name__ == "__main__":
    main()
