"""The benchmark scenes of the CIS-LBDPT paper's character (bench_*.py): name -> builder,
triangle target, resolution. `register(scenes.SCENES)` makes them buildable by build.py; they
stay out of scenes.SCENES otherwise (the Cycles reference tools iterate that)."""

import os
import sys
from dataclasses import dataclass

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bench_hard  # noqa: E402
import bench_monkeybox  # noqa: E402
import bench_rooms  # noqa: E402


@dataclass(frozen=True)
class BenchBlend:
    name: str
    build: object           # builder: no arguments, returns the triangle count
    target_tris: int        # 0: no target (the small hard cases)
    resolution: tuple
    note: str


BENCH = {s.name: s for s in [
    BenchBlend("monkeybox", bench_monkeybox.monkeybox, bench_monkeybox.TARGET,
               bench_monkeybox.RES, "paper's Monkeybox: 3 Suzannes, pendant + 2 recesses"),
    BenchBlend("whiteroom", bench_rooms.whiteroom, bench_rooms.WHITEROOM_TARGET, bench_rooms.RES,
               "paper's Whiteroom: living/dining room, 4 recesses, 3 pendants, floor lamp"),
    BenchBlend("bedroom", bench_rooms.bedroom, bench_rooms.BEDROOM_TARGET, bench_rooms.RES,
               "paper's Bedroom: bed, 2 table lamps, 2 recesses, pendant"),
    BenchBlend("bench_fixture", bench_hard.bench_fixture, 0, bench_hard.RES,
               "bulb in a closed box with a 6 cm opening"),
    BenchBlend("bench_caustics", bench_hard.bench_caustics, 0, bench_hard.RES,
               "glass sphere + glass Suzanne over a diffuse floor, small bulb in a cup"),
    BenchBlend("bench_tiny_light", bench_hard.bench_tiny_light, 0, bench_hard.RES,
               "1 mm bulb in a 2 cm cup"),
    BenchBlend("bench_glossy", bench_hard.bench_glossy, 0, bench_hard.RES,
               "facing metal panels, copper Suzanne, recessed light"),
]}


def register(scenes_dict):
    """Add the builders to a scenes.SCENES-like dict (build.py)."""
    for name, spec in BENCH.items():
        scenes_dict.setdefault(name, spec.build)
