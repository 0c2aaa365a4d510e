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
import re
import subprocess
import sys

HEAD = re.compile(r"^(?:\.visible |\.weak |\.extern )*\.(entry|func)\s+(?:\([^)]*\)\s*)?([\w$]+)\(")
DEPOT = re.compile(r"\.local .*__local_depot\d+\[(\d+)\]")
PARAM = re.compile(r"\.param .*\.b8 \w+\[(\d+)\]")
CALLEE = re.compile(r"call(?:\.uni)?\s*(?:\([^)]*\),\s*)?(_Z[\w$]+)")
KERNEL_PREFIX = "_ZN7lantern11cuda_detail11each_kernel"


def parse(lines):
    """{function: {"depot": bytes, "calls": [(callee, param bytes)]}}."""
    funcs, cur, call = {}, None, None
    for line in lines:
        m = HEAD.match(line)
        if m:
            cur = m.group(2)
            funcs[cur] = {"depot": 0, "calls": []}
            continue
        if cur is None:
            continue
        m = DEPOT.search(line)
        if m:
            funcs[cur]["depot"] = int(m.group(1))
            continue
        if "{ // callseq" in line:
            call = {"bytes": 0, "callee": None, "next_line": False}
            continue
        if call is None:
            continue
        m = PARAM.search(line)
        if m:
            call["bytes"] += int(m.group(1))
        if re.match(r"\s*call", line):
            m = CALLEE.search(line)
            if m:
                call["callee"] = m.group(1)
            else:
                call["next_line"] = True  # the callee's name is on the next line
            continue
        if call["next_line"]:
            call["callee"], call["next_line"] = line.strip().rstrip(",").strip(), False
        if "} // callseq" in line:
            funcs[cur]["calls"].append((call["callee"], call["bytes"]))
            call = None
    return funcs


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
    funcs = parse(open(a.ptx).read().splitlines())
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
