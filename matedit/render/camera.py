"""An orbit camera: yaw and pitch around a target, distance, vertical field of view."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


def perspective(fovy_deg: float, aspect: float, near: float, far: float) -> np.ndarray:
    f = 1.0 / math.tan(math.radians(fovy_deg) / 2)
    m = np.zeros((4, 4))
    m[0, 0] = f / aspect
    m[1, 1] = f
    m[2, 2] = (far + near) / (near - far)
    m[2, 3] = 2 * far * near / (near - far)
    m[3, 2] = -1.0
    return m


def look_at(eye, target, up=(0.0, 1.0, 0.0)) -> np.ndarray:
    eye, target, up = (np.asarray(x, dtype=np.float64) for x in (eye, target, up))
    f = target - eye
    f /= np.linalg.norm(f)
    s = np.cross(f, up)
    if np.linalg.norm(s) < 1e-9:
        s = np.cross(f, (0.0, 0.0, 1.0))
    s /= np.linalg.norm(s)
    u = np.cross(s, f)
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = s, u, -f
    m[:3, 3] = -m[:3, :3] @ eye
    return m


@dataclass
class OrbitCamera:
    yaw: float = 30.0  # degrees about +Y, 0 looks down -Z
    pitch: float = 15.0  # degrees above the horizon
    distance: float = 4.0
    target: tuple[float, float, float] = (0.0, 0.0, 0.0)
    fov: float = 40.0
    near: float = 0.05
    far: float = 100.0

    def reset(self) -> None:
        self.yaw, self.pitch, self.distance, self.target = 30.0, 15.0, 4.0, (0.0, 0.0, 0.0)

    @property
    def eye(self) -> np.ndarray:
        y, p = math.radians(self.yaw), math.radians(self.pitch)
        d = np.array([math.sin(y) * math.cos(p), math.sin(p), math.cos(y) * math.cos(p)])
        return np.asarray(self.target) + self.distance * d

    def orbit(self, dyaw: float, dpitch: float) -> None:
        self.yaw = (self.yaw + dyaw) % 360.0
        self.pitch = max(-89.0, min(89.0, self.pitch + dpitch))

    def dolly(self, factor: float) -> None:
        self.distance = max(0.3, min(50.0, self.distance * factor))

    def pan(self, dx: float, dy: float) -> None:
        """Moves the target in the view plane by fractions of the distance."""
        view = self.view_matrix()
        right, up = view[0, :3], view[1, :3]
        t = np.asarray(self.target) + (right * dx + up * dy) * self.distance
        self.target = tuple(float(x) for x in t)

    def view_matrix(self) -> np.ndarray:
        return look_at(self.eye, self.target)

    def projection(self, aspect: float) -> np.ndarray:
        return perspective(self.fov, aspect, self.near, self.far)


# a bound within this share of a half-turn of the view axis is taken as unbounded (the sphere
# reaches beside the eye: its projection is not bounded on that side)
_EDGE_ANGLE = math.radians(89.0)


def sphere_screen_bounds(center, radius: float, view: np.ndarray, projection: np.ndarray
                         ) -> tuple[float, float, float, float] | None:
    """The rectangle (x0, y0, x1, y1) in normalised device coordinates that holds the
    perspective projection of the sphere (`center` in world space, `radius`), clamped to the
    screen (-1..1): on each axis the two planes through the eye tangent to the sphere bound
    it (Mara and McGuire 2013, "2D Polyhedral Bounds of a Clipped, Perspective-Projected 3D
    Sphere"). None when the sphere is not wholly in front of the near plane (the eye inside or
    beside it): then nothing is known and the whole screen is the bound. An empty rectangle
    (x0 >= x1 or y0 >= y1) when the sphere is off screen. `projection` is a `perspective`
    matrix (P[0,0] and P[1,1] scale x/-z and y/-z; no skew)."""
    c = view[:3, :3] @ np.asarray(center, dtype=np.float64) + view[:3, 3]
    depth = -c[2]  # in front of the eye: positive
    near = projection[2, 3] / (projection[2, 2] - 1.0)  # the near distance, from the matrix
    if depth - radius <= near:  # reaching the near plane (or behind the eye)
        return None
    out = []
    for axis, scale in ((0, projection[0, 0]), (1, projection[1, 1])):
        d = math.hypot(c[axis], depth)
        centre = math.atan2(c[axis], depth)
        half = math.asin(min(1.0, radius / d))
        lo, hi = centre - half, centre + half
        out.append((-1.0 if lo <= -_EDGE_ANGLE else max(-1.0, scale * math.tan(lo)),
                    1.0 if hi >= _EDGE_ANGLE else min(1.0, scale * math.tan(hi))))
    (x0, x1), (y0, y1) = out
    return x0, y0, x1, y1
