"""The environment BRDF LUT of the split sum (docs/shading.md#image-based-lighting), by
deterministic quadrature.

A(NoV, roughness) and B(NoV, roughness) are the notes' IntegrateBRDF averages over GGX
half vectors H (k = a/2, exact (1 - VoH)^5, zero where NoL <= 0). Plain Hammersley
needs more than 16k points a texel to come within 1e-3 of the converged values: the
integrand is cut off where L = reflect(-V, H) drops below the horizon, and that cut-off
(a kink, or nearly a jump when k is small) sits across the point set. So we integrate
the same expectation in coordinates where it is smooth:

* Azimuth. For a half vector at polar angle theta_h, NoL > 0 exactly when
  cos(phi) > c0 = -NoV cos(2 theta_h) / (2 cos(theta_h) sinV sin(theta_h)), so the
  azimuth integral runs over [0, phi_max], phi_max = acos(c0), folded by the symmetry
  phi -> -phi. Inside it the integrand is smooth: 8-point Gauss-Legendre.
* Polar angle. GGX sampling's u = tan^2 / (a^2 + tan^2) makes du = 2 u (1 - u) ds for
  s = ln tan(theta_h): a bell of unit width around ln a whatever the roughness, so one
  grid serves roughness 0.01 and 1 alike. s runs over ln a +- 8 (the tails hold
  e^-16 of the mass), split at s1 and s2 where the azimuth range starts to shrink
  (theta_h = pi/4 - theta_v/2) and vanishes (pi/4 + theta_v/2); each part gets
  4-point Gauss-Legendre panels in proportion to its length, and the panels that end
  on s1 or s2 use a quadratic substitution that smooths the square-root kink there.

Measured at the 32 x 32 cell centres against a converged integration (float64, 8k
points a texel, agreeing with an independent brute-force H-space integration to 5e-5),
max |error| over A and B:

    this quadrature, 512 evaluations a texel ........ 1.7e-4
    this quadrature, 1024 (the default) ............. 1.6e-5
    notes' Hammersley estimator, 1024 ............... 3.1e-2
    notes' Hammersley estimator, 16384 .............. 5.8e-3

(The Hammersley figures are this poor partly because the notes' tangent frame for N = +Z
turns the point set by 90 degrees against V's azimuth; docs/shading.md#measured-accuracy
has the generators side by side.) A 128 x 128 LUT takes ~0.1 s on llvmpipe, half of it the
sheen channel (brdf_lut.frag).
"""

from __future__ import annotations

import moderngl
import numpy as np

from matedit.ibl import gpu

DEFAULT_LUT_SIZE = 128
DEFAULT_LUT_SAMPLES = 1024


def brdf_lut(
    size: int = DEFAULT_LUT_SIZE,
    samples: int = DEFAULT_LUT_SAMPLES,
    *,
    ctx: moderngl.Context,
    method: str = "quadrature",
) -> np.ndarray:
    """(size, size, 2) float32: [k, i] = (A, B) at roughness (k+.5)/size, NoV (i+.5)/size.

    Computed on the GPU, uncached (`matedit.ibl.bake_brdf_lut` caches). `samples` is the
    number of integrand evaluations a texel; method "hammersley" runs the notes' Monte
    Carlo estimator instead, for comparison.
    """
    with gpu.Baker(ctx) as baker:
        return baker.brdf_lut(size, samples, method)
