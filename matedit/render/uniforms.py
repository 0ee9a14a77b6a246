"""The scene's uniform blocks shared by every lit program: FrameBlock (camera, time, exposure,
viewport) and LightsBlock (the analytic lights), their layouts from matedit/glsl/layout.py."""

from __future__ import annotations

import moderngl
import numpy as np

from matedit.glsl.layout import BINDINGS, FRAME_BLOCK, MAX_LIGHTS
from matedit.render.camera import OrbitCamera
from matedit.render.fullscreen import mat_bytes
from matedit.shading.lights import Light
from matedit.shading.lights_block import pack_lights

_FRAME_OFFSETS = FRAME_BLOCK.offsets()


def pack_frame_block(camera: OrbitCamera, size: tuple[int, int], time: float,
                     exposure: float) -> tuple[bytes, np.ndarray]:
    """FrameBlock's bytes (std140) and the view-projection matrix they hold."""
    w, h = size
    vp = camera.projection(w / h) @ camera.view_matrix()
    data = bytearray(FRAME_BLOCK.size)
    for name, value in (("viewProjection", mat_bytes(vp)), ("model", mat_bytes(np.eye(4))),
                        ("normalMatrix", mat_bytes(np.eye(4))),
                        ("cameraPosition", np.array([*camera.eye, 1.0], "f4").tobytes()),
                        ("params", np.array([time, exposure, w, h], "f4").tobytes())):
        data[_FRAME_OFFSETS[name]:_FRAME_OFFSETS[name] + len(value)] = value
    return bytes(data), vp


class SceneUniforms:
    def __init__(self, ctx: moderngl.Context, lights: list[Light]) -> None:
        self._frame = ctx.buffer(reserve=FRAME_BLOCK.size)
        self._lights = ctx.buffer(pack_lights(lights))

    def set_lights(self, lights: list[Light]) -> list[Light]:
        """Writes the first MAX_LIGHTS of `lights` (returned) into LightsBlock."""
        kept = list(lights)[:MAX_LIGHTS]
        self._lights.write(pack_lights(kept))
        return kept

    def write_frame(self, camera: OrbitCamera, size: tuple[int, int], time: float,
                    exposure: float) -> np.ndarray:
        """Writes FrameBlock; returns the view-projection matrix."""
        data, vp = pack_frame_block(camera, size, time, exposure)
        self._frame.write(data)
        return vp

    def bind(self) -> None:
        self._lights.bind_to_uniform_block(BINDINGS["LIGHTS"])
        self._frame.bind_to_uniform_block(BINDINGS["FRAME"])

    def release(self) -> None:
        self._frame.release()
        self._lights.release()
