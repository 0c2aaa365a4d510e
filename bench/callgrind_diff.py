"""Per-function differences of two callgrind files' exclusive instruction counts (as
callgrind_annotate lists them), largest first; builds linked unstripped (nanobind_add_module's
NOSTRIP) name their functions:

    python bench/callgrind_diff.py A.cg B.cg [ROWS]

bench/cpu_speed_counts.py with CG_KEEP=DIR keeps each row's file of the counted steps."""
import re
import subprocess
import sys


def functions(path):
    """{function: exclusive instructions} of a callgrind file."""
    out = subprocess.run(["callgrind_annotate", "--threshold=100", path], capture_output=True,
                         text=True, check=True).stdout
    counts = {}
    for line in out.splitlines():
        m = re.match(r"\s*([\d,]+)\s+\([\s\d.]+%\)\s+(.*)$", line)
        if not m or "PROGRAM TOTALS" in line:
            continue
        name = re.sub(r" \[[^\]]*\]$", "", m.group(2))  # the object file's path
        counts[name] = counts.get(name, 0) + int(m.group(1).replace(",", ""))
    return counts


if __name__ == "__main__":
    a, b = functions(sys.argv[1]), functions(sys.argv[2])
    rows = int(sys.argv[3]) if len(sys.argv) > 3 else 40
    ta, tb = sum(a.values()), sum(b.values())
    print(f"total {ta:,} -> {tb:,} ({tb - ta:+,}, {(tb - ta) / ta:+.3%})")
    print(f"{'B - A':>12} {'A':>12} {'B':>12}  function")
    names = sorted(set(a) | set(b), key=lambda k: -abs(b.get(k, 0) - a.get(k, 0)))
    for k in names[:rows]:
        x, y = a.get(k, 0), b.get(k, 0)
        if x == y:
            break
        print(f"{y - x:+12,} {x:>12,} {y:>12,}  {k[:160]}")
