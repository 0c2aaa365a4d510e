"""Build the Cornell box into build/blend_scenes/cornell_box.blend (or the path given)."""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scenes  # noqa: E402

if __name__ == "__main__":
    print(scenes.build("cornell_box", sys.argv[1] if len(sys.argv) > 1 else None))
