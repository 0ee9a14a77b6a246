"""Reference mode's Monte Carlo area lights (lights_reference.glsl) against an independent
numpy brute force: a deterministic quadrature over the emitter's surface of
Le f(l, v) N.l cos(theta_light) / dist^2, with the BRDF written here from docs/shading.md#brdf
(Lambert, GGX, Schlick-Smith with k = (roughness + 1)^2 / 8, spherical-Gaussian Fresnel). Nothing is
imported from matedit.shading. Emitters (the file's header): a sphere of radiance
I / (pi r^2); a capsule of radiance I / (2 r l + pi r^2).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from gpu_eval import gpu_eval_many

pytestmark = pytest.mark.gl


def brdf_cos(N, V, L, diffuse, F0, rough):
    """f(l, v) N.l, rows of unit vectors; rough clamped to 0.03 as for analytic lights."""
    rough = max(rough, 0.03)
    a = rough * rough
    k = (rough + 1) ** 2 / 8
    nol = L @ N
    nov = max(float(N @ V), 1e-4)
    H = L + V
    H /= np.linalg.norm(H, axis=1, keepdims=True)
    noh = np.clip(H @ N, 0, 1)
    voh = np.clip(H @ V, 0, 1)
    D = a * a / (math.pi * (noh * noh * (a * a - 1) + 1) ** 2)
    vis = 1.0 / (4 * (nol * (1 - k) + k) * (nov * (1 - k) + k))
    fc = 2.0 ** ((-5.55473 * voh - 6.98316) * voh)
    F = F0[None, :] + (1 - F0[None, :]) * fc[:, None]
    spec = (D * vis * nol)[:, None] * F
    out = diffuse[None, :] / math.pi * nol[:, None] + spec
    return np.where(nol[:, None] > 0, out, 0.0)


def _frame(axis):
    axis = axis / np.linalg.norm(axis)
    up = np.array([0.0, 0.0, 1.0]) if abs(axis[2]) < 0.999 else np.array([1.0, 0.0, 0.0])
    t = np.cross(up, axis)
    t /= np.linalg.norm(t)
    return t, np.cross(axis, t), axis


def surface_integral(points, normals, dA, le, N, V, diffuse, F0, rough):
    """Sum over surface elements facing the shaded point (at the origin)."""
    dist2 = np.sum(points * points, axis=1)
    L = points / np.sqrt(dist2)[:, None]
    cos_l = -np.sum(normals * L, axis=1)
    w = np.where(cos_l > 0, cos_l / dist2 * dA, 0.0)
    return le * np.sum(brdf_cos(N, V, L, diffuse, F0, rough) * w[:, None], axis=0)


def sphere_points(c, r, n=700):
    th = (np.arange(n) + 0.5) / n * math.pi
    ph = (np.arange(2 * n) + 0.5) / (2 * n) * 2 * math.pi
    TH, PH = np.meshgrid(th, ph, indexing="ij")
    nrm = np.stack([np.sin(TH) * np.cos(PH), np.sin(TH) * np.sin(PH), np.cos(TH)], -1)
    dA = (r * r * np.sin(TH) * (math.pi / n) * (math.pi / n)).reshape(-1)
    nrm = nrm.reshape(-1, 3)
    return c + r * nrm, nrm, dA


def capsule_points(c, axis, length, r, n_len=1200, n_ang=400, n_cap=300):
    t, b, ax = _frame(np.asarray(axis, np.float64))
    s = ((np.arange(n_len) + 0.5) / n_len - 0.5) * length
    ang = (np.arange(n_ang) + 0.5) / n_ang * 2 * math.pi
    S, A = np.meshgrid(s, ang, indexing="ij")
    nrm = np.cos(A)[..., None] * t + np.sin(A)[..., None] * b
    pts = c + S[..., None] * ax + r * nrm
    dA = np.full(S.size, (length / n_len) * r * (2 * math.pi / n_ang))
    cap_p, cap_n, cap_a = sphere_points(np.zeros(3), r, n_cap)
    side = cap_n @ ax
    cap_p = cap_p + np.where(side[:, None] >= 0, c + 0.5 * length * ax, c - 0.5 * length * ax)
    return (np.concatenate([pts.reshape(-1, 3), cap_p]),
            np.concatenate([nrm.reshape(-1, 3), cap_n]), np.concatenate([dA, cap_a]))


BODY = """
    Light light;
    light.type = int(kind + 0.5);
    light.position = pos;
    light.direction = axis;
    light.color = vec3(1.0);
    light.intensity = 1.0;
    light.influenceRadius = 1.0e4;
    light.sourceRadius = radius;
    light.sourceLength = len;
    ShadingContext s = makeShadingContext(vec3(0.0), nrm, view, diffuse, f0, rough);
    ref = evaluateLightReference(s, light, uint(count + 0.5), vec2(0.0));
    rep = evaluateLight(s, light);
