"""Blender materials -> Lantern materials (docs/materials.md), by the shader node at the
Material Output's Surface:

- Principled BSDF -> principled (bsdf/principled.h): sheen and coat over metal, glass and a
  dielectric specular layer (IOR, Specular IOR Level, Specular Tint, Roughness) over a diffuse
  Base Color (Lambert, or Oren-Nayar with Diffuse Roughness). Metallic 1 -> conductor (the
  same lobe, cheaper); Specular IOR Level 0 without metal or glass -> diffuse; either only
  without coat and sheen (they would be lost: difftest D16). Subsurface is
  not rendered (a warning). Emission Color x Strength in every case.
- Diffuse BSDF -> diffuse (Roughness > 0: Blender's energy-preserving Oren-Nayar);
  Translucent BSDF -> translucent; Emission -> emission; Glossy BSDF -> conductor of constant
  reflectance Color (Cycles' Glossy has no Fresnel: eta 0, k 1 scaled by Color); Metallic BSDF
  (F82) -> conductor (Base Color, Edge Tint), physical-conductor mode -> its normal-incidence
  reflectance as F0, with a warning; Glass BSDF -> dielectric (Color tints reflection and
  transmission, as Cycles); Refraction BSDF -> dielectric (its reflection included, untinted),
  with a warning.
- Mix Shader, Add Shader -> mix (Transparent BSDF leaves -> alpha); see material_mix.py.
- Anything else: grey 0.8 diffuse, with a warning naming the material and the node.
- Negative or non-finite colours read as 0, non-finite weights as 0 (a warning).

Textures (texture.py): an Image Texture feeding Base Color / Color, Roughness, Metallic or Alpha
(directly, through a Separate Color channel, or its Alpha output) is rendered as a texture; a
Normal Map node (tangent space) on Normal (and Coat Normal) as a normal map. On other inputs (emission colour,
coat, sheen, ...) the image's mean value is used, with a warning. A missing image is magenta.
Alpha < 1 (constant or textured) lets rays pass the surface (docs/materials.md).

This file picks the node at the Material Output and keeps the table of converted materials;
material_shader.py converts one shader node, material_mix.py a Mix / Add Shader tree,
material_inputs.py reads the inputs (constants, textures, node-graph programs)."""

import bpy

from .holdout import holdout_material
from . import node_bump
from .material_compile import GraphCompiler
from .material_inputs import DEFAULT, DEFAULT_SURFACE, _source
from .material_mix import _convert_mix
from .material_shader import _convert_shader
from .texture import TextureTable
from .volume import attach_material_volume


def convert_material(material, report, textures=None, add_leaf=None):
    """The Lantern material of a Blender material. A Mix / Add Shader tree becomes a "mix" of
    leaf materials, which add_leaf(dict) -> id appends to the scene (MaterialTable does). The
    Volume output: export/volume.py."""
    textures = textures if textures is not None else TextureTable(report)
    out = _convert_surface(material, report, textures, add_leaf)
    return attach_material_volume(material, out, report,
                                  GraphCompiler(material, report, textures, textures.attributes))


def _convert_surface(material, report, textures=None, add_leaf=None):
    textures = textures if textures is not None else TextureTable(report)
    out = dict(DEFAULT, name=material.name)
    tree = material.node_tree
    if bpy.app.version < (5, 0, 0) and not material.use_nodes:  # always nodes from 5.0
        tree = None
    if tree is None:
        return out
    output = next((n for n in tree.nodes if n.type == "OUTPUT_MATERIAL" and n.is_active_output),
                  None) or next((n for n in tree.nodes if n.type == "OUTPUT_MATERIAL"), None)
    # the Volume output: export/volume.py; true displacement: export/unsupported.py
    if output is None or not output.inputs["Surface"].is_linked:
        out["base_color"] = [0.0, 0.0, 0.0]  # no surface shader: black, as in Cycles
        return out
    node, _ = _source(output.inputs["Surface"])
    if node is None:
        out["base_color"] = [0.0, 0.0, 0.0]
        return out
    if node.type == "HOLDOUT":  # export/holdout.py
        return holdout_material(material)
    if node.type in ("MIX_SHADER", "ADD_SHADER", "BSDF_TRANSPARENT"):
        out = _convert_mix(node, material, report, textures, add_leaf)
    else:
        out = _convert_shader(node, material, report, textures)
        out.pop("_emission_mean", None)
    disp = node_bump.displacement(GraphCompiler(material, report, textures,
                                                textures.attributes), material, output)
    if disp is not None:   # the displaced surface first, then the shader's own Bump nodes
        out.setdefault("programs", []).insert(0, disp)
    return out


class MaterialTable:
    """Unique Lantern materials by Blender material; index 0 is the default material (Blender's
    default surface, DEFAULT_SURFACE)."""

    def __init__(self, report, texture_cache=None):
        self.report = report
        self.materials = [dict(DEFAULT_SURFACE)]
        self._index = {}
        self.texture_table = TextureTable(report, texture_cache)

    @property
    def textures(self):
        return self.texture_table.textures

    @property
    def attributes(self):
        return self.texture_table.attributes

    def index(self, material):
        if material is None:
            return 0
        key = material.name_full
        if key not in self._index:
            slot = len(self.materials)
            self._index[key] = slot
            self.materials.append(None)   # the slot, before any mix leaves are appended
            self.materials[slot] = convert_material(material, self.report, self.texture_table,
                                                    self._add_leaf)
        return self._index[key]

    def _add_leaf(self, leaf):
        self.materials.append(leaf)
        return len(self.materials) - 1
