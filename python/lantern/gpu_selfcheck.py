"""The GPU self-check: before a session trusts a GPU with `backend="auto"`, a child process
renders a small conformance set on that GPU and on the CPU and compares them (issue 30).

Contract:
- `auto_backend_veto(info, features)` -> None (use the GPU) or the reason to render on the CPU
  instead, a sentence for the render report that names the failing case. Only "auto" asks: an
  artist who picks the CUDA device ("cuda") forces the GPU and skips the check.
- Per feature: the core set (every scene) must pass for "auto" to use the GPU at all; a scene
  with a feature of FEATURE_CASES (`features`: subsurface scattering, participating media) goes
  to the GPU only when that feature's cases passed too. A feature whose case failed, crashed or
  hung, or was never reached, keeps only its own scenes on the CPU: the walk and medium stages
  are the GPU's least tried code, and a fault there should not cost an artist the GPU for the
  rest.
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

CHECK_VERSION = 3          # a change to the conformance set makes old verdicts stale
                           # (2: strands and motion blur joined it; 3: the feature cases)
TIMEOUT_S = 180.0          # the whole check, first CUDA context and module load included
DOUBLE = None              # tests: the child's stand-in for the GPU (see module docstring)
CASES = None               # tests: a subset of gpu_selfcheck_run.CASES ("scene/integrator")

_memo = {}                 # key -> verdict, for the sessions of this process

# The cases a scene with a feature needs besides the core set (gpu_selfcheck_run.CASES runs them
# after it, a feature's cases in this order, skipping the rest of a feature after its first
# failure): subsurface, every walk the GPU runs (pt's; the camera and light paths' walks of
# bdpt, lvc and cis, cis standing in for the three: the same kernels; lt's adjoint walk); media,
# pt's volume path (what "auto" renders media with on a GPU), the bidirectional medium stages
# (cis standing in for bdpt and lvc) and lt's, in homogeneous and heterogeneous media.
FEATURE_CASES = {"subsurface": ("skin/pt", "skin/cis", "skin/lt"),
                 "media": ("fog/pt", "fog/cis", "fog/lt")}
FEATURE_LABELS = {"subsurface": "subsurface scattering", "media": "participating media"}


def feature_of(case):
    """The feature a case checks, or None for the core set."""
    return next((f for f, cases in FEATURE_CASES.items() if case in cases), None)


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


def _case_lines(text):
    """The child's per-case lines ("case {json}": case, ok, reason), in order."""
    out = []
    for line in (text or "").splitlines():
        if line.startswith("case "):
            try:
                entry = json.loads(line[len("case "):])
            except ValueError:
                continue
            if isinstance(entry, dict) and "case" in entry:
                out.append(entry)
    return out


def _stopped(text, why, seconds):
    """The verdict of a child that crashed or hung (why: what happened, "in case 'x'" added).
    Stopped in a core case: the GPU fails. Stopped in a feature's case: the core set had passed
    (the child runs it first and stops at its first failure), so only that feature fails; the
    features finished before keep their verdicts, those after it were not checked."""
    case = _last_started(text)
    where = f" in case '{case}'" if case else ""
    reason = f"{why}{where}"
    feature = feature_of(case) if case else None
    if feature is None:
        return {"ok": False, "case": case or "", "reason": reason, "seconds": seconds}
    done = _case_lines(text)
    features = {}
    for entry in done:
        f = feature_of(entry["case"])
        if f and f != feature and features.get(f, {}).get("ok", True):
            features[f] = {"ok": bool(entry.get("ok")), "case": entry["case"],
                           "reason": entry.get("reason") or ""}
    features[feature] = {"ok": False, "case": case, "reason": reason}
    return {"ok": True, "case": case, "cases": done, "features": features, "seconds": seconds,
            "reason": f"the GPU passed the core set; {FEATURE_LABELS[feature]}: {reason}"}


def run_check(timeout=None):
    """Run the conformance set in a child process; the verdict dict (ok: the core set passed,
    reason, case, seconds; features: per feature reached, ok, case and reason)."""
    timeout = TIMEOUT_S if timeout is None else float(timeout)
    t0 = time.monotonic()
    try:
        r = subprocess.run(_child_command(), env=_child_env(), capture_output=True,
                           timeout=timeout, stdin=subprocess.DEVNULL)
    except subprocess.TimeoutExpired as e:
        return _stopped(_decode(e.stdout), f"the GPU self-check timed out after {timeout:.0f} s",
                        time.monotonic() - t0)
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
        how = (f"was killed by signal {-r.returncode}" if r.returncode < 0
               else f"exited with status {r.returncode}")
        tail = err.strip().splitlines()[-1:] if err.strip() else []
        detail = f" ({tail[0][:200]})" if tail else ""
        return _stopped(out, f"the GPU self-check process {how}{detail}",
                        time.monotonic() - t0)
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


def feature_veto(v, features):
    """None when the verdict v lets the GPU render a scene with `features` (names of
    FEATURE_CASES; others are ignored), else why not."""
    if not v.get("ok"):
        return v.get("reason") or "the GPU self-check failed"
    checked = v.get("features") if isinstance(v.get("features"), dict) else {}
    for f in FEATURE_CASES:
        if f not in features:
            continue
        fv = checked.get(f)
        if not isinstance(fv, dict):
            return (f"the GPU self-check has not checked {FEATURE_LABELS[f]}, which this scene "
                    f"has, on this GPU (its cases did not run)")
        if not fv.get("ok"):
            return (f"{fv.get('reason') or 'the GPU self-check failed on ' + FEATURE_LABELS[f]} "
                    f"({FEATURE_LABELS[f]}, which this scene has; scenes without it still use "
                    f"the GPU)")
    return None


def features_passed(v):
    """The features (of FEATURE_CASES) whose cases passed in the verdict v: none where the core
    set failed."""
    if not v.get("ok"):
        return set()
    checked = v.get("features") if isinstance(v.get("features"), dict) else {}
    return {f for f in FEATURE_CASES
            if isinstance(checked.get(f), dict) and checked[f].get("ok") is True}


def passed_features(info):
    """The features whose cases the GPU `info` describes passed, from its verdict (run or read
    as auto_backend_veto does: after it, the memo's); none where the check is off
    (LANTERN_GPU_SELFCHECK=off trusts the GPU to render, not integrator auto's choice on it)."""
    if not info.get("available") or os.environ.get("LANTERN_GPU_SELFCHECK_CHILD"):
        return set()
    if os.environ.get("LANTERN_GPU_SELFCHECK", "").strip().lower() in ("0", "off", "no", "false"):
        return set()
    return features_passed(verdict(info))


def auto_backend_veto(info, features=()):
    """None when "auto" may take the GPU `info` describes for a scene with `features` (names of
    FEATURE_CASES the scene has), else why not (for the report)."""
    if not info.get("available") or os.environ.get("LANTERN_GPU_SELFCHECK_CHILD"):
        return None
    mode = os.environ.get("LANTERN_GPU_SELFCHECK", "").strip().lower()
    if mode in ("0", "off", "no", "false"):
        return None
    v = verdict(info, again=(mode == "again"))
    why = feature_veto(v, set(features))
    if why is None:
        return None
    when = " (cached verdict)" if v.get("cached") else ""
    return (f"{why}{when}: rendering on the CPU. "
            f"Pick the CUDA device to force the GPU, or set LANTERN_GPU_SELFCHECK=again to "
            f"check it again")
