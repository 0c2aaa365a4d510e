"""A stand-in for `lantern._core` with the interface of docs/team_plan.md: it checks what the
Python side hands over and returns a constant image, so the wrapper and the command line can be
tested without the native build."""
import threading

import numpy as np


class Session:
    instances = []

    def __init__(self, scene, settings):
        assert isinstance(scene, dict) and isinstance(settings, dict)
        for mesh in scene["meshes"]:
            assert mesh["positions"].dtype == np.float32
            assert mesh["indices"].dtype == np.uint32
        assert scene["camera"]["to_world"].dtype == np.float32
        assert settings["backend"] == "cpu" and settings["integrator"] in ("pt", "auto")
        self.scene, self.settings = scene, settings
        self._spp = 0
        self._iterations = 0
        self._cancel = threading.Event()
        Session.instances.append(self)

    def step(self):
        if self._cancel.is_set():
            return
        self._spp += self.settings["spp_per_iteration"]
        self._iterations += 1

    def image(self):
        film = self.scene["film"]
        color = np.asarray(self.scene["world"]["color"], dtype=np.float32)
        return np.broadcast_to(color, (film["height"], film["width"], 3)).copy()

    @property
    def spp(self):
        return self._spp

    def stats(self):
        return {"iterations": self._iterations, "spp": self._spp,
                "rays_camera": 100 * self._spp, "rays_shadow": 50 * self._spp,
                "rays_total": 150 * self._spp,
                "backend": "cpu"}

    def cancel(self):
        self._cancel.set()

    def warnings(self):
        return ["fake core"]


def embree_available():
    return False


def embree_version():
    return "none"


def build_info():
    return {"fake": True}
