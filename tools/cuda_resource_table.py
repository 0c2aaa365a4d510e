"""The registers and stack frame of every CUDA kernel a build produced, as a Markdown table,
from the ptxas lines that nvcc's --resource-usage prints (cmake -DLANTERN_CUDA_RESOURCE_USAGE=ON):

    cmake --build build/cuda -j1 2>&1 | tee build.log
    python tools/cuda_resource_table.py build.log          # largest stack frame first

Kernels of each() lambdas are named by the function that launched them and the lambda's number
in it, e.g. `Renderer::run_camera_chunk #2`; CUB's by their CUB name."""
import re
import subprocess
import sys

ENTRY = re.compile(r"Compiling entry function '([^']+)' for '(sm_\d+)'")
FRAME = re.compile(r"(\d+) bytes stack frame, (\d+) bytes spill stores, (\d+) bytes spill loads")
REGS = re.compile(r"Used (\d+) registers")


def demangle(names):
    try:
        out = subprocess.run(["c++filt"], input="\n".join(names), capture_output=True,
                             text=True, check=True).stdout.splitlines()
        return out if len(out) == len(names) else names
    except (OSError, subprocess.CalledProcessError):
        return names


def short(name):
    lam = re.search(r"each_kernel<(?:lantern::)?(?:cuda_detail::)?([\w:]+)\([^)]*\)(?: const)?::"
                    r"(\{lambda.*?)>\(int,", name)
    if lam:  # nested lambdas (a kernel launched inside timed([&] { ... })): #outer.inner
        nums = re.findall(r"\{lambda\([^)]*\)#(\d+)\}", lam.group(2))
        return f"{lam.group(1)} #{'.'.join(nums)}"
    tag = re.search(r"__nv_dl_tag<[^,]*,\s*&?(?:lantern::)?(?:cuda_detail::)?([\w:]+),\s*(\d+)u?>",
                    name)
    if tag:
        return f"{tag.group(1)} #{tag.group(2)}"
    tag = re.search(r"__nv_hdl_wrapper_t<[^,]*,\s*__nv_dl_tag<[^,]*,\s*&?([\w:]+),\s*(\d+)u?>",
                    name)
    if tag:
        return f"{tag.group(1)} #{tag.group(2)}"
    m = re.match(r"(?:void )?([\w:]+?(?:Kernel|kernel|_kernel))\b", name)
    if m:
        return m.group(1).replace("lantern::cuda_detail::", "").split("::")[-1] if \
            "cub" not in m.group(1) else "cub::" + m.group(1).split("::")[-1]
    return name[:80]


def parse(text):
    rows, cur = [], None
    for line in text.splitlines():
        m = ENTRY.search(line)
        if m:
            cur = {"mangled": m.group(1), "arch": m.group(2)}
            continue
        if cur is None:
            continue
        m = FRAME.search(line)
        if m:
            cur["stack"], cur["spill_st"], cur["spill_ld"] = map(int, m.groups())
            continue
        m = REGS.search(line)
        if m:
            cur["regs"] = int(m.group(1))
            rows.append(cur)
            cur = None
    for r, name in zip(rows, demangle([r["mangled"] for r in rows])):
        r["name"] = short(name)
    return rows


def table(rows):
    seen, out = set(), []
    out.append("| kernel | arch | registers | stack frame (B) | spill stores / loads (B) |")
    out.append("|---|---|---:|---:|---:|")
    for r in sorted(rows, key=lambda r: (-r.get("stack", 0), -r["regs"], r["name"])):
        key = (r["name"], r["arch"], r["regs"], r.get("stack"))
        if key in seen:
            continue
        seen.add(key)
        out.append(f"| `{r['name']}` | {r['arch']} | {r['regs']} | {r.get('stack', 0)} | "
                   f"{r.get('spill_st', 0)} / {r.get('spill_ld', 0)} |")
    return "\n".join(out)


if __name__ == "__main__":
    text = open(sys.argv[1]).read() if len(sys.argv) > 1 else sys.stdin.read()
    rows = parse(text)
    if not rows:
        sys.exit("no ptxas resource lines found (build with -DLANTERN_CUDA_RESOURCE_USAGE=ON)")
    print(table(rows))
    over = [r for r in rows if r["regs"] > 128 or r.get("stack", 0) > 2048]
    print(f"\n{len(rows)} kernels; {len(over)} over 128 registers or 2 KB of stack frame")
