"""ptxas on one kernel of a kept PTX file, alone (issue 30's measurements of the camera shade
kernel): the kernel's own module (tools/ptx_parse.kernel_ptx), `ptxas -arch=sm_90 -v
--entry=<it>` under `/usr/bin/time -v`, with its PTX lines, the local depot chain below it
(tools/ptx_local_chains.py's reading) and ptxas's full output written beside.

    nice -n 5 prlimit --as=8000000000 .venv/bin/python bench/ptxas_one_kernel.py \
        build/ptxchk/cuda_schedule_bdpt_camera.ptx "camera_chunk" --nth 2 --out /tmp/cam.log

--nth picks among the entries whose name holds the pattern, in the file's order (1-based:
camera_chunk's second lambda kernel is the shade, CI's `wf::camera_chunk #2.1`)."""

import argparse
import os
import re
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))
from ptx_parse import kernel_ptx, split_module  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("ptx")
    ap.add_argument("pattern", help="a substring of the entry's mangled name")
    ap.add_argument("--nth", type=int, default=1)
    ap.add_argument("--arch", default="sm_90")
    ap.add_argument("--timeout", type=int, default=600)
    ap.add_argument("--out", required=True, help="ptxas's output (and time -v) go here")
    ap.add_argument("--list", action="store_true", help="list the matching entries and stop")
    a = ap.parse_args()
    module, defs = split_module(open(a.ptx).read())
    entries = [n for n, (k, _) in defs.items() if k == "entry" and a.pattern in n]
    if a.list or not entries:
        for j, e in enumerate(entries, 1):
            print(j, len(kernel_ptx(module, defs, e).splitlines()), e)
        return 0 if entries else 1
    entry = entries[a.nth - 1]
    ptx = kernel_ptx(module, defs, entry)
    with tempfile.TemporaryDirectory() as tmp:
        src = os.path.join(tmp, "k.ptx")
        open(src, "w").write(ptx)
        r = subprocess.run(["/usr/bin/time", "-v", "timeout", str(a.timeout), "ptxas",
                            f"-arch={a.arch}", "-v", f"--entry={entry}", src,
                            "-o", os.path.join(tmp, "k.cubin")],
                           capture_output=True, text=True)
    text = r.stdout + r.stderr
    with open(a.out, "w") as f:
        f.write(f"# {entry}: {len(ptx.splitlines())} PTX lines\n{text}")
    pat = re.compile(re.escape(entry) + r"\n\s*(\d+) bytes stack frame, (\d+) bytes spill "
                     r"stores, (\d+) bytes spill loads\n.*?Used (\d+) registers.*?(\d+) bytes "
                     r"cumulative stack", re.S)
    m = pat.search(text)
    cpu = re.search(r"User time \(seconds\): ([\d.]+)", text)
    sys_t = re.search(r"System time \(seconds\): ([\d.]+)", text)
    rss = re.search(r"Maximum resident set size \(kbytes\): (\d+)", text)
    print(f"entry {entry}\nPTX lines {len(ptx.splitlines())}, rc {r.returncode}")
    if m:
        print(f"registers {m.group(4)}, cumulative stack {m.group(5)} B, own frame "
              f"{m.group(1)} B, kernel spills {m.group(2)} / {m.group(3)} B")
    if cpu and sys_t and rss:
        print(f"ptxas CPU {float(cpu.group(1)) + float(sys_t.group(1)):.1f} s, peak RSS "
              f"{int(rss.group(1)) / 1e6:.2f} GB")
    return r.returncode


if __name__ == "__main__":
    sys.exit(main())
