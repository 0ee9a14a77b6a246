"""Prints the accuracy tables of docs/shading.md, measured on this machine's GL.

    .venv/bin/python docs/accuracy.py          # about a minute on 2 cores (llvmpipe)

Each table compares matedit against an independent reference: the brute-force integrations
in tests/ (the same ones the test suite holds the code to), or a brute-force integral over
a sphere light's solid angle written here. Nothing is asserted; the tests do that.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT))


def table(header: list[str], rows: list[list[str]]) -> None:
    print("| " + " | ".join(header) + " |")
    print("|" + "|".join("---" if i == 0 else "---:" for i in range(len(header))) + "|")
    for r in rows:
        print("| " + " | ".join(r) + " |")
    print()


def lut_section(ctx) -> None:
    from test_ibl_lut import CENTRES, N, brute_force_lut

    from matedit.ibl.gpu import Baker

    ref = brute_force_lut()
    rows = []
    with Baker(ctx) as baker:
        for method, samples in (("quadrature (default)", 1024), ("hammersley", 1024),
                                ("hammersley", 4096)):
            name = method.split()[0]
            lut = baker.brdf_lut(N, samples, method=name)
            err = np.abs(lut - ref)
            k, i, _c = np.unravel_index(err.argmax(), err.shape)
            rows.append([method, f"{samples:,}", f"{err.max():.1e}", f"{err.mean():.1e}",
                         f"roughness {CENTRES[k]:.2f}, NoV {CENTRES[i]:.2f}"])
    print("### Environment BRDF LUT\n")
    print(f"{N}×{N} cell centres against `brute_force_lut` of tests/test_ibl_lut.py (a "
          "midpoint rule over half vectors, float64, converged to about 7e-5).\n")
    table(["generator", "samples a texel", "max abs error", "mean abs error", "worst cell"],
          rows)


def prefilter_section(ctx) -> None:
    from test_ibl_prefilter import blob_faces, brute_force_prefilter

    from matedit.ibl.cubemap import face_directions
    from matedit.ibl.gpu import Baker

    faces = blob_faces(32)
    rows = []
    with Baker(ctx) as baker:
        for samples in (64, 256):
            mips = baker.prefilter(faces, levels=4, samples=samples, lod_bias=0.5)
            for m in (1, 2, 3):
                dirs = face_directions(mips[m].shape[1]).reshape(-1, 3)
                ref = brute_force_prefilter(faces, dirs, m / 3)
                got = mips[m].reshape(-1, 3)
                err = np.abs(got - ref)
                rows.append([f"{samples}", f"{m} (roughness {m / 3:.2f})",
                             f"{err.max() / ref.max():.4f}", f"{err.mean() / ref.mean():.4f}"])
    print("### Prefiltered environment\n")
    print("A 32² cube with one bright Gaussian spot (peak 40, σ 0.12 rad, background 0.05), "
          "4 mips; every texel of mips 1–3 against `brute_force_prefilter` of "
          "tests/test_ibl_prefilter.py (a sum over every source texel of env · D · NoL · dω, "
          "N = V = R).\n")
    table(["GGX samples a texel", "mip", "max error / peak", "mean error / mean"], rows)


def _cone_directions(axis: np.ndarray, half_angle: float, n: int) -> tuple[np.ndarray, float]:
    """n stratified unit vectors uniformly over a cone, and the solid angle each stands for."""
    cos_max = np.cos(half_angle)
    side = int(np.sqrt(n))
    u = (np.arange(side) + 0.5) / side
    cu, phi = np.meshgrid(1.0 - u * (1.0 - cos_max), 2.0 * np.pi * u, indexing="ij")
    su = np.sqrt(1.0 - cu * cu)
    local = np.stack([su * np.cos(phi), su * np.sin(phi), cu], -1).reshape(-1, 3)
    z = axis / np.linalg.norm(axis)
    x = np.cross(z, [0.0, 1.0, 0.0] if abs(z[1]) < 0.9 else [1.0, 0.0, 0.0])
    x /= np.linalg.norm(x)
    y = np.cross(z, x)
    dirs = local @ np.stack([x, y, z])
    return dirs, 2.0 * np.pi * (1.0 - cos_max) / len(dirs)


def sphere_light_section() -> None:
    from matedit.shading import lights as L

    radius, d = 0.25, 2.0
    centre = np.array([0.0, 0.0, 1.0]) * d  # straight above the shaded point
    # Outgoing directions over the hemisphere (stratified in cos θ and φ).
    nv = 48
    u = (np.arange(nv) + 0.5) / nv
    cos_t, phi = np.meshgrid(u, 2.0 * np.pi * u, indexing="ij")
    sin_t = np.sqrt(1.0 - cos_t * cos_t)
    V = np.stack([sin_t * np.cos(phi), sin_t * np.sin(phi), cos_t], -1).reshape(-1, 3)
    d_omega_v = 2.0 * np.pi / len(V)
    Ldirs, d_omega_l = _cone_directions(centre, np.arcsin(radius / d), 1024)
    radiance = 1.0 / (np.pi * radius * radius)  # a sphere of intensity 1
    rows = []
    for roughness in (0.1, 0.2, 0.35, 0.5, 0.8):
        n = len(V)
        s = L.makeShadingContext(np.zeros((n, 3)), np.tile([0.0, 0.0, 1.0], (n, 1)), V,
                                 np.zeros((n, 3)), np.ones((n, 3)), np.full(n, roughness))
        light = L.Light(kind="sphere", position=tuple(centre), intensity=1.0,
                        influence_radius=1e4, source_radius=radius)
        model = L.sphereLight(s, light)[:, 0]
        brute = np.zeros(n)
        for Ld in Ldirs:
            brute += L.specularTowards(s, np.broadcast_to(Ld, (n, 3)))[:, 0]
        brute *= radiance * d_omega_l
        e_model = float((model * V[:, 2]).sum() * d_omega_v)
        e_brute = float((brute * V[:, 2]).sum() * d_omega_v)
        a = roughness * roughness
        # the default widening is a' = a + r/(2d); the notes' reading r/(3d) for comparison
        alt = (a / min(1.0, a + radius / (3 * d))) ** 2 / (a / min(1.0, a + radius / (2 * d))) ** 2
        rows.append([f"{roughness:.2f}", f"{e_model / e_brute:.2f}",
                     f"{e_model * alt / e_brute:.2f}"])
    print("### Sphere light, specular energy\n")
    print(f"Reflected specular energy (∫ Lo NoV dω over every view direction) of a white metal "
          f"(F0 = 1) under a sphere light of radius {radius} m at {d} m straight above, "
          "`matedit.shading.lights.sphereLight` (representative point and the default "
          "normalisation, a' = a + r/(2d)) divided by a brute-force integral of the same BRDF "
          "over the sphere's solid angle at uniform radiance. 1.00 is exact; the second "
          "column is what `sourceRadius / (3 d)` would give instead. "
          "`benchmarks/bench_lights.py` measures more sizes, tubes and tilted lights "
          "(benchmarks/LIGHTS_ENERGY.md).\n")
    table(["roughness", "ours, a' = a + r/(2d)", "if a' = a + r/(3d)"], rows)


def ibl_section(ctx) -> None:
    from test_render import SMALL, _sphere_hits, constant_env, flat_material

    from matedit.compiler import compile_document
    from matedit.ibl import bake
    from matedit.io import document as fmt
    from matedit.io.document import FileResolver
    from matedit.render import Renderer
    from matedit.resources import graphs_dir
    from matedit.shading.ibl import sample_lut

    r = Renderer(ctx, (64, 64), samples=4, environment="studio", bake_settings=SMALL)
    try:
        r.show_gizmos = False
        r.set_lights([])
        r.reference_frames = 32
        rows = []
        for path in sorted((graphs_dir() / "materials").glob("*.json")):
            r.set_material(compile_document(fmt.load(path), FileResolver()))
            r.mode = "splitsum"
            r.render()
            split = r.read_hdr().copy()
            r.mode = "reference"
            r.render_converged()
            ref = r.read_hdr("reference")
            rows.append([path.stem, f"{np.abs(split - ref).mean() / max(ref.mean(), 1e-6):.3f}"])
        print("### Split sum against the reference, sample materials\n")
        print("64² renders, 4x MSAA, built-in studio environment, no analytic lights; mean "
              "|split-sum − reference| over the image divided by the reference's mean "
              "radiance (linear HDR). The reference accumulates 32 frames of GGX and cosine "
              "samples from the unfiltered environment.\n")
        table(["material", "mean relative difference"], rows)

        r.set_environment(constant_env(1.0))
        r.show_background = False
        r.reference_frames = 64
        r.mode = "reference"
        lut = bake(constant_env(1.0), SMALL, ctx=ctx).lut
        hit, P, V = _sphere_hits(r)
        nov = np.clip(np.sum(P * V, -1), 0, 1)
        inner = hit & (nov > 0.25)
        rows = []
        for roughness in (0.2, 0.5, 0.9):
            r.set_material(compile_document(flat_material(roughness=roughness)))
            r.render_converged()
            got = r.read_hdr("reference").mean(-1)
            want = sample_lut(lut, nov[inner], np.full(inner.sum(), roughness)).sum(-1)
            err = np.abs(got[inner] - want)
            rows.append([f"{roughness:.1f}", f"{np.median(err):.4f}",
                         f"{np.percentile(err, 95):.4f}", f"{want.mean():.3f}"])
        print("### White furnace: reference mode against the LUT's A + B\n")
        print("A white metal (F0 = 1) under a constant white environment reflects A + B of "
              "the environment BRDF LUT; the reference renderer (64 frames) against the LUT, "
              "over the sphere's pixels with NoV > 0.25.\n")
        table(["roughness", "median abs error", "95th percentile", "mean A + B"], rows)
    finally:
        r.release()


def main() -> int:
    from matedit.render.context import headless_context

    t0 = time.perf_counter()
    ctx = headless_context()
    print(f"GL: {ctx.info['GL_RENDERER']}, {ctx.info['GL_VERSION']}\n")
    lut_section(ctx)
    prefilter_section(ctx)
    sphere_light_section()
    ibl_section(ctx)
    print(f"({time.perf_counter() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
