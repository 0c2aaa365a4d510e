"""Fuzz the scene loader and the renderer with mutated `.lantern` files.

Each case mutates a small valid scene (tools/fuzz_mutate.py: zip structure, JSON, .npy
headers and data, values, whole-scene scale), then loads and renders it in a child process
under time and memory limits, and is classified:

  image      rendered, every pixel finite          error      a clean error (below)
  cancelled  too slow, stopped cleanly by cancel()  nonfinite  rendered, a NaN or Inf pixel
  traceback  an exception that is not a clean error crash      killed by a signal
  hang       no answer within the time limit        memory     MemoryError, or over --mem-mb
  vague      an error from Session that only names a C++ exception ("std::bad_cast")

A clean error is a `lantern.SceneError` from `load_scene` whose message names the file, or a
ValueError / RuntimeError from `Session` whose message says more than a C++ exception's name. Cases are reproducible: case i of
--seed S is the same file on every machine. Usage (tools/README.md):

  python tools/fuzz_scene.py --cases 1000 --seed 1 --jobs 2 --keep /tmp/fuzz_fail
  python tools/fuzz_scene.py --seed 1 --case 417 --keep /tmp/c   # one case, with its output"""

import argparse
import collections
import json
import os
import random
import resource
import signal
import subprocess
import sys
import tempfile
import time
import warnings
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "python"))
sys.path.insert(0, str(Path(__file__).resolve().parent))

CLASSES = ("image", "cancelled", "error", "vague", "nonfinite", "traceback", "crash", "hang",
           "memory")
FAILURES = ("vague", "nonfinite", "traceback", "crash", "hang", "memory")
VAGUE = ("std::", "bad_cast", "bad_alloc", "Bad CRC-32", "No data left in file",
         "maximum recursion depth")  # alone, these say nothing a user can act on
FAMILY_WEIGHTS = {"zip": 3, "json": 3, "npy": 3, "values": 3, "scale": 2}
INTEGRATORS = ("pt", "bdpt", "lvc", "cis", "lt")


# ---- Seeds: small valid scenes ----
def build_seeds(folder):
    """Small scenes from lantern.scenes and bench/scenes, saved at a small film size."""
    import lantern
    from lantern import scenes
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    made = {"cornell": lambda: scenes.cornell_box(width=16, height=16),
            "furnace": lambda: scenes.furnace_sphere(subdivisions=1, width=12, height=12),
            "fixture": lambda: scenes.fixture_box(width=16, height=12),
            "glass": lambda: scenes.glass_lantern(width=12, height=16),
            "principled": lambda: scenes.principled_box(width=16, height=16),
            "features": lambda: scenes.features_box(width=16, height=16),
            "coat_normal": lambda: scenes.coat_normal_box(width=12, height=12),
            "sphere": lambda: scenes.integrating_sphere(width=8, height=8, light="sphere")}
    for path in sorted((ROOT / "bench" / "scenes").glob("*.lantern")):
        if path.stat().st_size < 400_000:
            made[path.stem] = lambda p=path: _shrunk(lantern.load_scene(p))
    out = []
    for name, build in made.items():
        target = folder / f"{name}.lantern"
        if not target.exists():
            build().save(target)
        out.append(target)
    return out


def _shrunk(scene, size=16):
    w, h = scene.film["width"], scene.film["height"]
    k = size / max(w, h)
    scene.film.update(width=max(1, round(w * k)), height=max(1, round(h * k)))
    return scene


_SEEDS = {}


def make_case(seeds, seed, index, folder):
    """Write case `index` of run `seed`; returns (path, label, settings)."""
    from fuzz_mutate import FAMILIES, Seed
    rng = random.Random(f"lantern-fuzz:{seed}:{index}")
    src = rng.choice(seeds)
    family = rng.choices(list(FAMILY_WEIGHTS), weights=list(FAMILY_WEIGHTS.values()))[0]
    if src not in _SEEDS:
        _SEEDS[src] = Seed(src.stem, src.read_bytes())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # zipfile's "Duplicate name": on purpose
        data, what = FAMILIES[family](_SEEDS[src], rng)
    Path(folder).mkdir(parents=True, exist_ok=True)
    path = Path(folder) / f"case_{seed}_{index}.lantern"
    path.write_bytes(data)
    settings = {"integrator": rng.choice(INTEGRATORS), "max_depth": rng.choice([2, 4, 8]),
                "seed": rng.randrange(1000), "threads": 2, "backend": "cpu"}
    accel = rng.choice(["auto", "auto", "bvh"])
    return path, f"{family}: {src.stem}: {what}", settings, accel


