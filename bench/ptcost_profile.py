"""The profiled process of bench/results/2026-12-06-ptcost (its per-function tables): pt on a
saved scene, one thread, spp_per_iteration 1, 64 steps (as bench/efficiency_cycles.py renders
pt), max_depth 18, REPS sessions; prints each session's CPU seconds and the last one's stage timers. With an unstripped
_core (the link line of build/dev's _core without -Wl,-s) under perf:

    perf record -F 4000 -o pt.data python bench/ptcost_profile.py PKG SCENE.lantern 64 4
    perf report -i pt.data --no-children --sort dso,symbol --stdio

PKG: a folder holding a `lantern` package with that _core; SCENE: bench/save_blend_scene.py's
export of a blend_scenes/ scene at 64x64."""
import sys
import time

sys.path.insert(0, sys.argv[1])
import lantern  # noqa: E402

scene = lantern.load_scene(sys.argv[2])
steps = int(sys.argv[3]) if len(sys.argv) > 3 else 64
reps = int(sys.argv[4]) if len(sys.argv) > 4 else 4
s = None
for r in range(reps):
    s = lantern.Session(scene, integrator="pt", seed=1 + r, spp_per_iteration=1, backend="cpu",
                        threads=1, max_depth=int(sys.argv[5]) if len(sys.argv) > 5 else 18)
    t0 = time.process_time()
    for _ in range(steps):
        s.step()
    print("cpu", time.process_time() - t0, file=sys.stderr)
st = s.stats
print({k: v for k, v in st.items() if k.startswith("time_") or k.startswith("rays_")},
      file=sys.stderr)
