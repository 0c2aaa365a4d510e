"""Viewport drawing: the latest progressive image as a float texture on a region-sized quad,
drawn inside the engine's display-space shader binding (view transform applied by Blender)."""

import gpu
import numpy as np
from gpu_extras.batch import batch_for_shader


class ImageDraw:
    def __init__(self):
        self.texture = None
        self.serial = -1
        self.size = None
        self.shader = gpu.shader.from_builtin("IMAGE")

    def update(self, image, serial):
        if serial == self.serial and self.texture is not None:
            return
        h, w = image.shape[:2]
        rgba = np.ones((h, w, 4), dtype=np.float32)
        rgba[:, :, :3] = image[::-1]  # GPU textures start at the bottom row
        buf = gpu.types.Buffer("FLOAT", w * h * 4, rgba.ravel())
        self.texture = gpu.types.GPUTexture((w, h), format="RGBA16F", data=buf)
        self.serial, self.size = serial, (w, h)

    def draw(self, width, height):
        if self.texture is None:
            return
        batch = batch_for_shader(
            self.shader, "TRI_FAN",
            {"pos": ((0, 0), (width, 0), (width, height), (0, height)),
             "texCoord": ((0, 0), (1, 0), (1, 1), (0, 1))})
        gpu.state.blend_set("ALPHA_PREMULT")
        self.shader.bind()
        self.shader.uniform_sampler("image", self.texture)
        batch.draw(self.shader)
        gpu.state.blend_set("NONE")