# ---- The child: load, render, report ----
def child(case, settings_json, out_path, render_s):
    import threading
    import traceback

    import numpy as np

    import lantern
    settings = json.loads(settings_json)
    result = {"class": None, "stage": "load", "message": ""}
    selftest = settings.pop("_selftest", None)  # tests/python/test_fuzz.py: the classifier

    def finish(cls, message=""):
        # VmHWM is this program's own peak RSS: exec starts it afresh. The parent's ru_maxrss
        # is not: Linux carries the pre-exec high-water mark, the forked copy of the parent
        # (a pytest process of a few hundred MB), into it.
        status = Path("/proc/self/status")
        fields = dict(ln.split(":", 1) for ln in (status.read_text().splitlines()
                                                  if status.exists() else []) if ":" in ln)

        def mb(key):
            return int(fields[key].split()[0]) // 1024 if key in fields else None
        result.update({"class": cls, "message": " ".join(str(message).split())[:500],
                       "vm_peak_mb": mb("VmPeak"), "rss_peak_mb": mb("VmHWM")})
        Path(out_path).write_text(json.dumps(result))
        os._exit(0)

    def unexpected(e):
        tb = traceback.extract_tb(e.__traceback__)
        where = f" at {Path(tb[-1].filename).name}:{tb[-1].lineno}" if tb else ""
        return f"{type(e).__name__}{where}: {e}"

    try:
        if selftest and selftest != "vague":
            _misbehave(selftest)
        scene = lantern.load_scene(case)
    except lantern.SceneError as e:
        finish("error" if str(case) in str(e) else "traceback", e)
    except MemoryError as e:
        finish("memory", f"MemoryError: {e}")
    except BaseException as e:
        finish("traceback", unexpected(e))
    try:
        result["stage"] = "session"
        if selftest == "vague":
            raise ValueError("invalid scene or settings: std::bad_cast")
        session = lantern.Session(scene, **settings)
        result["warnings"] = len(session.warnings)
        result["stage"] = "render"
        timer = threading.Timer(render_s, session.cancel)
        timer.start()
        session.step()
        timer.cancel()
        img = session.image()
    except MemoryError as e:
        finish("memory", f"MemoryError: {e}")
    except (ValueError, RuntimeError) as e:
        vague = not str(e).strip() or any(v in str(e) for v in VAGUE)
        finish("vague" if vague else "error", f"{type(e).__name__}: {e}")
    except BaseException as e:
        finish("traceback", unexpected(e))
    result["spp"] = session.spp
    if not np.isfinite(img).all():
        finish("nonfinite", f"{int((~np.isfinite(img)).sum())} non-finite values")
    finish("image" if session.spp > 0 else "cancelled", f"{img.shape}")


def _misbehave(kind):
    if kind == "crash":
        os.abort()
    if kind == "hang":
        time.sleep(3600)
    if kind == "rss":  # touched memory past --mem-mb, then a normal load
        global _BALLAST
        _BALLAST = bytearray(400 << 20)
        _BALLAST[::4096] = b"x" * len(range(0, 400 << 20, 4096))
    if kind == "alloc":  # past the address-space limit
        _BALLAST = bytearray(64 << 30)
    if kind == "traceback":
        raise KeyError("selftest")


# ---- The parent: run one case under limits ----
def run_case(path, settings, accel, timeout_s, mem_mb, render_s):
    out = Path(str(path) + ".json")
    out.unlink(missing_ok=True)
    log = open(str(path) + ".log", "wb")

    def limits():
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
        cap = (mem_mb * 2 + 1024) << 20  # address space, with room for libraries and thread
        # stacks (a render maps ~0.5 GB); the peak RSS is checked against mem_mb below
        resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
        resource.setrlimit(resource.RLIMIT_CPU, (int(timeout_s * 4), int(timeout_s * 4) + 5))
    env = dict(os.environ, LANTERN_ACCEL=accel, PYTHONPATH=os.pathsep.join(
        [str(ROOT / "python")] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep)
                                  if p]))
    start = time.monotonic()
    proc = subprocess.Popen([sys.executable, __file__, "--child", str(path),
                             json.dumps(settings), str(out), str(render_s)],
                            stdout=log, stderr=log, preexec_fn=limits, env=env)
    status = rusage = None
    while status is None:
        pid, st, ru = os.wait4(proc.pid, os.WNOHANG)
        if pid:
            status, rusage = st, ru
            break
        if time.monotonic() - start > timeout_s:
            os.kill(proc.pid, signal.SIGKILL)
            _, status, rusage = os.wait4(proc.pid, 0)
            proc.returncode = -9
            log.close()
            return {"class": "hang", "message": f"no answer in {timeout_s} s", "seconds":
                    round(time.monotonic() - start, 2)}
        time.sleep(0.02)
    proc.returncode = os.waitstatus_to_exitcode(status)
    log.close()
    seconds = round(time.monotonic() - start, 2)
    rss_mb = rusage.ru_maxrss / 1024  # includes the parent's size at fork: see child()
    if os.WIFSIGNALED(status):
        tail = Path(str(path) + ".log").read_bytes()[-300:].decode("utf8", "replace")
        sig = signal.Signals(os.WTERMSIG(status)).name
        return {"class": "crash", "message": f"{sig}: {' '.join(tail.split())[-200:]}",
                "seconds": seconds, "rss_mb": round(rss_mb)}
    if not out.exists():
        tail = Path(str(path) + ".log").read_bytes()[-300:].decode("utf8", "replace")
        cls = "memory" if "MemoryError" in tail or "bad_alloc" in tail else "crash"
        return {"class": cls, "message": f"exit {proc.returncode}, no result: "
                f"{' '.join(tail.split())[-200:]}", "seconds": seconds}
    result = json.loads(out.read_text())
    if result.get("rss_peak_mb") is not None:
        rss_mb = result["rss_peak_mb"]
    result.update(seconds=seconds, rss_mb=round(rss_mb))
    if rss_mb > mem_mb and result["class"] not in FAILURES:
        result["message"] = f"peak {rss_mb:.0f} MB (limit {mem_mb}): {result['message']}"
        result["class"] = "memory"
    return result


