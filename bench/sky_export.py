"""Export cost of the Multiple and Single Scattering Sky Textures (addon/export/sky.py,
sky_ms.py, sky_ss.py): the map built from scratch (every cache cleared) for a few skies, wall
and CPU time, median of N. CPU time (this process only) carries the machine's load less than wall.

Run: .venv/bin/python bench/sky_export.py [--runs N] [--out DIR]"""

import argparse
import math
import os
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools"))

SKIES = {"defaults": (math.radians(15.0), 0.0, 100.0, 1.0, 1.0, 1.0),
         "low sun, 3 km, thin aerosol": (math.radians(3.0), 0.7, 3000.0, 2.0, 0.3, 3.0),
         "sun below the horizon": (math.radians(-8.0), 2.0, 100.0, 1.0, 1.0, 1.0)}


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--runs", type=int, default=7)
    ap.add_argument("--out", default=None)
    args = ap.parse_args()
    import lantern_bpy
    lantern_bpy.load_addon()
    from lantern_blender.export import sky
    lines = [f"# Sky export cost ({time.strftime('%Y-%m-%d %H:%M')})", "",
             "Machine: 2-core AMD EPYC VM, 24 GB, Debian 12, numpy of the repo's venv; shared",
             "with other jobs (load below), so wall time carries the load, CPU time (this",
             "process) much less.", "",
             f"map {sky.MS_MAP_SIZE[0]} x {sky.MS_MAP_SIZE[1]}, load average "
             f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} CPUs at the start", "",
             "| model | sky | wall median (s) | wall min (s) | CPU median (s) |",
             "|---|---|---|---|---|"]

    def clear():
        sky._multiple_scattering_map.cache_clear()
        sky.sky_ms._atmosphere.cache_clear()
        sky._single_scattering_map.cache_clear()
        sky.sky_ss.sky_table.cache_clear()
    for model, build in (("multiple", sky._multiple_scattering_map),
                         ("single", sky._single_scattering_map)):
        for name, params in SKIES.items():
            wall, cpu = [], []
            for _ in range(args.runs):
                clear()
                t0, c0 = time.perf_counter(), time.process_time()
                build(params)
                wall.append(time.perf_counter() - t0)
                cpu.append(time.process_time() - c0)
            lines.append(f"| {model} | {name} | {statistics.median(wall):.3f} | "
                         f"{min(wall):.3f} | {statistics.median(cpu):.3f} |")
    lines += ["", f"load average at the end {os.getloadavg()[0]:.1f}"]
    text = "\n".join(lines) + "\n"
    print(text)
    if args.out:
        os.makedirs(args.out, exist_ok=True)
        with open(os.path.join(args.out, "results.md"), "w") as f:
            f.write(text)


if __name__ == "__main__":
    main()
