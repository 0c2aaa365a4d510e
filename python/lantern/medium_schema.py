"""Validation of participating media in a scene dict (docs/volumes.md): a material's
``"volume"`` (the homogeneous medium inside its mesh) and ``"volume_only"`` (no surface: a
boundary that pt passes through), and the world's ``"volume"`` (the medium everywhere else).

A medium is ``{"sigma_a": rgb, "sigma_s": rgb, "emission": rgb, "g": float}``: absorption and
scattering coefficients per metre, emitted radiance per metre and the Henyey-Greenstein
anisotropy in (-1, 1), all in Blender's units (addon/export/volume.py converts the nodes).
A Volume object's medium may add its fire, read with the material's ``"temperature_grid"`` and
``"flame_grid"`` (grid_schema.py): ``"blackbody_intensity"`` (float >= 0), ``"temperature"``
(kelvin per unit of the temperature grid), ``"blackbody_tint"`` (rgb) and ``"flame_emission"``
(rgb radiance per metre per unit of the flame grid). With the material's ``"color_grid"``:
``"color_scatter"`` (rgb: Color x Density, the scattering that the grid's colour c multiplies),
``"color_absorb"`` (rgb: max(1 - sqrt(Absorption Color), 0) x Density, the absorption that
max(1 - color_base c, 0) multiplies) and ``"color_base"`` (rgb: the Color socket), per unit of
the density grid, beside sigma_a and sigma_s (the parts the colour does not touch); with colour
programs ``"absorb_alone"`` (rgb: the absorption that an Absorption Color graph's factor
multiplies alone, where a Color graph is another shader's)."""
import math

MEDIUM_KEYS = ("sigma_a", "sigma_s", "emission", "g")
FIRE_KEYS = ("blackbody_intensity", "temperature", "blackbody_tint", "flame_emission",
             "color_scatter", "color_absorb", "color_base", "absorb_alone")


def _rgb(value, what):
    try:
        v = [float(x) for x in value]
    except TypeError:
        v = [float(value)] * 3
    if len(v) != 3:
        raise ValueError(f"{what}: expected 3 values, got {len(v)}")
    if not all(math.isfinite(x) and x >= 0.0 for x in v):
        raise ValueError(f"{what}: expected finite values >= 0, got {v}")
    return v


def validate_medium(medium, what):
    """The medium dict, checked: unknown keys and out-of-range values are errors."""
    if not isinstance(medium, dict):
        raise ValueError(f"{what} volume: expected a dict")
    unknown = set(medium) - set(MEDIUM_KEYS) - set(FIRE_KEYS)
    if unknown:
        raise ValueError(f"{what} volume: unknown keys {sorted(unknown)} "
                         f"(expected {', '.join(MEDIUM_KEYS + FIRE_KEYS)})")
    out = {k: _rgb(medium.get(k, [0.0, 0.0, 0.0]), f"{what} volume {k}")
           for k in ("sigma_a", "sigma_s", "emission")}
    g = float(medium.get("g", 0.0))
    if not (math.isfinite(g) and -1.0 < g < 1.0):
        raise ValueError(f"{what} volume g: expected a value in (-1, 1), got {g}")
    out["g"] = g
    for k in ("blackbody_tint", "flame_emission", "color_scatter", "color_absorb", "color_base",
              "absorb_alone"):
        if k in medium:
            out[k] = _rgb(medium[k], f"{what} volume {k}")
    for k in ("blackbody_intensity", "temperature"):
        if k in medium:
            v = float(medium[k])
            if not (math.isfinite(v) and v >= 0.0):
                raise ValueError(f"{what} volume {k}: expected a finite value >= 0, got {v}")
            out[k] = v
    return out


def validate_material_volume(material, out, what):
    """A material's "volume" and "volume_only" into out (validate_material's dict)."""
    if material.get("volume") is not None:
        out["volume"] = validate_medium(material["volume"], what)
    else:
        out.pop("volume", None)
    if "volume_only" in material:
        if not isinstance(material["volume_only"], bool):
            raise ValueError(f"{what} volume_only: expected a bool")
        out["volume_only"] = material["volume_only"]


def validate_world_volume(world, out):
    """The world's "volume" into out (validate_world's dict)."""
    if world.get("volume") is not None:
        out["volume"] = validate_medium(world["volume"], "world")
    else:
        out.pop("volume", None)
