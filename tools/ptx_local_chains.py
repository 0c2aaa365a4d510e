"""The deepest chain of local memory under each `each()` kernel of a PTX file: along every call
path from the kernel, the sum of each function's local depot (what cicc put in local memory)
and the aggregate .param / .retval bytes passed at each call; the deepest path is a model of
the stack frame ptxas will give the kernel (only a guide: ptxas's frames came out 236-503 B
above it on 2026-12-03, bench/results/2026-12-03-progregs).

    python3 tools/ptx_local_chains.py PTX [KERNEL_SUBSTRING] [--lower "mix_eval:376,f"] [--min B]

KERNEL_SUBSTRING (default pt_chunk) picks kernels by their demangled name. --lower takes
depots down for a what-if: "name" zeroes the depots of functions whose name contains it,
"name:N" lowers them by N bytes (which chain is next deepest once one is fixed). PTX: from
tools/cuda_kernel_resources.py --ptx-dir, or the build's kept PTX (build/ptx)."""
import argparse
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ptx_parse import call_graph  # noqa: E402

KERNEL_PREFIX = "_ZN7lantern11cuda_detail11each_kernel"


def deepest(funcs):
    memo = {}

    def walk(f, path=()):
        if f in memo:
            return memo[f]
        if f not in funcs or f in path:
            return 0, []
        d = funcs[f]["depot"]
        best = (d, [(f, d, 0)])
        for callee, nbytes in funcs[f]["calls"]:
            total, chain = walk(callee, path + (f,))
            if d + nbytes + total > best[0]:
                best = (d + nbytes + total, [(f, d, nbytes)] + chain)
        memo[f] = best
        return best
    return walk


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("ptx")
    ap.add_argument("kernel", nargs="?", default="pt_chunk")
    ap.add_argument("--lower", default="", help='"name" or "name:N", comma-separated')
    ap.add_argument("--min", type=int, default=200, help="print chains of at least B bytes")
    a = ap.parse_args()
    funcs = call_graph(open(a.ptx).read().splitlines())
    names = list(funcs)
    pretty = dict(zip(names, subprocess.run(["c++filt"], input="\n".join(names),
                                            capture_output=True, text=True).stdout.splitlines()))
    for item in filter(None, a.lower.split(",")):
        name, _, by = item.partition(":")
        for f in funcs:
            if name in pretty.get(f, f).split("(")[0]:
                funcs[f]["depot"] = max(0, funcs[f]["depot"] - int(by)) if by else 0
    walk = deepest(funcs)

    def short(n):
        x = pretty.get(n, n)
        return "KERNEL" if "each_kernel" in x else x.split("(")[0][-50:]
    for f in funcs:
        if f.startswith(KERNEL_PREFIX) and a.kernel in pretty.get(f, ""):
            total, chain = walk(f)
            if total >= a.min:
                print(total, f[60:130])
                print("   ", " -> ".join(f"{short(n)}[{d}+{b}]" for n, d, b in chain))
    return 0


if __name__ == "__main__":
    sys.exit(main())
