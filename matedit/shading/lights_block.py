"""Bytes of the ``LightsBlock`` uniform block (``lights_block.glsl``), std140.

Layout: ``ivec4 count`` at 0 (x = lights in use), then per light i at ``16 + 64 i`` four
vec4: position.xyz + type, color.rgb + intensity, direction.xyz + influence radius,
(source radius, source length, 0, 0).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from matedit.glsl import layout as _layout
from matedit.shading.lights import Light, LightKind

# from the one layout source (matedit/glsl/layout.py), like the shader's defines
MAX_LIGHTS = _layout.MAX_LIGHTS
LIGHT_STRIDE = _layout.LIGHT_STRIDE
LIGHTS_HEADER = _layout.LIGHTS_BLOCK.offsets()["light"]
LIGHTS_BLOCK_SIZE = _layout.LIGHTS_BLOCK.size  # 1040 bytes


def pack_lights(lights: Sequence[Light], max_lights: int = MAX_LIGHTS) -> bytes:
    """The block's bytes for up to `max_lights` lights (the shader's MATEDIT_MAX_LIGHTS)."""
    if len(lights) > max_lights:
        raise ValueError(f"{len(lights)} lights given; the block holds {max_lights}")
    header = np.array([len(lights), 0, 0, 0], dtype="<i4")
    body = np.zeros((max_lights, 4, 4), dtype="<f4")
    for i, light in enumerate(lights):
        body[i, 0] = (*light.position, float(light.type))
        body[i, 1] = (*light.color, light.intensity)
        body[i, 2] = (*light.direction, light.influence_radius)
        body[i, 3] = (light.source_radius, light.source_length, 0.0, 0.0)
    return header.tobytes() + body.tobytes()


def unpack_lights(data: bytes) -> list[Light]:
    """Inverse of pack_lights (for tests and debugging)."""
    count = int(np.frombuffer(data, dtype="<i4", count=1)[0])
    body = np.frombuffer(data, dtype="<f4", offset=LIGHTS_HEADER).reshape(-1, 4, 4)
    kinds: dict[int, LightKind] = {0: "point", 1: "directional", 2: "sphere", 3: "tube"}
    out = []
    for row in body[:count].astype(np.float64):
        out.append(
            Light(
                kind=kinds[int(round(row[0, 3]))],
                position=tuple(row[0, :3]),
                color=tuple(row[1, :3]),
                intensity=float(row[1, 3]),
                direction=tuple(row[2, :3]),
                influence_radius=float(row[2, 3]),
                source_radius=float(row[3, 0]),
                source_length=float(row[3, 1]),
            )
        )
    return out
