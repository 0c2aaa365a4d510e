"""What media cost a scene without them (docs/volumes.md): pt's wall time on committed scenes
without media, for the lantern package on PYTHONPATH (run once per build, interleaved):

    PYTHONPATH=/path/to/base/python   python bench/volumes_cost.py --tag base --out r.txt
    PYTHONPATH=/path/to/branch/python python bench/volumes_cost.py --tag volumes --out r.txt

Each line: tag, scene, best and median of --repeats renders in process CPU seconds (one
render thread; less sensitive to a loaded machine than wall time), samples, threads."""
import argparse
import platform
import statistics
import time

import lantern
from lantern import scenes

SCENES = {"cornell_box": lambda: scenes.cornell_box(64, 64),
          "features_box": lambda: scenes.features_box(64, 64)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--tag", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--spp", type=int, default=16)
    args = ap.parse_args()
    with open(args.out, "a") as f:
        for name, make in SCENES.items():
            scene = make()
            times = []
            for r in range(args.repeats):
                s = lantern.Session(scene, integrator="pt", seed=r, spp_per_iteration=args.spp,
                                    backend="cpu", threads=1)
                t0 = time.process_time()
                s.step()
                times.append(time.process_time() - t0)
            line = (f"{args.tag} {name} best {min(times):.4f} cpu-s median "
                    f"{statistics.median(times):.4f} cpu-s spp {args.spp} threads 1 "
                    f"({platform.processor() or platform.machine()}, {lantern.__file__})")
            print(line)
            f.write(line + "\n")


if __name__ == "__main__":
    main()
