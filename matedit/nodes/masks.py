"""Masks from the surface's geometry and view."""

from __future__ import annotations

from typing import TYPE_CHECKING

from matedit.nodes.kind import UNIT, Thumbnail, _fn, _i, _o
from matedit.nodes.twin import _clamp, _col, _dot, _need, _smoothstep, derivatives

if TYPE_CHECKING:
    import numpy as np
else:  # numpy is imported at first use (matedit.nodes.lazy_numpy)
    from matedit.nodes.lazy_numpy import np



def _nov(ctx):
    return _clamp(_dot(ctx.normal, ctx.view), 0.0, 1.0)


def _unit_axis(up):
    return up / _col(np.sqrt(np.maximum(_dot(up, up), 1e-12)))


def _fresnel(ctx, base, exponent):
    nov = _nov(_need(ctx))
    return (base + (1.0 - base) * np.power(1.0 - nov, np.maximum(exponent, 1e-4)),)


# --- masks -----------------------------------------------------------------------------------
_fn("fresnel", "Fresnel", "Mask",
    "Schlick's Fresnel of the geometric normal and view: base at normal incidence, 1 at "
    "grazing.",
    [_i("base", "float", 0.04, "reflectance facing the viewer", UNIT),
     _i("exponent", "float", 5.0, "", (0.0, 16.0))], [_o("value", "float")],
    impure=True, geometry=True,
    numpy=_fresnel)
_fn("facing_ratio", "Facing Ratio", "Mask",
    "N · V: 1 where the surface faces the camera, 0 at its silhouette.", [],
    [_o("value", "float")], impure=True, geometry=True,
    numpy=lambda ctx: (_nov(_need(ctx)),))


def _slope_mask(ctx, up, threshold, softness):
    d = _dot(_need(ctx).normal, _unit_axis(up))
    s = np.maximum(softness, 1e-4)
    return (_smoothstep(threshold - s, threshold + s, d),)


_fn("slope_mask", "Slope Mask", "Mask",
    "1 where the surface faces up (world normal · up above threshold): snow, dust, moss.",
    [_i("up", "vec3", [0.0, 1.0, 0.0]), _i("threshold", "float", 0.5, "cosine", (-1.0, 1.0)),
     _i("softness", "float", 0.1, "", (0.0, 1.0))], [_o("mask", "float")],
    impure=True, geometry=True,
    numpy=_slope_mask)


def _height_mask(ctx, up, low, high):
    h = _dot(_need(ctx).position, _unit_axis(up))
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(high > low + 1e-6, _clamp((h - low) / (high - low), 0.0, 1.0),
                     np.where(h < low, 0.0, 1.0)).astype(h.dtype)
    return (t * t * (3.0 - 2.0 * t),)


_fn("height_mask", "Height Mask", "Mask",
    "0 below low, 1 above high along the up axis in world space: grime at the bottom, "
    "water lines.",
    [_i("up", "vec3", [0.0, 1.0, 0.0]), _i("low", "float", -1.0, "metres", (-10.0, 10.0)),
     _i("high", "float", 1.0, "metres", (-10.0, 10.0))], [_o("mask", "float")],
    impure=True, geometry=True,
    numpy=_height_mask)


def _curvature(ctx, scale):
    ctx = _need(ctx)
    dndx, dndy = derivatives(ctx, ctx.normal)
    dpdx, dpdy = derivatives(ctx, ctx.position)
    kx = _dot(dndx, dpdx) / np.maximum(_dot(dpdx, dpdx), 1e-12)
    ky = _dot(dndy, dpdy) / np.maximum(_dot(dpdy, dpdy), 1e-12)
    k = 0.5 * (kx + ky)
    return k, _clamp(k * scale, 0.0, 1.0), _clamp(-k * scale, 0.0, 1.0)


_fn("curvature", "Curvature", "Mask",
    "Mean curvature of the surface from screen-space derivatives of its normal (1/m), and "
    "its convex and concave parts scaled into [0, 1]: edge wear and cavity dirt without "
    "baked maps.",
    [_i("scale", "float", 0.5, "metres: mask reaches 1 at curvature 1/scale", (0.0, 10.0))],
    [_o("curvature", "float"), _o("convex", "float"), _o("concave", "float")],
    thumbnail=Thumbnail.ALWAYS, impure=True, geometry=True,
    numpy=_curvature)
