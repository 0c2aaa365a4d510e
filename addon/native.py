"""The native core for the add-on: the `lantern` package (built from native/), or a RuntimeError
that says how to get it. The one place the add-on loads it from, so that export/ needs nothing
of engine.py (engine imports export, never the other way)."""


def import_lantern():
    """The `lantern` package, or a RuntimeError that says how to get it."""
    try:
        import lantern
    except ImportError as e:
        raise RuntimeError(f"the 'lantern' Python package is not importable in Blender's "
                           f"Python ({e}); install the extension zip that carries it "
                           f"(tools/build_extension.sh -> dist/lantern-<version>-<platform>.zip,"
                           f" docs/extension.md), or pip install . from the Lantern repository "
                           f"into the Python Blender runs") from e
    return lantern
