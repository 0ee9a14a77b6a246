"""Light gizmos: a small ball at each point and sphere light, a line with a ball at each end
for a tube light; directional lights have none. Drawn into the scene's HDR target."""

from __future__ import annotations

import moderngl
import numpy as np

from matedit.render.fullscreen import mat_bytes, render_program
from matedit.render.mesh import uv_sphere
from matedit.shading.lights import Light

MIN_RADIUS = 0.04  # a ball's radius at least (m), so that point lights show


def gizmo_color(light: Light) -> tuple[float, ...]:
    """The light's colour scaled by its intensity (capped), lifted so that dim lights show."""
    color = np.asarray(light.color) * min(light.intensity, 50.0) / 10.0 + 0.2
    return tuple(float(c) for c in color)


def tube_ends(light: Light) -> list[np.ndarray]:
    """The two ends of a tube light (its direction normalised; a zero direction gives one point)."""
    d = np.asarray(light.direction, dtype=np.float64)
    d = d / (np.linalg.norm(d) or 1.0)
    half = d * light.source_length / 2
    return [np.asarray(light.position) - half, np.asarray(light.position) + half]


class Gizmos:
    def __init__(self, ctx: moderngl.Context) -> None:
        self._prog = render_program(ctx, "gizmo.vert", "gizmo.frag")
        ball = uv_sphere(1.0, 16, 8)
        self._ball_vbo = ctx.buffer(ball.positions.astype("f4").tobytes())
        self._ball_ibo = ctx.buffer(ball.indices.astype("u4").tobytes())
        self._ball = ctx.vertex_array(self._prog, [(self._ball_vbo, "3f", "a_position")],
                                      self._ball_ibo)
        self._line_vbo = ctx.buffer(reserve=24)
        self._line = ctx.vertex_array(self._prog, [(self._line_vbo, "3f", "a_position")])

    def draw(self, view_projection: np.ndarray, lights: list[Light]) -> None:
        """The gizmos of `lights` into the bound target (depth test as the caller set it)."""
        self._prog["uViewProjection"].write(mat_bytes(view_projection))
        for light in lights:
            if light.kind == "directional":
                continue
            self._prog["uColor"].value = gizmo_color(light)
            r = max(light.source_radius, MIN_RADIUS)
            if light.kind == "tube":
                ends = tube_ends(light)
                self._line_vbo.write(np.array(ends, "f4").tobytes())
                self._prog["uModel"].write(mat_bytes(np.eye(4)))
                self._line.render(mode=moderngl.LINES)
                for e in ends:
                    self._draw_ball(e, r)
            else:
                self._draw_ball(np.asarray(light.position), r)

    def _draw_ball(self, centre, radius: float) -> None:
        m = np.eye(4) * radius
        m[3, 3] = 1.0
        m[:3, 3] = centre
        self._prog["uModel"].write(mat_bytes(m))
        self._ball.render()

    def release(self) -> None:
        for obj in (self._ball, self._line, self._ball_vbo, self._ball_ibo, self._line_vbo,
                    self._prog):
            obj.release()
