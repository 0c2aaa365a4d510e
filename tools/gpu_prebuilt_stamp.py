"""The stamp of a prebuilt CUDA backend (tools/gpu_prebuild.sh, gpu_check.sh --prebuilt): a
digest of every source the backend's objects are compiled from (native/src, tests/cuda,
tests/cpp headers, CMakeLists.txt) and of the nvcc that compiled them. The GPU machine computes
it again on its copy of the working tree (no git there) and refuses a prebuilt whose stamp
differs: objects of older sources linked with newer host code would break silently.

    python3 tools/gpu_prebuilt_stamp.py [--nvcc "$(nvcc --version | tail -1)"]"""
import argparse
import hashlib
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SOURCES = ("native/src", "tests/cuda", "tests/cpp")
SUFFIXES = (".h", ".hpp", ".cpp", ".cu", ".cuh", ".inl", "CMakeLists.txt")


def files():
    out = ["CMakeLists.txt"]
    for top in SOURCES:
        for d, dirs, names in os.walk(os.path.join(ROOT, top)):
            dirs[:] = sorted(x for x in dirs if not x.startswith(("build", ".", "__")))
            for n in sorted(names):
                if n.endswith(SUFFIXES):
                    out.append(os.path.relpath(os.path.join(d, n), ROOT).replace(os.sep, "/"))
    return sorted(out)


def nvcc_version():
    try:
        r = subprocess.run(["nvcc", "--version"], capture_output=True, text=True, timeout=60)
        return r.stdout.strip().splitlines()[-1] if r.stdout.strip() else "unknown"
    except (OSError, subprocess.SubprocessError):
        return "no nvcc"


def stamp(nvcc=None):
    h = hashlib.sha256()
    for rel in files():
        with open(os.path.join(ROOT, rel), "rb") as f:
            data = f.read().replace(b"\r\n", b"\n")
        h.update(rel.encode() + b"\0" + hashlib.sha256(data).digest())
    h.update(b"nvcc\0" + (nvcc or nvcc_version()).encode())
    return h.hexdigest()[:20]


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--nvcc", default=None, help="nvcc's version line (default: ask nvcc)")
    print(stamp(ap.parse_args().nvcc))
    sys.exit(0)
