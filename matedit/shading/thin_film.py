"""Twin of ``thin_film.glsl``: thin-film iridescence, the Airy reflectance of a dielectric film
on the base (Belcour & Barla 2017, as glTF KHR_materials_iridescence evaluates it) in place of
the base specular's Fresnel. Vectorised over pixels."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from matedit.shading.common import f64

# The Gaussian fit of the CIE XYZ sensitivities in wavenumber (1/m): amplitude, mean,
# variance of X, Y, Z, and X's second lobe; the normalisation (Belcour & Barla 2017,
# supplemental; the constants as glTF KHR_materials_iridescence tabulates them).
_AMP = np.array([5.4856e-13, 4.4201e-13, 5.2481e-13])
_MEAN = np.array([1.6810e6, 1.7953e6, 2.2084e6])
_VAR = np.array([4.3278e9, 9.3046e9, 6.6121e9])
_X2 = (9.7470e-14, 2.2399e6, 4.5282e9)
_NORM = 1.0685e-7
# Orders of the Airy sum's Fourier form kept (the extension keeps 2; thin_film.glsl)
THIN_FILM_ORDERS = 12
# XYZ to linear Rec.709 (IEC 61966-2-1), rows the output channels
XYZ_TO_REC709 = np.array([[3.2404542, -1.5371385, -0.4985314],
                          [-0.9692660, 1.8760108, 0.0415560],
                          [0.0556434, -0.2040259, 1.0572252]])


@dataclass
class ThinFilm:
    thickness: np.ndarray   # (...,) nm; 0: no film
    ior: np.ndarray         # (...,)
    outsideIor: np.ndarray  # (...,)
    baseIor: np.ndarray     # (..., 3)


def thinFilmIorOfF0(F0) -> np.ndarray:
    s = np.sqrt(np.clip(f64(F0), 0.0, 0.9999))
    return (1.0 + s) / (1.0 - s)


def thinFilmF0OfIor(n, nOut) -> np.ndarray:
    r = (f64(n) - f64(nOut)) / (f64(n) + f64(nOut))
    return r * r


def thinFilmSchlick(F0, c) -> np.ndarray:
    x = 1.0 - f64(c)
    return f64(F0) + (1.0 - f64(F0)) * x**5


def makeThinFilm(thickness, ior, outsideIor, F0) -> ThinFilm:
    F0 = f64(F0)
    shape = F0.shape[:-1]
    return ThinFilm(np.broadcast_to(np.maximum(f64(thickness), 0.0), shape),
                    np.broadcast_to(f64(ior), shape), np.broadcast_to(f64(outsideIor), shape),
                    thinFilmIorOfF0(F0))


def thinFilmSensitivity(opd, shift) -> np.ndarray:
    """opd (...,) nm, shift (..., 3) -> (..., 3) linear Rec.709."""
    phase = 2.0 * np.pi * f64(opd)[..., None] * 1e-9
    shift = f64(shift)
    xyz = _AMP * np.sqrt(2.0 * np.pi * _VAR) * np.cos(_MEAN * phase + shift) * np.exp(
        -_VAR * phase * phase)
    a, mu, v = _X2
    x2 = a * np.sqrt(2.0 * np.pi * v) * np.cos(mu * phase[..., 0] + shift[..., 0]) * np.exp(
        -v * phase[..., 0] ** 2)
    xyz = xyz + np.stack([x2, np.zeros_like(x2), np.zeros_like(x2)], -1)
    return (xyz / _NORM) @ XYZ_TO_REC709.T


def smoothstep(e0: float, e1: float, x) -> np.ndarray:
    t = np.clip((f64(x) - e0) / (e1 - e0), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def thinFilmFresnel(f: ThinFilm, cosTheta1) -> np.ndarray:
    """The film's reflectance towards cosTheta1 (...,) -> (..., 3)."""
    c1 = np.clip(f64(cosTheta1), 0.0, 1.0)
    out = f64(f.outsideIor)
    n2 = out + (f64(f.ior) - out) * smoothstep(0.0, 0.03, f.thickness)
    ratio = out / n2
    cos2Sq = 1.0 - ratio * ratio * (1.0 - c1 * c1)
    tir = cos2Sq <= 0.0
    c2 = np.sqrt(np.maximum(cos2Sq, 0.0))
    R12 = thinFilmSchlick(thinFilmF0OfIor(n2, out), c1)
    T121 = 1.0 - R12
    phi21 = np.where(n2 < out, 0.0, np.pi)
    R23 = thinFilmSchlick(thinFilmF0OfIor(f.baseIor, n2[..., None]), c2[..., None])
    phi23 = np.where(f64(f.baseIor) < n2[..., None], np.pi, 0.0)
    opd = 2.0 * n2 * f64(f.thickness) * c2
    phi = phi21[..., None] + phi23
    R123 = np.clip(R12[..., None] * R23, 0.0, 0.9999)
    r123 = np.sqrt(R123)
    Rs = (T121 * T121)[..., None] * R23 / (1.0 - R123)
    intensity = R12[..., None] + Rs
    Cm = Rs - T121[..., None]
    for m in range(1, THIN_FILM_ORDERS + 1):
        Cm = Cm * r123
        intensity = intensity + Cm * 2.0 * thinFilmSensitivity(m * opd, m * phi)
    return np.where(tir[..., None], 1.0, np.maximum(intensity, 0.0))


def filmOrFresnel(f: ThinFilm | None, F0, cosTheta, fresnel) -> np.ndarray:
    """thinFilmFresnel where the film has a thickness, else `fresnel(F0, cosTheta)` (the
    plain Fresnel, exactly, at thickness 0)."""
    plain = fresnel(F0, cosTheta)
    if f is None:
        return plain
    return np.where((f64(f.thickness) > 0.0)[..., None], thinFilmFresnel(f, cosTheta), plain)
