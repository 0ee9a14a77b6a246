"""Diffuse irradiance as order-2 spherical harmonics (Ramamoorthi and Hanrahan 2001).

`project_radiance` integrates the cube map against the nine real SH basis functions,
using each texel's exact solid angle. `irradiance_coefficients` convolves those with
the clamped cosine (band factors pi, 2 pi / 3, pi / 4), so that the irradiance is

    E(N) = sum_i E_i * Y_i(N)        and the diffuse term is diffuseColor * E(N) / pi.

Basis order (i = 0..8): Y00; Y1-1 (y), Y10 (z), Y11 (x); Y2-2 (xy), Y2-1 (yz),
Y20 (3z^2 - 1), Y21 (xz), Y22 (x^2 - y^2), in world coordinates (+Y up).
"""

from __future__ import annotations

import numpy as np

from matedit.ibl.cubemap import face_directions, texel_solid_angles

# Normalisation constants of the real basis, in the order above.
SH_CONSTANTS = (
    0.282094791773878,  # 1 / (2 sqrt(pi))
    0.488602511902920,  # sqrt(3 / (4 pi))
    0.488602511902920,
    0.488602511902920,
    1.092548430592079,  # sqrt(15 / (4 pi))
    1.092548430592079,
    0.315391565252520,  # sqrt(5 / (16 pi))
    1.092548430592079,
    0.546274215296040,  # sqrt(15 / (16 pi))
)
# Clamped-cosine convolution per band (Ramamoorthi and Hanrahan 2001, eq. 8).
BAND_FACTORS = (np.pi,) + (2.0 * np.pi / 3.0,) * 3 + (np.pi / 4.0,) * 5


def sh_basis(dirs: np.ndarray) -> np.ndarray:
    """The nine basis functions at unit directions (..., 3) -> (..., 9)."""
    d = np.asarray(dirs, dtype=np.float64)
    x, y, z = d[..., 0], d[..., 1], d[..., 2]
    c = SH_CONSTANTS
    return np.stack(
        [
            np.full_like(x, c[0]),
            c[1] * y,
            c[2] * z,
            c[3] * x,
            c[4] * x * y,
            c[5] * y * z,
            c[6] * (3.0 * z * z - 1.0),
            c[7] * x * z,
            c[8] * (x * x - y * y),
        ],
        axis=-1,
    )


def project_radiance(faces: np.ndarray) -> np.ndarray:
    """SH coefficients (9, 3) of the radiance in a cube map (6, n, n, >=3)."""
    n = faces.shape[1]
    basis = sh_basis(face_directions(n).reshape(-1, 3))  # (6 n n, 9)
    omega = np.broadcast_to(texel_solid_angles(n), (6, n, n)).reshape(-1, 1)
    rgb = np.asarray(faces[..., :3], dtype=np.float64).reshape(-1, 3) * omega
    return basis.T @ rgb  # one matrix product: sum over texels of Y_k * L_c * dOmega


def irradiance_coefficients(radiance_sh: np.ndarray) -> np.ndarray:
    """Convolve radiance coefficients with the clamped cosine: E_i = A_l(i) * L_i."""
    return np.asarray(radiance_sh) * np.asarray(BAND_FACTORS)[:, None]


def sh_irradiance(faces: np.ndarray) -> np.ndarray:
    """Irradiance coefficients (9, 3) of a cube map: `E(N) = sh_basis(N) @ coeffs`."""
    return irradiance_coefficients(project_radiance(faces))


def eval_irradiance(coeffs: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Irradiance E(N) (..., 3) at unit normals (..., 3) from `sh_irradiance` coefficients."""
    return sh_basis(normals) @ np.asarray(coeffs, dtype=np.float64)