"""


def gpu_light(ctx, cases, count=4096):
    cols = {k: np.array([c[k] for c in cases], np.float32)
            for k in ("pos", "axis", "nrm", "view", "diffuse", "f0")}
    scal = {k: np.array([c[k] for c in cases], np.float32)
            for k in ("kind", "radius", "len", "rough")}
    out = gpu_eval_many(ctx, BODY, {**cols, **scal,
                                    "count": np.full(len(cases), count, np.float32)},
                        {"ref": "vec3", "rep": "vec3"}, includes=["lights_reference.glsl"])
    return out["ref"].astype(np.float64), out["rep"].astype(np.float64)


def _unit(v):
    v = np.asarray(v, np.float64)
    return v / np.linalg.norm(v)


def make_cases():
    cases = []
    base = dict(axis=[1.0, 0.0, 0.0], diffuse=[0.3, 0.2, 0.1], f0=[0.9, 0.8, 0.6])
    views = [_unit([0.3, 0.0, 1.0]), _unit([-0.6, 0.2, 0.5])]
    for rough in (0.25, 0.6):
        for v in views:
            # sphere above, sphere half below the horizon, capsule above, capsule tilted
            cases.append({**base, "kind": 2, "pos": [-0.5, 0.1, 1.8], "radius": 0.4, "len": 0.0,
                          "nrm": [0.0, 0.0, 1.0], "view": v, "rough": rough})
            cases.append({**base, "kind": 2, "pos": [1.5, 0.0, 0.1], "radius": 0.5, "len": 0.0,
                          "nrm": [0.0, 0.0, 1.0], "view": v, "rough": rough})
            cases.append({**base, "kind": 3, "pos": [-0.4, 0.0, 1.5], "radius": 0.08,
                          "len": 1.2, "nrm": [0.0, 0.0, 1.0], "view": v, "rough": rough})
            cases.append({**base, "kind": 3, "pos": [0.6, 0.5, 1.2], "radius": 0.05,
                          "len": 1.5, "axis": list(_unit([1.0, 1.0, 0.5])),
                          "nrm": [0.0, 0.0, 1.0], "view": v, "rough": rough})
    return cases


def brute_force(case):
    N, V = np.asarray(case["nrm"], float), np.asarray(case["view"], float)
    c, r = np.asarray(case["pos"], float), case["radius"]
    if case["kind"] == 2:
        pts, nrm, dA = sphere_points(c, r)
        le = 1.0 / (math.pi * r * r)
    else:
        pts, nrm, dA = capsule_points(c, case["axis"], case["len"], r)
        le = 1.0 / (2 * r * case["len"] + math.pi * r * r)
    return surface_integral(pts, nrm, dA, le, N, V, np.asarray(case["diffuse"], float),
                            np.asarray(case["f0"], float), case["rough"])


def test_area_light_reference_converges_to_brute_force(ctx):
    cases = make_cases()
    ref, rep = gpu_light(ctx, cases)
    truth = np.array([brute_force(c) for c in cases])
    rel = np.abs(ref - truth).max(axis=1) / truth.max(axis=1)
    # 4,096 light + 4,096 GGX samples (one Hammersley set, balance heuristic): measured max
    # relative error ~1e-3; the brute force's own quadrature error is ~1e-4
    assert rel.max() < 0.01, rel
    # the representative point is not the reference: it differs by far more than that
    # somewhere (horizon clipping, energy), which is what the difference view shows
    rep_rel = np.abs(rep - truth).max(axis=1) / truth.max(axis=1)
    assert rep_rel.max() > 0.05, rep_rel


def test_fewer_samples_still_converge(ctx):
    """The renderer's 32 a frame accumulated over rotated frames: 32 x 32 samples."""
    from matedit.render.renderer import r2_offset

    cases = make_cases()[:4]
    truth = np.array([brute_force(c) for c in cases])
    acc = np.zeros_like(truth)
    frames = 32
    for f in range(frames):
        o = r2_offset(f)
        body = BODY.replace("vec2(0.0)", f"vec2({o[0]:.9f}, {o[1]:.9f})")
        cols = {k: np.array([c[k] for c in cases], np.float32)
                for k in ("pos", "axis", "nrm", "view", "diffuse", "f0")}
        scal = {k: np.array([c[k] for c in cases], np.float32)
                for k in ("kind", "radius", "len", "rough")}
        out = gpu_eval_many(ctx, body, {**cols, **scal,
                                        "count": np.full(len(cases), 32, np.float32)},
                            {"ref": "vec3", "rep": "vec3"}, includes=["lights_reference.glsl"])
        acc += out["ref"]
    rel = np.abs(acc / frames - truth).max(axis=1) / truth.max(axis=1)
    assert rel.max() < 0.03, rel


def _black_env_renderer(gl_ctx, lights):
    import sys

    sys.path.insert(0, str(__import__("pathlib").Path(__file__).parent))
    from test_render import SMALL, flat_material

    from matedit.compiler import compile_document
    from matedit.ibl import Environment
    from matedit.io.document import FileResolver
    from matedit.render import Renderer

    r = Renderer(gl_ctx, (32, 32), environment=None, bake_settings=SMALL)
    r.set_environment(Environment("black", equirect=np.zeros((16, 32, 3), np.float32)))
    r.show_gizmos = False
    r.set_lights(lights)
    doc = flat_material(base=(0.8, 0.8, 0.8), metallic=1.0, roughness=0.3)
    assert r.set_material(compile_document(doc, FileResolver(), "glsl330")).ok
    r.set_reference_samples(256)
    return r


def test_difference_view_shows_the_representative_point_error(gl_ctx):
    from matedit.shading.lights import Light

    sphere = [Light("sphere", position=(1.5, 1.5, 2.5), intensity=20.0, influence_radius=50.0,
                    source_radius=0.6)]
    point = [Light("point", position=(1.5, 1.5, 2.5), intensity=20.0, influence_radius=50.0)]
    means = {}
    for name, rig in (("sphere", sphere), ("point", point)):
        r = _black_env_renderer(gl_ctx, rig)
        try:
            r.mode = "difference"
            r.render_converged()
            means[name] = r.difference_mean
            split, ref = r.read_hdr("splitsum"), r.read_hdr("reference")
            assert np.isfinite(ref).all()
            if name == "point":  # punctual lights are exact in both: nothing to show
                assert np.abs(split - ref).max() < 1e-4
        finally:
            r.release()
    assert means["sphere"] > 1e-3 and means["sphere"] > 20 * means["point"], means