def run(seed=1, cases=100, start=0, jobs=2, timeout_s=60.0, mem_mb=2048, render_s=10.0,
        keep=None, verbose=False, work=None):
    """Run cases start..start+cases-1 of `seed`; returns {"counts": ..., "failures": [...]}."""
    work = Path(work or tempfile.mkdtemp(prefix="lantern_fuzz_"))
    seeds = build_seeds(work / "seeds")
    counts = collections.Counter()
    failures, rows = [], []

    def one(index):
        path, label, settings, accel = make_case(seeds, seed, index, work)
        result = run_case(path, settings, accel, timeout_s, mem_mb, render_s)
        result.update(case=index, label=label, settings=settings, accel=accel)
        if result["class"] in FAILURES and keep:
            Path(keep).mkdir(parents=True, exist_ok=True)
            os.replace(path, Path(keep) / path.name)
        else:
            path.unlink(missing_ok=True)
        for suffix in (".json", ".log"):
            Path(str(path) + suffix).unlink(missing_ok=True)
        return result

    with ThreadPoolExecutor(max_workers=jobs) as pool:
        for result in pool.map(one, range(start, start + cases)):
            counts[result["class"]] += 1
            rows.append([result["case"], result["class"], result["label"][:100],
                         result["message"][:160], result.get("rss_mb")])
            bad = result["class"] in FAILURES
            if bad:
                failures.append(result)
            if verbose or bad:
                print(f"case {result['case']:5d} {result['class']:9s} "
                      f"{result.get('seconds', 0):5.1f}s {result['label'][:70]} | "
                      f"{result['message'][:160]}", flush=True)
    return {"seed": seed, "start": start, "cases": cases,
            "counts": {c: counts.get(c, 0) for c in CLASSES}, "failures": failures,
            "cases": rows}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--seed", type=int, default=1)
    p.add_argument("--cases", type=int, default=100)
    p.add_argument("--start", type=int, default=0, help="first case index")
    p.add_argument("--case", type=int, default=None, help="run this one case, verbosely")
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--timeout", type=float, default=60.0, help="seconds per case")
    p.add_argument("--render-seconds", type=float, default=10.0,
                   help="cancel() a render after this long (slow is not a hang)")
    p.add_argument("--mem-mb", type=int, default=2048, help="peak RSS allowed per case")
    p.add_argument("--keep", default=None, help="keep failing cases in this folder")
    p.add_argument("--json", default=None, help="write the counts and failures here")
    p.add_argument("-v", "--verbose", action="store_true")
    a = p.parse_args(argv)
    if a.case is not None:
        a.start, a.cases, a.verbose = a.case, 1, True
    t0 = time.monotonic()
    report = run(a.seed, a.cases, a.start, a.jobs, a.timeout, a.mem_mb, a.render_seconds,
                 a.keep, a.verbose)
    report["seconds"] = round(time.monotonic() - t0, 1)
    print(" ".join(f"{c}={n}" for c, n in report["counts"].items()),
          f"({a.cases} cases, seed {a.seed}, {report['seconds']} s)")
    if a.json:
        Path(a.json).write_text(json.dumps(report, indent=1))
    return 1 if report["failures"] else 0


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--child":
        child(sys.argv[2], sys.argv[3], sys.argv[4], float(sys.argv[5]))
    else:
        sys.exit(main())
