"""Build a blend_scenes/ scene in bpy, export it through this checkout's add-on and save it as a
.lantern file, so that builds without bpy (or older builds) render the very same scene data:

    python bench/save_blend_scene.py monkeybox 128x128 /tmp/monkeybox.lantern

(the Python with bpy: /work/main/.venv/bin/python). Used by bench/issue13_speed.sh."""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "python"))

if __name__ == "__main__":
    import rmse_cycles

    name, res, out = sys.argv[1:4]
    w, h = (int(v) for v in res.split("x"))
    rmse_cycles.build_blend(name, w, h).save(out)
    print(f"saved {name} {w}x{h} to {out}")
