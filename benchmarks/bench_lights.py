"""Measured specular energy of the area lights: rendered / true (not a test).

    .venv/bin/python benchmarks/bench_lights.py [--quick] [--gpu] [--only PART]

Geometry (tests/light_energy_ref.py): a white metal (F0 = 1) with N = +Z, the light straight
above at d = 2 m (one sphere table with the light 45 degrees off the normal), intensity 1;
energy = the specular radiant exitance (outgoing specular
radiance integrated over all view directions, weighted by N.V). True: a uniform sphere of
radius r (Le = I / (pi r^2)) or a capsule of radius 0.02 m and length l along X (Le =
I / (2 r l + pi r^2)), integrated over its solid angle against the GGX albedo. Rendered:
the representative-point lights, evaluated by matedit.shading (the numpy twin the tests hold
to the GLSL at 1e-4; `--gpu` evaluates the GLSL itself), for the widening divisor of
a' = a + r / (c d): c = 3 (docs/shading.md's reading, before) and c = 2 (the default now).
The tests (tests/test_shading_light_energy.py) check a subset on the GPU.
The sheen lobe's sphere lights are measured against its own brute force (sheen_table), its
tubes against the capsule's solid angle over the lobe's albedo (sheen_tube_table). The
anisotropic lobe (table_aniso) against its own albedo, spheres overhead and 45 degrees off,
tubes along, across and at 45 degrees to the stretch. `--only base|coat|sheen|aniso` prints
one part (the aniso table takes minutes); with `--gpu`, base and aniso evaluate the GLSL.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from light_energy_ref import (  # noqa: E402
    aniso_albedo,
    brdf_albedo,
    capsule_true_energy,
    exitance_axisymmetric,
    sphere_true_energy,
    sphere_true_energy_tilted,
    tube_view_grid,
    turned_albedo,
)

import matedit.shading.anisotropy as anisotropy  # noqa: E402
import matedit.shading.brdf as brdf  # noqa: E402
import matedit.shading.coat as coat  # noqa: E402
import matedit.shading.lights as lights  # noqa: E402
import matedit.shading.sheen as sheen  # noqa: E402

D = 2.0
TILT = math.radians(45.0)  # the second sphere table: the light 45 degrees off the normal
TUBE_RADIUS = 0.02
ROUGHNESS = (0.1, 0.2, 0.3, 0.5, 0.7, 0.9)
SPHERE_RD = (0.01, 0.05, 0.1, 0.25, 0.5)
TUBE_LENGTHS = (0.25, 0.5, 1.0, 2.0)


def _twin(V, kind, radius, length, rough, tilt=0.0):
    n = len(V)
    s = lights.makeShadingContext(np.zeros((n, 3)), np.tile([0.0, 0.0, 1.0], (n, 1)), V,
                                  np.zeros((n, 3)), np.ones((n, 3)), np.full(n, rough))
    pos = (D * math.sin(tilt), 0.0, D * math.cos(tilt))
    light = lights.Light(kind, position=pos, direction=(1.0, 0.0, 0.0),
                         intensity=1.0, influence_radius=1e4, source_radius=radius,
                         source_length=length)
    return lights.evaluateLight(s, light)[:, 0]


def _twin_coat(V, kind, radius, length, rough, tilt=0.0):
    """The coat lobe alone (issue 23): the base black (no diffuse, its specular scaled to 0,
    its roughness 0.9 so a coat reading the base's alpha would show), the coat over it with
    weight 1, roughness `rough` and, for this measurement only, F0 = 1 (F = 1, the white
    metal's definition of the true energy), on the same N = +Z."""
    n = len(V)
    N = np.tile([0.0, 0.0, 1.0], (n, 1))
    s = lights.makeShadingContext(np.zeros((n, 3)), N, V, np.zeros((n, 3)), np.zeros((n, 3)),
                                  np.full(n, 0.9))
    s.specularScale = 0.0
    s.coat = coat.makeCoatContext(N, V, np.ones(n), np.full(n, rough),
                                  lights.MIN_ANALYTIC_ROUGHNESS, np.ones(3), 1.5)
    s.coat.F0 = np.ones(n)
    pos = (D * math.sin(tilt), 0.0, D * math.cos(tilt))
    light = lights.Light(kind, position=pos, direction=(1.0, 0.0, 0.0),
                         intensity=1.0, influence_radius=1e4, source_radius=radius,
                         source_length=length)
    return lights.evaluateLight(s, light)[:, 0]


ANISOTROPY = 0.9  # the anisotropic rows: T along X (the tube's axis), B along Y


def _twin_aniso(V, kind, radius, length, rough, tilt=0.0, axis_deg=0.0):
    """The anisotropic lobe (issue 23) at ANISOTROPY, stretched along X, on N = +Z; a tube's
    axis `axis_deg` degrees from X in the surface's plane."""
    n = len(V)
    N = np.tile([0.0, 0.0, 1.0], (n, 1))
    s = lights.makeShadingContext(np.zeros((n, 3)), N, V, np.zeros((n, 3)), np.ones((n, 3)),
                                  np.full(n, rough))
    s.aniso = anisotropy.makeAnisotropicLobe(s.a, np.full(n, ANISOTROPY), np.array([1.0, 0, 0]),
                                             np.tile([1.0, 0, 0], (n, 1)),
                                             np.tile([0.0, 1, 0], (n, 1)), N)
    pos = (D * math.sin(tilt), 0.0, D * math.cos(tilt))
    ang = math.radians(axis_deg)
    light = lights.Light(kind, position=pos, direction=(math.cos(ang), math.sin(ang), 0.0),
                         intensity=1.0, influence_radius=1e4, source_radius=radius,
                         source_length=length)
    return lights.evaluateLight(s, light)[:, 0]


AXIS_DEGREES = (45.0, 90.0)  # the extra tubes: across the stretch (90) and between


def table_aniso(quick: bool, spec=None) -> tuple[list, list, list, list]:
    """Rendered / true for the anisotropic lobe: spheres straight above and 45 degrees off
    (towards +X, along the stretch), tubes along X (the stretch) and, in the last list,
    tubes at AXIS_DEGREES from it; all integrated over the tube view grid (the lobe is not
    axisymmetric)."""
    spec = spec or _twin_aniso
    V, w = tube_view_grid(400, 400) if quick else tube_view_grid(800, 800)
    rhos = {r: aniso_albedo(r, ANISOTROPY) for r in ROUGHNESS}
    spheres, tilted, tubes, turned = [], [], [], []
    for rows, tilt in ((spheres, 0.0), (tilted, TILT)):
        for rd in SPHERE_RD:
            row = []
            for rough in ROUGHNESS:
                true = sphere_true_energy_tilted(rd * D, D, tilt, rough, rho=rhos[rough])
                row.append(float(np.sum(spec(V, "sphere", rd * D, 0.0, rough, tilt) * w))
                           / true)
            rows.append((rd, row))
    for deg, rows in ((0.0, tubes),) + tuple((d, turned) for d in AXIS_DEGREES):
        for length in TUBE_LENGTHS:
            row = []
            for rough in ROUGHNESS:
                true = capsule_true_energy(TUBE_RADIUS, length, D, rough,
                                           rho=turned_albedo(rhos[rough], deg))
                row.append(float(np.sum(spec(V, "tube", TUBE_RADIUS, length, rough,
                                             axis_deg=deg) * w)) / true)
            rows.append((f"{length} m, {deg:g}°" if deg else length, row))
    return spheres, tilted, tubes, turned


def _gpu(ctx):
    from gpu_eval import gpu_eval_many
    from test_shading_light_energy import BODY

    def spec(V, kind, radius, length, rough, tilt=0.0):
        n = len(V)
        f = lambda x: np.full(n, x, np.float32)  # noqa: E731
        k = {"sphere": 2, "tube": 3}[kind]
        body = BODY.replace("vec3(0.0, 0.0, dist)",
                            f"dist * vec3({math.sin(tilt):.9f}, 0.0, {math.cos(tilt):.9f})")
        out = gpu_eval_many(ctx, body, {"V": V.astype(np.float32), "kind": f(k), "dist": f(D),
                                        "radius": f(radius), "len": f(length),
                                        "rough": f(rough)}, {"spec": "float"},
                            includes=["lights.glsl"])
        return out["spec"].astype(np.float64)
    return spec


def _gpu_aniso(ctx):
    """The GLSL of _twin_aniso (lights.glsl with MATERIAL_HAS_ANISOTROPY)."""
    from gpu_eval import gpu_eval_many
    from test_shading_light_energy import BODY

    def spec(V, kind, radius, length, rough, tilt=0.0, axis_deg=0.0):
        n = len(V)
        f = lambda x: np.full(n, x, np.float32)  # noqa: E731
        ang = math.radians(axis_deg)
        body = BODY.replace("vec3(0.0, 0.0, dist)",
                            f"dist * vec3({math.sin(tilt):.9f}, 0.0, {math.cos(tilt):.9f})")
        axis = f"vec3({math.cos(ang):.9f}, {math.sin(ang):.9f}, 0.0)"
        body = body.replace("light.direction = vec3(1.0, 0.0, 0.0);",
                            f"light.direction = {axis};")
        x, y, z = "vec3(1.0, 0.0, 0.0)", "vec3(0.0, 1.0, 0.0)", "vec3(0.0, 0.0, 1.0)"
        body = body.replace("    spec = ", f"    s.aniso = makeAnisotropicLobe(s.a, {ANISOTROPY}, "
                            f"{x}, {x}, {y}, {z});\n    spec = ")
        out = gpu_eval_many(ctx, body, {"V": V.astype(np.float32), "kind": f({"sphere": 2,
                                        "tube": 3}[kind]), "dist": f(D), "radius": f(radius),
                                        "len": f(length), "rough": f(rough)}, {"spec": "float"},
                            includes=["lights.glsl"], defines=("MATERIAL_HAS_ANISOTROPY",))
        return out["spec"].astype(np.float64)
    return spec


def table(spec, quick: bool) -> tuple[list, list, list]:
    n_view = 8000 if quick else 20000
    grid = tube_view_grid(400, 400) if quick else tube_view_grid(800, 800)
    spheres, tubes = [], []
    for rd in SPHERE_RD:
        row = []
        for rough in ROUGHNESS:
            true = sphere_true_energy(rd * D, D, rough)
            e = exitance_axisymmetric(
                lambda V, rd=rd, rough=rough: spec(V, "sphere", rd * D, 0.0, rough), n=n_view)
            row.append(e / true)
        spheres.append((rd, row))
    V, w = grid
    tilted = []
    for rd in SPHERE_RD:
        row = []
        for rough in ROUGHNESS:
            true = sphere_true_energy_tilted(rd * D, D, TILT, rough)
            row.append(float(np.sum(spec(V, "sphere", rd * D, 0.0, rough, TILT) * w)) / true)
        tilted.append((rd, row))
    for length in TUBE_LENGTHS:
        row = []
        for rough in ROUGHNESS:
            true = capsule_true_energy(TUBE_RADIUS, length, D, rough)
            row.append(float(np.sum(spec(V, "tube", TUBE_RADIUS, length, rough) * w)) / true)
        tubes.append((length, row))
    return spheres, tilted, tubes


def markdown(title: str, spheres, tilted, tubes) -> str:
    head = "| light | " + " | ".join(f"rough {r}" for r in ROUGHNESS) + " |"
    sep = "|---|" + "---|" * len(ROUGHNESS)
    lines = [f"**{title}**", "", head, sep]
    for rd, row in spheres:
        lines.append(f"| sphere r/d {rd} | " + " | ".join(f"{x:.2f}" for x in row) + " |")
    for rd, row in tilted:
        lines.append(f"| sphere r/d {rd}, 45° | " + " | ".join(f"{x:.2f}" for x in row) + " |")
    for length, row in tubes:
        name = f"tube {length}" if isinstance(length, str) else f"tube {length} m"
        lines.append(f"| {name} | " + " | ".join(f"{x:.2f}" for x in row) + " |")
    return "\n".join(lines)


def goal(spheres, tilted, tubes) -> str:
    inside = [x for rd, row in spheres + tilted if rd <= 0.25
              for r, x in zip(ROUGHNESS, row) if r >= 0.2]
    inside += [x for _, row in tubes for r, x in zip(ROUGHNESS, row) if r >= 0.2]
    ok = all(0.75 <= x <= 1.25 for x in inside)
    return (f"goal (within +-25 % for sphere r/d <= 0.25 and every tube, roughness >= 0.2): "
            f"{'met' if ok else 'missed'}; range {min(inside):.2f} .. {max(inside):.2f}")


# -- the sheen lobe (issue 23): its lights against its own brute force -----------------------

SHEEN_ROUGHNESS = (0.3, 0.5, 0.7, 1.0)


def _no_lut(NoV, r):
    """E = 0: the base is black here, so its albedo scaling does not matter."""
    return np.zeros(np.broadcast_shapes(np.shape(NoV), np.shape(r)) + (3,))


def _twin_sheen(V, kind, radius, length, rough, tilt=0.0):
    """The sheen lobe alone: base black (no diffuse, its specular scaled to 0), a white sheen
    of roughness `rough` on N = +Z, lit by the light as the renderer lights it (sphere and
    tube towards the light's centre, sheen_shading.glsl)."""
    n = len(V)
    N = np.tile([0.0, 0.0, 1.0], (n, 1))
    s = lights.makeShadingContext(np.zeros((n, 3)), N, V, np.zeros((n, 3)), np.zeros((n, 3)),
                                  np.full(n, 0.9))
    s.specularScale = 0.0
    white = np.ones((n, 3))
    sheen.setupSheen(s, white, np.full(n, rough), white, _no_lut)
    pos = (D * math.sin(tilt), 0.0, D * math.cos(tilt))
    light = lights.Light(kind, position=pos, direction=(1.0, 0.0, 0.0),
                         intensity=1.0, influence_radius=1e4, source_radius=radius,
                         source_length=length)
    return lights.evaluateLight(s, light)[:, 0]


def _sheen_true_of_view(V, radius, rough, n_cos=48, n_phi=96):
    """Brute force: the radiance the white sheen reflects towards each V from a uniform sphere
    light of radius `radius` straight above at D (Le = I / (pi r^2)), by a midpoint grid over
    the light's cone in (cos, phi), uniform in solid angle."""
    cos_max = math.sqrt(max(1.0 - (radius / D) ** 2, 0.0))
    c = 1.0 - (np.arange(n_cos) + 0.5) / n_cos * (1.0 - cos_max)
    phi = (np.arange(n_phi) + 0.5) / n_phi * 2.0 * math.pi
    C, P = np.meshgrid(c, phi, indexing="ij")
    S = np.sqrt(1.0 - C * C)
    L = np.stack([S * np.cos(P), S * np.sin(P), C], -1).reshape(-1, 3)
    d_omega = 2.0 * math.pi * (1.0 - cos_max) / len(L)
    Le = 1.0 / (math.pi * radius * radius)
    N = np.array([0.0, 0.0, 1.0])
    alpha = sheen.sheenAlpha(rough)
    out = np.empty(len(V))
    for i, v in enumerate(V):
        f = sheen.sheenBRDF(N, v, L, alpha) * L[:, 2]
        out[i] = Le * float(f.sum()) * d_omega
    return out


def sheen_table(quick: bool) -> list:
    """Sphere lights straight above: rendered / brute-force sheen exitance."""
    n_view = 400 if quick else 1500
    rows = []
    for rd in SPHERE_RD:
        row = []
        for rough in SHEEN_ROUGHNESS:
            true = exitance_axisymmetric(
                lambda V, rd=rd, rough=rough: _sheen_true_of_view(V, rd * D, rough), n=n_view)
            e = exitance_axisymmetric(
                lambda V, rd=rd, rough=rough: _twin_sheen(V, "sphere", rd * D, 0.0, rough),
                n=n_view)
            row.append(e / true)
        rows.append((rd, row))
    return rows


def sheen_albedo(rough: float):
    """rho(l) of the white sheen lobe (matedit.shading.sheen.sheenBRDF, the lobe under test)
    by light_energy_ref.brdf_albedo: the tubes' true energy is capsule_true_energy of it
    (the swapped integrals; the lobe is reciprocal, as the test checks)."""
    N = np.array([0.0, 0.0, 1.0])
    alpha = sheen.sheenAlpha(rough)
    return brdf_albedo(lambda V, L: sheen.sheenBRDF(N, V, L, alpha))


def sheen_tube_table(quick: bool) -> list:
    """Tubes along X straight above: rendered (over the tube view grid) / the capsule's true
    sheen exitance."""
    V, w = tube_view_grid(200, 200) if quick else tube_view_grid(400, 400)
    rhos = {r: sheen_albedo(r) for r in SHEEN_ROUGHNESS}
    rows = []
    for length in TUBE_LENGTHS:
        row = []
        for rough in SHEEN_ROUGHNESS:
            true = capsule_true_energy(TUBE_RADIUS, length, D, rough, rho=rhos[rough])
            e = float(np.sum(_twin_sheen(V, "tube", TUBE_RADIUS, length, rough) * w))
            row.append(e / true)
        rows.append((length, row))
    return rows


def sheen_markdown(rows, tubes=()) -> str:
    head = "| light | " + " | ".join(f"sheen rough {r}" for r in SHEEN_ROUGHNESS) + " |"
    lines = ["**sheen lobe: rendered / brute-force sheen energy, light straight above (tubes "
             "along X), numpy twin**", "", head, "|---|" + "---|" * len(SHEEN_ROUGHNESS)]
    for rd, row in rows:
        lines.append(f"| sphere r/d {rd} | " + " | ".join(f"{x:.3f}" for x in row) + " |")
    for length, row in tubes:
        lines.append(f"| tube {length} m | " + " | ".join(f"{x:.3f}" for x in row) + " |")
    return "\n".join(lines)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--gpu", action="store_true", help="evaluate the GLSL (llvmpipe: slower)")
    ap.add_argument("--only", choices=("all", "base", "coat", "sheen", "aniso"), default="all",
                    help="one table (base: the talk's lobe, both divisors); --gpu: base, aniso")
    args = ap.parse_args()
    want = lambda part: args.only in ("all", part)  # noqa: E731
    ctx = None
    if args.gpu:
        from matedit.render.context import headless_context

        ctx = headless_context()
    saved = brdf.AREA_WIDEN_DIVISOR
    try:
        for c in (3.0, saved) if want("base") else ():
            if ctx is not None and c != saved:
                continue  # the GLSL is compiled with its own default
            brdf.AREA_WIDEN_DIVISOR = c
            t0 = time.perf_counter()
            spec = _gpu(ctx) if ctx is not None else _twin
            spheres, tilted, tubes = table(spec, args.quick)
            label = "before" if c == 3.0 else "now (default)"
            print(markdown(f"rendered / true specular energy, a' = a + r / ({c:g} d), {label}, "
                           f"{'GLSL' if ctx else 'numpy twin'}", spheres, tilted, tubes))
            print()
            print(goal(spheres, tilted, tubes) + f"  [{time.perf_counter() - t0:.1f} s]")
            print()
        if ctx is None and want("coat"):
            # the clear coat's lobe: its own representative point and widening (its alpha)
            t0 = time.perf_counter()
            spheres, tilted, tubes = table(_twin_coat, args.quick)
            print(markdown(f"clear coat lobe: rendered / true specular energy, a' = a + r / "
                           f"({saved:g} d), coat roughness in the columns, numpy twin",
                           spheres, tilted, tubes))
            print()
            print(goal(spheres, tilted, tubes) + f"  [{time.perf_counter() - t0:.1f} s]")
            print()
        if ctx is None and want("sheen"):
            t0 = time.perf_counter()
            print(sheen_markdown(sheen_table(args.quick), sheen_tube_table(args.quick)))
            print(f"[{time.perf_counter() - t0:.1f} s]")
            print()
        if want("aniso"):
            # the anisotropic lobe: representative points closest to R in the lobe's metric,
            # widening per alpha (anisotropy.glsl); its own albedo for the true energy
            t0 = time.perf_counter()
            spec = _gpu_aniso(ctx) if ctx is not None else None
            spheres, tilted, tubes, turned = table_aniso(args.quick, spec)
            print(markdown(f"anisotropic lobe (anisotropy {ANISOTROPY}, stretched along X): "
                           f"rendered / true specular energy, a' = a + r / ({saved:g} d), "
                           f"roughness in the columns, {'GLSL' if ctx else 'numpy twin'}",
                           spheres, tilted, tubes + turned))
            print()
            print(goal(spheres, tilted, tubes + turned)
                  + f"  [{time.perf_counter() - t0:.1f} s]")
            print()
    finally:
        brdf.AREA_WIDEN_DIVISOR = saved
        if ctx is not None:
            ctx.release()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
