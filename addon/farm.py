"""Render-farm metadata of a final render: the samples, seed and scene identity that
`python -m lantern merge` weighs and checks (lantern/merge.py), stamped into the render result
so that Blender writes them into the EXR header (`blender -b file.blend -E LANTERN -f N`).

Blender writes the stamp fields of the engine's full result (`get_result()` after
`end_result`), as strings, into every EXR it saves from that render (measured with bpy 5.0.1)."""

import traceback


def stamp_chunk(engine, scene, session, settings):
    """Add lantern.spp / .seed / .chunk / .scene / .integrator to the render's stamp data.
    Never raises: a render without them still saves, it just cannot be merged."""
    try:
        from lantern import merge
        result = engine.get_result()
        if result is None or session is None or scene is None:
            return
        meta = merge.chunk_metadata(merge.scene_identity(scene, settings.max_depth),
                                    session.spp, settings.seed, 0, settings.integrator)
        for key, value in meta.items():
            result.stamp_data_add_field(key, str(value))
    except Exception:  # metadata must never fail a render
        traceback.print_exc()
