"""CI's check of every CUDA kernel's resources (issue 30: at most 128 registers and 2 KB of
stack), on the PTX the build kept (CMake LANTERN_CUDA_KEEP_PTX; tools/setup.sh keeps it in
build/ptx), without the SASS build:

1. Registers, from the PTX alone: a kernel not measured here must carry a launch bound that
   holds ptxas to 128 registers (`.maxnreg`, or `.maxntid` x `.minnctapersm` with
   65536 / (threads x blocks) <= 128: `__launch_bounds__(256, 2)`), else it fails.
2. Stack frame and registers as ptxas reports them (`ptxas -arch=sm_90 -v --entry`, one kernel
   at a time, the same measure as tools/cuda_kernel_resources.py): for every kernel of at most
   --max-lines PTX lines (its body and the functions it calls), and for the larger ones (the
   shade kernels: 7-12 minutes of ptxas each on the 2-core VM) from the record
   tools/cuda_kernel_resources.json, keyed by a digest of the kernel's PTX, written by
   `--update` on a developer machine. A larger kernel whose PTX is not in the record is listed
   as not measured here (gpu_check.sh's SASS build measures it on the GPU machine).

    python3 tools/cuda_kernel_check.py build/ptx [--max-lines 60000] [--update] [-j 2]

Exit 1 when a kernel has no bound or measures over the limits."""

import argparse
import concurrent.futures
import hashlib
import json
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from cuda_kernel_resources import label, ptxas  # noqa: E402
from cuda_resource_table import demangle  # noqa: E402
from ptx_parse import closure, definitions  # noqa: E402

RECORD = os.path.join(os.path.dirname(os.path.abspath(__file__)), "cuda_kernel_resources.json")
MAX_REGS, MAX_STACK = 128, 2048
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
    """One row per distinct kernel (the same PTX in several files counts once)."""
    rows = {}
    for f in sorted(os.listdir(ptx_dir)):
        if not f.endswith(".ptx"):
            continue
        path = os.path.join(ptx_dir, f)
        defs = definitions(open(path).read())
        entries = [n for n, (k, _) in defs.items() if k == "entry"]
        for e, pretty in zip(entries, demangle(entries)):
            parts = closure(e, defs)
            h = hashlib.sha256()
            for p in parts:
                h.update("\n".join(defs[p][1]).encode())
            digest = h.hexdigest()[:24]
            if digest in rows:
                rows[digest]["files"].append(f[:-4])
                continue
            rows[digest] = {"mangled": e, "name": label(pretty, e), "ptx": path,
                            "files": [f[:-4]], "lines": sum(len(defs[p][1]) for p in parts),
                            "bound": reg_bound(defs[e][1]), "digest": digest}
    return list(rows.values())


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("ptx_dir")
    ap.add_argument("--max-lines", type=int, default=60000,
                    help="ptxas runs here on kernels of at most this many PTX lines")
    ap.add_argument("--update", action="store_true",
                    help="measure every kernel (hours on 2 cores) and write the record")
    ap.add_argument("--arch", default="sm_90")
    ap.add_argument("--timeout", type=int, default=300, help="seconds per kernel")
    ap.add_argument("-j", type=int, default=2)
    a = ap.parse_args()
    if not os.path.isdir(a.ptx_dir) or not any(f.endswith(".ptx") for f in os.listdir(a.ptx_dir)):
        print(f"cuda_kernel_check: no PTX in {a.ptx_dir} (a build without CUDA?): nothing to check")
        return 0
    rows = kernels(a.ptx_dir)
    record = {}
    if os.path.exists(RECORD):
        record = json.load(open(RECORD)).get("kernels", {})
    todo = [r for r in rows if a.update or (r["digest"] not in record and
                                             r["lines"] <= a.max_lines)]
    with concurrent.futures.ThreadPoolExecutor(max_workers=a.j) as pool:
        futs = {pool.submit(ptxas, r["ptx"], r["mangled"], a.arch, a.timeout): r for r in todo}
        for fut in concurrent.futures.as_completed(futs):
            res, r = fut.result(), futs[fut]
            if "regs" in res:
                r.update(regs=res["regs"], stack=res.get("stack", 0) + res["callee_stack"],
                         source="ptxas here")
            else:
                r["error"] = f"ptxas rc {res['rc']}"
    failed = 0
    print("| kernel | files | PTX lines | bound | registers | stack (B) | from |")
    print("|---|---|---:|---:|---:|---:|---|")
    for r in sorted(rows, key=lambda r: -r["lines"]):
        if "regs" not in r and r["digest"] in record:
            r.update(regs=record[r["digest"]]["regs"], stack=record[r["digest"]]["stack"],
                     source="record")
        why = []
        if (r["bound"] is None or r["bound"] > MAX_REGS) and "regs" not in r:
            why.append(f"not measured here and no launch bound holds it to {MAX_REGS} "
                       f"registers")
        if r.get("regs", 0) > MAX_REGS or r.get("stack", 0) > MAX_STACK:
            why.append(f"over {MAX_REGS} registers or {MAX_STACK} B of stack")
        if "error" in r:
            why.append(r["error"])
        failed += bool(why)
        src = r.get("source", "not measured here (not in the record; larger than --max-lines)")
        print(f"| `{r['name']}`{' **FAIL: ' + '; '.join(why) + '**' if why else ''} | "
              f"{', '.join(sorted(set(r['files'])))} | {r['lines']:,} | {r['bound']} | "
              f"{r.get('regs', '')} | {r.get('stack', '')} | {src} |")
    measured = sum("regs" in r for r in rows)
    print(f"\n{len(rows)} kernels: {failed} failing, {measured} measured (ptxas here or the "
          f"record), {len(rows) - measured} with their register bound checked only")
    if a.update:
        keep = {r["digest"]: {"name": r["name"], "regs": r["regs"], "stack": r["stack"]}
                for r in rows if "regs" in r}
        with open(RECORD, "w") as f:
            json.dump({"arch": a.arch, "kernels": keep}, f, indent=1, sort_keys=True)
            f.write("\n")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
