"""The benchmark scenes of `bench/rmse.py`: a name -> a function of (width, height) returning a
`lantern.Scene`. Factories are looked up by name in `lantern.scenes` when a run asks for them,
so a scene whose builder has not landed yet is skipped (`SceneUnavailable`), not an error.

To add a scene: add its builder to `lantern.scenes` (taking `width=`, `height=`) and one
`BenchScene` line below. A name not listed here but present in `lantern.scenes` also works."""

from dataclasses import dataclass, field


class SceneUnavailable(Exception):
    """The scene cannot be built in this checkout (its builder is missing); skip it."""


@dataclass(frozen=True)
class BenchScene:
    name: str
    factory: str                 # function name in lantern.scenes
    note: str = ""
    kwargs: dict = field(default_factory=dict)  # extra keyword arguments for the factory
    # The .blend twin in blend_scenes/ (a builder name of blend_scenes/scenes.py), for the
    # Cycles comparison of DESIGN.md "Speed against error".
    # TODO(cycles): a `--cycles` run builds the twin with blend_scenes.scenes.build(), renders
    # it with Cycles on the CPU at the same resolution and time budget, and scores it against
    # the same reference. Check first that the twin matches the numpy scene (the Cornell twin
    # uses a 60 W light and a 35 mm camera; lantern.scenes.cornell_box 40 W and fov 39.3).
    blend: str | None = None


SCENES = {s.name: s for s in [
    BenchScene("cornell", "cornell_box", "diffuse Cornell box, rectangle area light",
               blend="cornell_box"),
    BenchScene("fixture", "fixture_box", "light in a fixture: paths must find a small opening"),
    BenchScene("glass", "glass_lantern", "caustics through dielectric glass"),
    BenchScene("glossy", "glossy_box", "glossy conductors lit by a small light"),
]}


def lookup(name):
    """The `BenchScene` for `name` (registered, or a function of that name in lantern.scenes)."""
    if name in SCENES:
        return SCENES[name]
    return BenchScene(name, name, "lantern.scenes." + name)


def build(name, width, height):
    """The `lantern.Scene` of benchmark scene `name` at width x height pixels.
    Raises SceneUnavailable when lantern.scenes has no builder for it."""
    import lantern.scenes

    spec = lookup(name)
    factory = getattr(lantern.scenes, spec.factory, None)
    if not callable(factory):
        known = ", ".join(sorted(SCENES))
        raise SceneUnavailable(f"scene {name!r}: lantern.scenes has no {spec.factory}() in this "
                               f"checkout (registered scenes: {known})")
    return factory(width=int(width), height=int(height), **spec.kwargs)
