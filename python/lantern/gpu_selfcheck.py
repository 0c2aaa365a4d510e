"""The GPU self-check: before a session trusts a GPU with `backend="auto"`, a child process
renders a small conformance set on that GPU and on the CPU and compares them (issue 30).

Contract:
- `auto_backend_veto(info)` -> None (use the GPU) or the reason to render on the CPU instead,
  a sentence for the render report that names the failing case. Only "auto" asks: an artist
  who picks the CUDA device ("cuda") forces the GPU and skips the check.
- The verdict is cached per card, compute capability, driver and build of `lantern._core`
  (a file in the user's cache folder, `LANTERN_CACHE_DIR` to move it): pass or fail, the check
  runs once per key. `LANTERN_GPU_SELFCHECK=off` skips it (trust the GPU), `=again` runs it
  again and replaces the cached verdict.
- The check runs in a separate process (gpu_selfcheck_run.py) under a timeout: a device fault,
  a hang or a crash costs that process, never Blender's. It fails on a launch error, a session
  that fell back to the CPU, a NaN, a negative or absurd pixel, or an image that disagrees with
  the CPU's (lantern.metrics.compare_renders, confirmed with fresh seeds before it counts).
- `DOUBLE` ("pass", "fail", "nan", "hang", "crash") makes the child stand a test double in
  for the GPU renderer: the tests of this module run on machines without a GPU.

    python -m lantern gpu-check [--again]     # run (or read) the verdict for this GPU
"""

import hashlib
import importlib.util
import json
import os
import subprocess
import sys
import time
from pathlib import Path

CHECK_VERSION = 2          # a change to the conformance set makes old verdicts stale
                           # (2: strands and motion blur joined it)
TIMEOUT_S = 180.0          # the whole check, first CUDA context and module load included
DOUBLE = None              # tests: the child's stand-in for the GPU (see module docstring)
CASES = None               # tests: a subset of gpu_selfcheck_run.CASES ("scene/integrator")

_memo = {}                 # key -> verdict, for the sessions of this process


def cache_dir():
    env = os.environ.get("LANTERN_CACHE_DIR")
    if env:
        return Path(env)
    if sys.platform == "win32":
        return Path(os.environ.get("LOCALAPPDATA", Path.home() / "AppData" / "Local")) / "lantern"
    if sys.platform == "darwin":
        return Path.home() / "Library" / "Caches" / "lantern"
    return Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "lantern"


def cache_file():
    return cache_dir() / "gpu_selfcheck.json"


_build_id = None


def build_id():
    """A digest of the native module's file: a rebuilt core is checked again."""
    global _build_id
    if _build_id is None:
        spec = importlib.util.find_spec("lantern._core")
        h = hashlib.sha256()
        if spec is not None and spec.origin and os.path.isfile(spec.origin):
            with open(spec.origin, "rb") as f:
                for chunk in iter(lambda: f.read(1 << 20), b""):
                    h.update(chunk)
        _build_id = h.hexdigest()[:16]
    return _build_id


def key(info):
    return (f"{info.get('name', '')}|cc {info.get('compute_capability', '')}|driver "
            f"{info.get('driver_version', 0)}|build {build_id()}|check {CHECK_VERSION}")


def _read_cache():
    try:
        with open(cache_file()) as f:
            data = json.load(f)
        return data if isinstance(data, dict) else {}
    except (OSError, ValueError):
        return {}


def _write_cache(k, verdict):
    """Atomic: another Blender on the same machine may be reading or writing it."""
    path = cache_file()
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        data = _read_cache()
        data[k] = verdict
        tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")
        with open(tmp, "w") as f:
            json.dump(data, f, indent=1, sort_keys=True)
        os.replace(tmp, path)
    except OSError:
        pass  # a read-only home: the verdict still holds for this process


def _child_command():
    cmd = [sys.executable, "-m", "lantern.gpu_selfcheck_run"]
    if DOUBLE:
        cmd += ["--double", str(DOUBLE)]
    if CASES:
        cmd += ["--cases", ",".join(CASES)]
    return cmd


def _child_env():
    env = dict(os.environ)
    root = str(Path(__file__).resolve().parent.parent)  # the folder holding the lantern package
    env["PYTHONPATH"] = os.pathsep.join([root] + [p for p in [env.get("PYTHONPATH")] if p])
    env["LANTERN_GPU_SELFCHECK_CHILD"] = "1"
    return env


def _last_started(text):
    """The case the child was rendering when it stopped (its progress lines)."""
    started = [line[len("start "):].strip() for line in (text or "").splitlines()
               if line.startswith("start ")]
    return started[-1] if started else None


def _decode(out):
    return out.decode("utf-8", "replace") if isinstance(out, bytes) else (out or "")


def run_check(timeout=None):
    """Run the conformance set in a child process; the verdict dict (ok, reason, case,
    seconds)."""
    timeout = TIMEOUT_S if timeout is None else float(timeout)
    t0 = time.monotonic()
    try:
        r = subprocess.run(_child_command(), env=_child_env(), capture_output=True,
                           timeout=timeout, stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired as e:
        case = _last_started(_decode(e.stdout))
        where = f" in case '{case}'" if case else ""
        return {"ok": False, "case": case or "",
                "reason": f"the GPU self-check timed out after {timeout:.0f} s{where}",
                "seconds": time.monotonic() - t0}
    except OSError as e:
        return {"ok": False, "case": "", "seconds": time.monotonic() - t0,
                "reason": f"the GPU self-check could not start ({e})"}
    out, err = _decode(r.stdout), _decode(r.stderr)
    result = None
    for line in out.splitlines():
        if line.startswith("result "):
            try:
                result = json.loads(line[len("result "):])
            except ValueError:
                result = None
    if result is None or r.returncode not in (0, 1):
        case = _last_started(out)
        where = f" in case '{case}'" if case else ""
        how = (f"was killed by signal {-r.returncode}" if r.returncode < 0
               else f"exited with status {r.returncode}")
        tail = err.strip().splitlines()[-1:] if err.strip() else []
        detail = f": {tail[0][:200]}" if tail else ""
        return {"ok": False, "case": case or "", "seconds": time.monotonic() - t0,
                "reason": f"the GPU self-check process {how}{where}{detail}"}
    result["seconds"] = time.monotonic() - t0
    return result


def verdict(info, again=False, timeout=None):
    """The cached verdict for this GPU (info: session.cuda_info()), running the check when
    there is none. Adds "cached": whether it came from an earlier check."""
    k = key(info)
    if not again:
        if k in _memo:
            return dict(_memo[k], cached=True)
        cached = _read_cache().get(k)
        if isinstance(cached, dict) and "ok" in cached:
            _memo[k] = cached
            return dict(cached, cached=True)
    v = run_check(timeout)
    v["when"] = time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())
    _memo[k] = v
    _write_cache(k, v)
    return dict(v, cached=False)


def auto_backend_veto(info):
    """None when "auto" may take the GPU `info` describes, else why not (for the report)."""
    if not info.get("available") or os.environ.get("LANTERN_GPU_SELFCHECK_CHILD"):
        return None
    mode = os.environ.get("LANTERN_GPU_SELFCHECK", "").strip().lower()
    if mode in ("0", "off", "no", "false"):
        return None
    v = verdict(info, again=(mode == "again"))
    if v.get("ok"):
        return None
    when = " (cached verdict)" if v.get("cached") else ""
    return (f"{v.get('reason', 'the GPU self-check failed')}{when}: rendering on the CPU. "
            f"Pick the CUDA device to force the GPU, or set LANTERN_GPU_SELFCHECK=again to "
            f"check it again")
