"""Pieces of the final (F12) render that need no Blender: the border rectangle in pixels as
Blender computes it, cropping an exported scene to it, and adaptive sampling (Cycles' noise
threshold): the core stops each converged pixel on the CPU (native/src/integrator/adaptive.h);
NoiseCheck stops a GPU render's whole frame once every pixel has converged."""

import math

import numpy as np


def film_size(render):
    """Blender's render size with the resolution percentage: (x * pct) / 100, integer."""
    pct = int(render.resolution_percentage)
    return (max(1, int(render.resolution_x) * pct // 100),
            max(1, int(render.resolution_y) * pct // 100))


def border_rect(render, width, height):
    """(x0, y0, w, h), y0 from the bottom, of a border render on a width x height film, or
    None for a full frame. Blender truncates border * size in single precision; so does this,
    so that the rectangle is the one the render result was made for."""
    if not render.use_border:
        return None
    f = np.float32
    x0 = int(f(render.border_min_x) * f(width))
    x1 = int(f(render.border_max_x) * f(width))
    y0 = int(f(render.border_min_y) * f(height))
    y1 = int(f(render.border_max_y) * f(height))
    x0, x1 = max(0, min(x0, width)), max(0, min(x1, width))
    y0, y1 = max(0, min(y0, height)), max(0, min(y1, height))
    if x1 <= x0 or y1 <= y0:
        return None
    if (x0, y0, x1 - x0, y1 - y0) == (0, 0, width, height):
        return None
    return x0, y0, x1 - x0, y1 - y0


def crop_scene(scene, rect):
    """Narrows an exported lantern.Scene (full film) to the border rect: the film shrinks to
    the rectangle and the camera's view window to the same part of the view, so each pixel
    sees exactly what it sees in the full frame."""
    x0, y0, w, h = rect
    film = dict(scene.film)
    full_w, full_h = film["width"], film["height"]
    xmin, xmax, ymin, ymax = scene.camera["screen"]
    sx = (xmax - xmin) / full_w
    sy = (ymax - ymin) / full_h
    camera = dict(scene.camera)
    camera["screen"] = [xmin + x0 * sx, xmin + (x0 + w) * sx,
                        ymin + y0 * sy, ymin + (y0 + h) * sy]
    film["width"], film["height"] = w, h
    scene.film, scene.camera = film, camera


def adaptive_settings(settings, on):
    """The Session settings of the scene's Noise Threshold panel (none when it is off)."""
    if not on:
        return {}
    return {"adaptive_threshold": float(settings.adaptive_threshold),
            "adaptive_min_samples": int(settings.adaptive_min_samples)}


def adaptive_status(session):
    """The status line's part for per-pixel adaptive sampling: pixels still sampling."""
    total = max(1, session.pixel_samples().size)
    err = session.noise_error
    worst = f", noise {err:.4f}" if err >= 0 else ""
    return f" | {100.0 * session.active_pixels / total:.0f}% of pixels sampling{worst}"


def auto_min_samples(threshold):
    """Cycles' automatic minimum before the first convergence check."""
    return max(4, int(math.ceil(16.0 / threshold ** 0.3)))


def half_a(first_sample, samples):
    """Whether a step's samples first_sample.. (a step of `samples`) go to half A: the parity
    of the odd bits of the sample's index (of the step's, for steps of several samples), as
    Cycles and the core's adaptive_half_a (native/src/integrator/adaptive.h): every other
    sample would put the QMC sampler's even-indexed points, which fill half a pixel, in one
    half."""
    q = int(first_sample) // int(samples) if samples > 1 else int(first_sample)
    return bin(q & 0xAAAAAAAAAAAAAAAA).count("1") % 2 == 1


def error_norm(intensity):
    """Cycles' normaliser of |I - A|_1: sqrt of R + G + B below 1, R + G + B itself above."""
    intensity = np.maximum(intensity, 0.0)
    return np.where(intensity < 1.0, np.sqrt(intensity), intensity)


class NoiseCheck:
    """Cycles' per-pixel error (Cycles' film_adaptive_sampling_convergence_check): with I the
    mean of all samples and A the mean of half of them (half_a),
    error = |I - A|_1 / (1e-4 + error_norm(I_r + I_g + I_b)); the render has converged when every
    pixel's error is below the threshold. Lantern renders whole frames, so it stops the frame
    where Cycles would stop its last pixel."""

    def __init__(self, threshold, min_samples=0):
        self.threshold = float(threshold)
        self.min_samples = int(min_samples) or auto_min_samples(self.threshold)
        self._prev_sum = None
        self._prev_spp = 0
        self._half_sum = None
        self._half_spp = 0
        self._steps = 0
        self.error = math.inf  # the worst pixel's error at the last check

    def add(self, image, spp):
        """The session's mean image after a step that brought it to `spp` samples; True when
        the frame has converged."""
        total = image.astype(np.float64) * spp
        if self._prev_sum is None:
            self._prev_sum = np.zeros_like(total)
            self._half_sum = np.zeros_like(total)
        step = total - self._prev_sum
        if half_a(self._prev_spp, spp - self._prev_spp):
            self._half_sum += step
            self._half_spp += spp - self._prev_spp
        self._prev_sum, self._prev_spp = total, spp
        self._steps += 1
        if spp < self.min_samples or self._half_spp <= 0 or self._half_spp >= spp:
            return False
        mean = total / spp
        half = self._half_sum / self._half_spp
        diff = np.abs(mean - half).sum(axis=2)
        norm = error_norm(mean.sum(axis=2))
        err = diff / (1e-4 + norm)
        self.error = float(err.max())
        return self.error < self.threshold
