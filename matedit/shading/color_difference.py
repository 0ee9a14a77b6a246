"""Colour difference of display images: CIE L*a*b* (D65) from sRGB codes, and CIEDE2000.

CIEDE2000 as CIE 142-2001 defines it, in the form of Sharma, Wu and Dalal 2005 ("The
CIEDE2000 color-difference formula: implementation notes, supplementary test data, and
mathematical observations", Color Research and Application 30(1)), with kL = kC = kH = 1;
tests/test_color_difference.py holds it to that paper's 34 test pairs. Pure numpy.
"""

from __future__ import annotations

import numpy as np

# IEC 61966-2-1 (sRGB): linear RGB -> CIE XYZ, D65 white
_RGB_TO_XYZ = np.array([[0.4124, 0.3576, 0.1805],
                        [0.2126, 0.7152, 0.0722],
                        [0.0193, 0.1192, 0.9505]])
_WHITE = _RGB_TO_XYZ.sum(axis=1)  # the matrix's own D65 white (Y = 1)


def srgb_to_lab(rgb) -> np.ndarray:
    """CIE L*a*b* (D65) of sRGB-encoded values in [0, 1], shape (..., 3)."""
    c = np.clip(np.asarray(rgb, np.float64), 0.0, 1.0)
    lin = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    xyz = lin @ _RGB_TO_XYZ.T / _WHITE
    e = 216.0 / 24389.0
    f = np.where(xyz > e, np.cbrt(xyz), (24389.0 / 27.0 * xyz + 16.0) / 116.0)
    return np.stack([116.0 * f[..., 1] - 16.0, 500.0 * (f[..., 0] - f[..., 1]),
                     200.0 * (f[..., 1] - f[..., 2])], axis=-1)


def ciede2000(lab1, lab2) -> np.ndarray:
    """ΔE00 between L*a*b* colours of shape (..., 3), element by element."""
    lab1, lab2 = np.asarray(lab1, np.float64), np.asarray(lab2, np.float64)
    l1, a1, b1 = lab1[..., 0], lab1[..., 1], lab1[..., 2]
    l2, a2, b2 = lab2[..., 0], lab2[..., 1], lab2[..., 2]
    c_mean = (np.hypot(a1, b1) + np.hypot(a2, b2)) / 2.0
    g = 0.5 * (1.0 - np.sqrt(c_mean ** 7 / (c_mean ** 7 + 25.0 ** 7)))
    ap1, ap2 = (1.0 + g) * a1, (1.0 + g) * a2
    cp1, cp2 = np.hypot(ap1, b1), np.hypot(ap2, b2)
    hp1 = np.degrees(np.arctan2(b1, ap1)) % 360.0
    hp2 = np.degrees(np.arctan2(b2, ap2)) % 360.0
    hp1 = np.where((ap1 == 0) & (b1 == 0), 0.0, hp1)
    hp2 = np.where((ap2 == 0) & (b2 == 0), 0.0, hp2)
    achromatic = cp1 * cp2 == 0
    dh = hp2 - hp1
    dh = np.where(dh > 180.0, dh - 360.0, np.where(dh < -180.0, dh + 360.0, dh))
    dh = np.where(achromatic, 0.0, dh)
    d_l = l2 - l1
    d_c = cp2 - cp1
    d_h = 2.0 * np.sqrt(cp1 * cp2) * np.sin(np.radians(dh) / 2.0)
    l_bar = (l1 + l2) / 2.0
    c_bar = (cp1 + cp2) / 2.0
    h_sum = hp1 + hp2
    h_bar = np.where(np.abs(hp1 - hp2) <= 180.0, h_sum / 2.0,
                     np.where(h_sum < 360.0, (h_sum + 360.0) / 2.0, (h_sum - 360.0) / 2.0))
    h_bar = np.where(achromatic, h_sum, h_bar)
    r = np.radians
    t = (1.0 - 0.17 * np.cos(r(h_bar - 30.0)) + 0.24 * np.cos(r(2.0 * h_bar))
         + 0.32 * np.cos(r(3.0 * h_bar + 6.0)) - 0.20 * np.cos(r(4.0 * h_bar - 63.0)))
    d_theta = 30.0 * np.exp(-(((h_bar - 275.0) / 25.0) ** 2))
    r_c = 2.0 * np.sqrt(c_bar ** 7 / (c_bar ** 7 + 25.0 ** 7))
    s_l = 1.0 + 0.015 * (l_bar - 50.0) ** 2 / np.sqrt(20.0 + (l_bar - 50.0) ** 2)
    s_c = 1.0 + 0.045 * c_bar
    s_h = 1.0 + 0.015 * c_bar * t
    r_t = -np.sin(r(2.0 * d_theta)) * r_c
    x, y, z = d_l / s_l, d_c / s_c, d_h / s_h
    return np.sqrt(np.maximum(x * x + y * y + z * z + r_t * y * z, 0.0))


def image_difference(a, b) -> np.ndarray:
    """ΔE00 per pixel between two sRGB display images (H, W, 3) in [0, 1]."""
    return ciede2000(srgb_to_lab(a), srgb_to_lab(b))
