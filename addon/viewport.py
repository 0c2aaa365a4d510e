"""Viewport drawing: the latest progressive image as a float texture stretched over the region,
drawn between the engine's bind_display_space_shader / unbind_display_space_shader (as in
Blender 5.0's RenderEngine template), with premultiplied alpha blending."""

import gpu
import numpy as np
from gpu_extras.presets import draw_texture_2d


class ImageDraw:
    def __init__(self):
        self.texture = None
        self.serial = -1

    def update(self, image, serial):
        """Upload a (H, W, 3) image, top row first, unless this serial is already uploaded."""
        if serial == self.serial and self.texture is not None:
            return
        h, w = image.shape[:2]
        rgba = np.ones((h, w, 4), dtype=np.float32)
        rgba[:, :, :3] = image[::-1]  # GPU textures start at the bottom row
        buf = gpu.types.Buffer("FLOAT", w * h * 4, rgba.ravel())
        self.texture = gpu.types.GPUTexture((w, h), format="RGBA16F", data=buf)
        self.serial = serial

    def draw(self, engine, scene, width, height):
        if self.texture is None:
            return
        gpu.state.blend_set("ALPHA_PREMULT")
        engine.bind_display_space_shader(scene)
        try:
            draw_texture_2d(self.texture, (0, 0), width, height)
        finally:
            engine.unbind_display_space_shader()
            gpu.state.blend_set("NONE")
