"""First-step CPU time of auto against pt on blend_scenes/ scenes (the pilot's cost)."""
import os
import sys, time
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))  # bench/
import rmse_cycles
from rmse import import_lantern
lantern = import_lantern()
for name in sys.argv[1].split(","):
    sc = rmse_cycles.build_blend(name, 64, 64)
    out = {}
    for integ in ("pt", "auto"):
        ts = []
        for seed in (1, 2):
            s = lantern.Session(sc, integrator=integ, seed=seed, threads=1, backend="cpu",
                                spp_per_iteration=1, max_depth=rmse_cycles.BOUNCES + 2)
            st = []
            for _ in range(4):
                c0 = time.process_time(); s.step(); st.append(time.process_time() - c0)
            ts.append(st)
        out[integ] = ts
    pt_step = sum(sum(t[1:]) for t in out["pt"]) / 6
    pilot = sum(a[0] - p[0] for a, p in zip(out["auto"], out["pt"])) / 2
    print(f"{name}: pt step {pt_step*1000:.1f} ms, pilot {pilot*1000:.1f} ms = {pilot/pt_step:.1f} pt samples; auto/pt at 64 spp ~ {64/(64+pilot/pt_step):.3f}; choice {s.stats.get('auto_choice')}", flush=True)
