"""Twin of ``output.glsl``: exposure, ACES filmic fit, sRGB encoding."""

from __future__ import annotations

import numpy as np

from matedit.shading.common import f64, saturate


def applyExposure(color, exposureEV) -> np.ndarray:
    return f64(color) * np.exp2(f64(exposureEV))[..., None]


def tonemapACES(x) -> np.ndarray:
    x = np.minimum(np.maximum(f64(x), 0.0), 1e4)  # as output.glsl: no change below 1e4
    return saturate((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14))


def linearToSRGB(c) -> np.ndarray:
    c = saturate(c)
    return np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1.0 / 2.4) - 0.055)


def displayTransform(hdr, exposureEV) -> np.ndarray:
    return linearToSRGB(tonemapACES(applyExposure(hdr, exposureEV)))
