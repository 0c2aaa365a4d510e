"""Build the scenes of scenes.py, the benchmark scenes of bench_registry.py and the feature
scenes of features.py (as feature_<name>) into build/blend_scenes/<name>.blend.

    .venv/bin/python blend_scenes/build.py [NAME ...]     (all scenes without names)"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_registry  # noqa: E402
import features  # noqa: E402
import scenes  # noqa: E402

bench_registry.register(scenes.SCENES)
features.register(scenes.SCENES)


def main(names):
    for name in names or list(scenes.SCENES):
        print(scenes.build(name))


if __name__ == "__main__":
    main(sys.argv[1:])
