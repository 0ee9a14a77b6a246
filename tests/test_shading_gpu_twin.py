"""Every GLSL shading function equals its numpy twin (matedit.shading) on the GPU.

Inputs are float32-exact (numpy sees what the GPU sees); numpy computes in float64.
Tolerance: |gpu - numpy| <= rtol |numpy| + atol (+ slack where stated). rtol = 1e-4 is the
float32 aim; atol covers values that go to 0, where a relative bound means nothing.
Functions that normalise sums of vectors (half vectors, reflections, representative
points) are ill-conditioned near a sharp highlight: float32 rounding of H moves NoH by
~1e-7, and GGX at roughness 0.03 turns that into a large relative change. There the slack
is 4x the spread of the float64 result under 16-ulp perturbations of the inputs (the GPU
must be as good as an exact evaluation of slightly different inputs: backward error).
"""

from __future__ import annotations

import numpy as np
import pytest

from matedit.ibl.importance import build_distribution
from matedit.shading import (
    brdf,
    common,
    env_sampling,
    ibl,
    lights,
    material,
    output,
    sampling,
    surface,
)
from matedit.shading.lights import Light
from matedit.shading.lights_block import pack_lights
from tests.gpu_eval import constant_cubemap as _constant_cube
from tests.gpu_eval import gpu_eval, gpu_eval_many

pytestmark = pytest.mark.gl


# --- float32-exact random inputs, crowding grazing angles and roughness 0 and 1 ---------


def f32(x) -> np.ndarray:
    """Round to float32 and back, so numpy sees exactly what the GPU sees."""
    return np.asarray(x, dtype=np.float32).astype(np.float64)


def unit01(rng, n: int) -> np.ndarray:
    """Values in [0, 1]: half uniform, a quarter crowding 0, a quarter crowding 1, exact ends."""
    u = rng.uniform(0.0, 1.0, n)
    q = n // 4
    u[:q] = 10.0 ** rng.uniform(-6, 0, q)
    u[q : 2 * q] = 1.0 - 10.0 ** rng.uniform(-6, 0, q)
    u[:4] = (0.0, 1.0, 0.5, 1e-7)
    return f32(rng.permutation(u))


def roughness(rng, n: int, lo: float = 0.03) -> np.ndarray:
    """Perceptual roughness in [lo, 1], crowding both ends."""
    return f32(lo + (1.0 - lo) * unit01(rng, n))


def unit_vectors(rng, n: int) -> np.ndarray:
    v = rng.normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def frame_with_cos(rng, N: np.ndarray, cos: np.ndarray) -> np.ndarray:
    """Unit vectors making angle acos(cos) with N, random azimuth."""
    t = np.cross(N, unit_vectors(rng, len(N)))
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    sin = np.sqrt(np.maximum(0.0, 1.0 - cos**2))
    return cos[:, None] * N + sin[:, None] * t


def normal_and_view(rng, n: int) -> tuple[np.ndarray, np.ndarray]:
    """(N, V), V in N's hemisphere with NoV from 1e-4 (grazing) to 1."""
    N = unit_vectors(rng, n)
    cos = np.clip(unit01(rng, n), 1e-4, 1.0)
    V = frame_with_cos(rng, N, cos)
    return f32(N), f32(V / np.linalg.norm(V, axis=1, keepdims=True))


N_ELEMS = 4096
MAX_ERRORS: dict[str, tuple[float, float]] = {}


@pytest.fixture(scope="module", autouse=True)
def _report():
    yield
    print("\nmax |gpu - numpy| (abs, rel to |numpy| + atol):")
    for name, (a, r) in sorted(MAX_ERRORS.items()):
        print(f"  {name:32s} {a:10.3e} {r:10.3e}")




def check(name, gpu, ref, rtol=1e-4, atol=1e-6, slack=0.0):
    gpu = np.asarray(gpu, dtype=np.float64)
    ref = np.broadcast_to(np.asarray(ref, dtype=np.float64), gpu.shape)
    assert np.all(np.isfinite(gpu)), f"{name}: NaN/Inf on the GPU"
    assert np.all(np.isfinite(ref)), f"{name}: NaN/Inf in numpy"
    err = np.abs(gpu - ref)
    tol = rtol * np.abs(ref) + atol + slack
    MAX_ERRORS[name] = (
        float(err.max()),
        float((err / np.maximum(np.abs(ref) + atol, 1e-30)).max()),
    )
    bad = np.argwhere(err > tol)
    assert bad.size == 0, (
        f"{name}: {len(bad)} of {err.size} beyond tolerance; first at {bad[0]}: "
        f"gpu {gpu[tuple(bad[0])]} numpy {ref[tuple(bad[0])]}"
    )


def perturbation_spread(fn, inputs: dict, rng, ulps: float = 16.0, trials: int = 4):
    """Max change of fn(**inputs) when every input moves by a few float32 ulps."""
    ref = fn(**inputs)
    spread = np.zeros_like(ref)
    for _ in range(trials):
        moved = {
            k: v * (1.0 + ulps * 2.0**-24 * rng.standard_normal(np.shape(v)))
            if isinstance(v, np.ndarray) else v
            for k, v in inputs.items()
        }  # fmt: skip
        spread = np.maximum(spread, np.abs(fn(**moved) - ref))
    return 4.0 * spread


# --- common.glsl, sampling.glsl ---------------------------------------------------------


def test_common_helpers(ctx, rng):
    x = f32(rng.uniform(-2, 2, N_ELEMS))
    inc = ["common.glsl"]
    check("saturate", gpu_eval(ctx, "saturate(x)", {"x": x}, includes=inc), common.saturate(x))
    check("sq", gpu_eval(ctx, "sq(x)", {"x": x}, includes=inc), common.sq(x))
    check("pow5", gpu_eval(ctx, "pow5(x)", {"x": x}, includes=inc), common.pow5(x))


def test_hammersley_and_radical_inverse(ctx, rng):
    i = rng.integers(0, 2**24, N_ELEMS)
    n = rng.integers(1, 2**24, N_ELEMS)
    i = np.minimum(i, n - 1)
    inputs = {"i": (i, "uint"), "n": (n, "uint")}
    inc = ["sampling.glsl"]
    got = gpu_eval(ctx, "radicalInverse_VdC(i)", inputs, includes=inc)
    # The GPU returns float32 of an exact dyadic value: one float32 rounding.
    check("radicalInverse_VdC", got, sampling.radicalInverse_VdC(i), rtol=1.2e-7, atol=0)
    got = gpu_eval(ctx, "hammersley(i, n)", inputs, "vec2", includes=inc)
    check("hammersley", got, sampling.hammersley(i, n), rtol=3e-7, atol=0)


def test_tangent_frame(ctx, rng):
    N = unit_vectors(rng, N_ELEMS)
    N[:200, 2] = np.sign(N[:200, 2]) * (1.0 - 10.0 ** rng.uniform(-8, -2, 200))
    N = f32(N / np.linalg.norm(N, axis=1, keepdims=True))
    out = gpu_eval_many(
        ctx, "tangentFrame(N, T, B);", {"N": N}, {"T": "vec3", "B": "vec3"},
        includes=["sampling.glsl"],
    )  # fmt: skip
    T, B = sampling.tangentFrame(N)
    # Unit vectors: an absolute bound is the meaningful one (components cross 0).
    check("tangentFrame.T", out["T"], T, rtol=0, atol=2e-6)
    check("tangentFrame.B", out["B"], B, rtol=0, atol=2e-6)


def test_importance_sampling(ctx, rng):
    Xi = np.stack([unit01(rng, N_ELEMS), unit01(rng, N_ELEMS)], -1)
    Xi = np.minimum(Xi, f32(1.0 - 2.0**-24))  # Hammersley points lie in [0, 1)
    a = f32(roughness(rng, N_ELEMS, lo=0.0) ** 2)
    N = f32(unit_vectors(rng, N_ELEMS))
    inc = ["sampling.glsl"]
    got = gpu_eval(ctx, "importanceSampleGGX(Xi, a, N)", {"Xi": Xi, "a": a, "N": N}, "vec3",
                   includes=inc)  # fmt: skip
    # sqrt((1 - y) / ...) near y = 1 and cos/sin of 2 pi x: absolute error on unit vectors.
    check("importanceSampleGGX", got, sampling.importanceSampleGGX(Xi, a, N), rtol=0, atol=5e-6)
    got = gpu_eval(ctx, "importanceSampleCosine(Xi, N)", {"Xi": Xi, "N": N}, "vec3",
                   includes=inc)  # fmt: skip
    check("importanceSampleCosine", got, sampling.importanceSampleCosine(Xi, N), rtol=0,
          atol=5e-6)  # fmt: skip


# --- brdf.glsl ----------------------------------------------------------------------------


def test_brdf_scalar_terms(ctx, rng):
    x = unit01(rng, N_ELEMS)
    y = unit01(rng, N_ELEMS)
    r = roughness(rng, N_ELEMS, lo=0.01)
    a = f32(r * r)
    k = f32(np.where(rng.uniform(size=N_ELEMS) < 0.5, brdf.k_Analytic(r), brdf.k_IBL(a)))
    inputs = {"x": x, "y": y, "r": r, "a": a, "k": k}
    inc = ["brdf.glsl"]
    cases = {
        "Fd_Lambert": ("Fd_Lambert()", lambda: np.full(N_ELEMS, brdf.Fd_Lambert())),
        "D_GGX": ("D_GGX(x, a)", lambda: brdf.D_GGX(x, a)),
        "k_Analytic": ("k_Analytic(r)", lambda: brdf.k_Analytic(r)),
        "k_IBL": ("k_IBL(a)", lambda: brdf.k_IBL(a)),
        "G1_Schlick": ("G1_Schlick(x, k)", lambda: brdf.G1_Schlick(x, np.maximum(k, 0))),
        "V_SchlickSmith": ("V_SchlickSmith(x, y, k)", lambda: brdf.V_SchlickSmith(x, y, k)),
        "Fc_Exact": ("Fc_Exact(x)", lambda: brdf.Fc_Exact(x)),
    }
    body = "\n".join(f"out_{name} = {expr};" for name, (expr, _) in cases.items())
    outs = {f"out_{name}": "float" for name in cases}
    out = gpu_eval_many(ctx, body, inputs, outs, includes=inc)
    for name, (_, fn) in cases.items():
        # G1 and Fc_Exact reach 0 (x = 0, VoH = 1): absolute floor of 1e-7 there.
        check(name, out[f"out_{name}"], fn(), rtol=1e-4, atol=1e-7)
    got = gpu_eval(ctx, "Fc_SphericalGaussian(x)", inputs, includes=inc)
    # exp2 in float32 of an argument up to -12.5: 1e-4 relative is the bound.
    check("Fc_SphericalGaussian", got, brdf.Fc_SphericalGaussian(x), rtol=1e-4, atol=0)


def test_brdf_vector_terms(ctx, rng):
    n = N_ELEMS
    F0 = f32(rng.uniform(0, 1, (n, 3)))
    dc = f32(rng.uniform(0, 1, (n, 3)))
    NoV, NoL, NoH, VoH = (unit01(rng, n) for _ in range(4))
    r = roughness(rng, n)
    a, k = f32(r * r), f32(brdf.k_Analytic(r))
    inputs = {"F0": F0, "dc": dc, "NoV": NoV, "NoL": NoL, "NoH": NoH, "VoH": VoH, "a": a, "k": k}
    inc = ["brdf.glsl"]
    out = gpu_eval_many(
        ctx,
        "Fs = F_Schlick(F0, VoH); Fe = F_SchlickExact(F0, VoH);"
        "spec = specularLobe(F0, a, k, NoV, NoL, NoH, VoH); diff = diffuseLobe(dc);",
        inputs, {"Fs": "vec3", "Fe": "vec3", "spec": "vec3", "diff": "vec3"}, includes=inc,
    )  # fmt: skip
    check("F_Schlick", out["Fs"], brdf.F_Schlick(F0, VoH))
    check("F_SchlickExact", out["Fe"], brdf.F_SchlickExact(F0, VoH))
    check("specularLobe", out["spec"], brdf.specularLobe(F0, a, k, NoV, NoL, NoH, VoH))
    check("diffuseLobe", out["diff"], brdf.diffuseLobe(dc))


# --- material.glsl --------------------------------------------------------------------------


def test_material_helpers(ctx, rng):
    n = N_ELEMS
    base = f32(rng.uniform(0, 1, (n, 3)))
    metal = unit01(rng, n)
    tn = f32(np.concatenate([rng.uniform(-1, 1, (n, 2)), rng.uniform(0.05, 1, (n, 1))], 1))
    N = f32(unit_vectors(rng, n))
    T, B = sampling.tangentFrame(N)
    T, B = f32(T), f32(B)
    out = gpu_eval_many(
        ctx,
        "dc = computeDiffuseColor(base, metal); f0 = computeF0(base, metal);"
        "w = tangentToWorldNormal(tn, T, B, N);"
        "MaterialAttributes m = defaultMaterialAttributes();"
        "d0 = vec4(m.baseColor, m.metallic); d1 = vec4(m.roughness, m.cavity, m.opacity, 0.0);"
        "d2 = vec4(m.normal, 0.0); d3 = vec4(m.emissive, 0.0);",
        {"base": base, "metal": metal, "tn": tn, "T": T, "B": B, "N": N},
        {"dc": "vec3", "f0": "vec3", "w": "vec3", "d0": "vec4", "d1": "vec4", "d2": "vec4",
         "d3": "vec4"},
        includes=["material.glsl"],
    )  # fmt: skip
    check("computeDiffuseColor", out["dc"], material.computeDiffuseColor(base, metal))
    check("computeF0", out["f0"], material.computeF0(base, metal))
    check("tangentToWorldNormal", out["w"], material.tangentToWorldNormal(tn, T, B, N),
          rtol=0, atol=2e-6)  # fmt: skip
    m = material.defaultMaterialAttributes()
    check("defaultMaterialAttributes", np.concatenate([out[f"d{i}"] for i in range(4)], 1),
          np.concatenate([m.baseColor, [m.metallic, m.roughness, m.cavity, m.opacity, 0],
                          m.normal, [0], m.emissive, [0]]), rtol=0, atol=0)  # fmt: skip


# --- lights.glsl --------------------------------------------------------------------------

_MAKE_LIGHT = """
Light makeLight(int type, vec3 position, vec3 direction, vec3 color, float intensity,
                float influenceRadius, float sourceRadius, float sourceLength) {
    Light l;
    l.type = type; l.position = position; l.direction = direction; l.color = color;
    l.intensity = intensity; l.influenceRadius = influenceRadius;
    l.sourceRadius = sourceRadius; l.sourceLength = sourceLength;
    return l;
}
"""


def _scene(rng, n):
    """Per-element shading point, material and light parameters."""
    N, V = normal_and_view(rng, n)
    P = f32(rng.uniform(-1, 1, (n, 3)))
    dist = 10.0 ** rng.uniform(-1.5, 0.7, n)
    to_light = unit_vectors(rng, n)
    pos = f32(P + dist[:, None] * to_light)
    return {
        "P": P, "N": N, "V": V, "pos": pos,
        "dir": f32(unit_vectors(rng, n)),
        "col": f32(rng.uniform(0, 1, (n, 3))),
        "I": f32(rng.uniform(1, 100, n)),
        "R": f32(dist * rng.uniform(0.5, 3.0, n)),  # about 1 in 5 beyond the radius
        "srcR": f32(rng.uniform(0, 0.5, n) * dist),
        "srcL": f32(rng.uniform(0, 2, n)),
        "dc": f32(rng.uniform(0, 1, (n, 3))),
        "F0": f32(rng.uniform(0.02, 1, (n, 3))),
        "rough": roughness(rng, n, lo=0.0),
    }  # fmt: skip


def _np_light(kind, s):
    return Light(kind=kind, position=s["pos"], direction=s["dir"], color=s["col"],
                 intensity=s["I"], influence_radius=s["R"], source_radius=s["srcR"],
                 source_length=s["srcL"])  # fmt: skip


@pytest.mark.parametrize("kind", ["point", "directional", "sphere", "tube"])
def test_lights(ctx, rng, kind):
    s = _scene(rng, N_ELEMS)
    type_id = lights.LIGHT_TYPES[kind]
    body = (
        "ShadingContext s = makeShadingContext(P, N, V, dc, F0, rough);"
        f"Light light = makeLight({type_id}, pos, dir, col, I, R, srcR, srcL);"
        "result = evaluateLight(s, light);"
        f"direct = {kind}Light(s, light);"
    )
    out = gpu_eval_many(ctx, body, s, {"result": "vec3", "direct": "vec3"},
                        includes=["lights.glsl"], preamble=_MAKE_LIGHT)  # fmt: skip

    def twin(**v):
        c = lights.makeShadingContext(v["P"], v["N"], v["V"], v["dc"], v["F0"], v["rough"])
        return lights.evaluateLight(c, _np_light(kind, v))

    ref = twin(**s)
    slack = perturbation_spread(twin, s, rng)
    # Radiance spans 1e-6..1e6: relative 1e-4 plus the conditioning slack (module doc).
    check(f"{kind}Light", out["direct"], ref, rtol=1e-4, atol=1e-6, slack=slack)
    check(f"evaluateLight[{kind}]", out["result"], ref, rtol=1e-4, atol=1e-6, slack=slack)
    exact = np.abs(out["direct"] - ref) <= 1e-4 * np.abs(ref) + 1e-6
    MAX_ERRORS[f"{kind}Light share within 1e-4"] = (float(exact.mean()), 0.0)


def test_light_building_blocks(ctx, rng):
    s = _scene(rng, N_ELEMS)
    R = f32(common.reflect(-s["V"], s["N"]))
    d = f32(np.linalg.norm(s["pos"] - s["P"], axis=1))
    Lc = f32(s["pos"] - s["P"])
    half = s["srcL"][:, None] * s["dir"] * 0.5
    L0, L1 = f32(Lc - half), f32(Lc + half)
    a = f32(np.maximum(s["rough"], 0.03) ** 2)
    inputs = {**s, "Rv": R, "d": d, "Lc": Lc, "L0": L0, "L1": L1, "a": a}
    body = """
        win = distanceWindow(d, R); fall = distanceFalloff(d, R);
        sn = sphereNormalization(a, srcR, d); ln = lineNormalization(a, srcL, d);
        ti = tubeIrradiance(N, L0, L1);
        srp = sphereRepresentativePoint(Lc, Rv, srcR);
        trp = tubeRepresentativePoint(L0, L1, Rv);
        ShadingContext s = makeShadingContext(P, N, V, dc, F0, rough);
        st = specularTowards(s, normalize(Lc));
    """
    outs = {"win": "float", "fall": "float", "sn": "float", "ln": "float", "ti": "float",
            "srp": "vec3", "trp": "vec3", "st": "vec3"}  # fmt: skip
    out = gpu_eval_many(ctx, body, inputs, outs, includes=["lights.glsl"])
    # The window is 0 beyond R and goes to 0 as (1 - (d/R)^4)^2: absolute floor 1e-6.
    check("distanceWindow", out["win"], lights.distanceWindow(d, s["R"]), atol=1e-6)
    check("distanceFalloff", out["fall"], lights.distanceFalloff(d, s["R"]), atol=1e-6)
    check("sphereNormalization", out["sn"], lights.sphereNormalization(a, s["srcR"], d))
    check("lineNormalization", out["ln"], lights.lineNormalization(a, s["srcL"], d))
    ti = lights.tubeIrradiance(s["N"], L0, L1)
    check("tubeIrradiance", out["ti"], ti, atol=1e-5,
          slack=perturbation_spread(lambda **v: lights.tubeIrradiance(**v),
                                    {"N": s["N"], "L0": L0, "L1": L1}, rng))  # fmt: skip
    check("sphereRepresentativePoint", out["srp"],
          lights.sphereRepresentativePoint(Lc, R, s["srcR"]), rtol=0, atol=1e-5)  # fmt: skip
    trp = lights.tubeRepresentativePoint(L0, L1, R)
    check("tubeRepresentativePoint", out["trp"], trp, rtol=0, atol=1e-5,
          slack=perturbation_spread(lambda **v: lights.tubeRepresentativePoint(**v),
                                    {"L0": L0, "L1": L1, "R": R}, rng)[..., None]
          if trp.ndim == 1 else perturbation_spread(
              lambda **v: lights.tubeRepresentativePoint(**v), {"L0": L0, "L1": L1, "R": R},
              rng))  # fmt: skip

    def st(**v):
        c = lights.makeShadingContext(v["P"], v["N"], v["V"], v["dc"], v["F0"], v["rough"])
        return lights.specularTowards(c, common.normalize(v["Lc"]))

    sv = {k: inputs[k] for k in ("P", "N", "V", "dc", "F0", "rough", "Lc")}
    check("specularTowards", out["st"], st(**sv), slack=perturbation_spread(st, sv, rng))


def test_lobes_reflect_nothing_where_the_light_is_straight_behind_the_view(ctx, rng):
    """L = -V with N.L > 0 (a shading point seen from behind its surface, lit from in front:
    a tube light's representative point can land exactly there) leaves H undefined; the
    plain, coat and anisotropic lobes return exactly 0, not D(0) = inf, on the GPU and in
    the twins. Near it (|L + V| = 1e-3) both stay finite and agree (float32 tolerance)."""
    from matedit.shading import anisotropy, coat

    n = 64
    N = unit_vectors(rng, n)
    L = N + 0.5 * unit_vectors(rng, n)
    L = f32(L / np.linalg.norm(L, axis=1, keepdims=True))
    L = np.where((np.sum(N * L, 1) <= 0.05)[:, None], N, L)
    exact, near = f32(-L), -L + 1e-3 * np.cross(L, unit_vectors(rng, n))
    near = f32(near / np.linalg.norm(near, axis=1, keepdims=True))
    T = np.cross(N, unit_vectors(rng, n))
    T = f32(T / np.linalg.norm(T, axis=1, keepdims=True))
    B = f32(np.cross(N, T))
    base = {"N": f32(N), "L": L, "T": T, "B": B, "rough": f32(rng.uniform(0.05, 1.0, n)),
            "F0": f32(rng.uniform(0.02, 1.0, (n, 3)))}  # fmt: skip
    body = """
        ShadingContext s = makeShadingContext(vec3(0.0), N, V, vec3(0.5), F0, rough);
        plain = specularTowards(s, L);
        CoatContext c = makeCoatContext(N, V, 1.0, rough, 0.03, vec3(1.0), 1.5, 1.0);
        coatd = vec2(coatSpecularTowards(c, V, L), coatBrdfCosine(c, V, L));
    """
    abody = """
        AnisotropicLobe l = makeAnisotropicLobe(rough * rough, 0.8, vec3(1.0, 0.0, 0.0), T, B, N);
        aniso = anisotropicSpecularTowards(l, N, V, max(dot(N, V), 1e-4), F0, L);
        anisoIbl = anisotropicBrdfCosineIBL(l, N, V, F0, L);
    """
    for V, label in ((exact, "L = -V"), (near, "|L + V| = 1e-3")):
        v = {**base, "V": V}
        out = gpu_eval_many(ctx, body, v, {"plain": "vec3", "coatd": "vec2"},
                            includes=["lights.glsl", "coat.glsl"], defines=("MATERIAL_HAS_COAT",))
        aout = gpu_eval_many(ctx, abody, v, {"aniso": "vec3", "anisoIbl": "vec3"},
                             includes=["lights.glsl"], defines=("MATERIAL_HAS_ANISOTROPY",))
        s = lights.makeShadingContext(np.zeros(3), v["N"], V, np.full(3, 0.5), v["F0"],
                                      v["rough"])
        c = coat.makeCoatContext(v["N"], V, 1.0, v["rough"], 0.03, np.ones(3), 1.5)
        lo = anisotropy.makeAnisotropicLobe(v["rough"] ** 2, 0.8, np.array([1.0, 0, 0]), T, B,
                                            v["N"])
        nov = np.maximum(np.sum(v["N"] * V, 1), 1e-4)
        twins = {
            "plain": lights.specularTowards(s, L),
            "coatd": np.stack([coat.coatSpecularTowards(c, V, L),
                               coat.coatBrdfCosine(c, V, L)], 1),
            "aniso": anisotropy.anisotropicSpecularTowards(lo, v["N"], V, nov, v["F0"], L),
            "anisoIbl": anisotropy.anisotropicBrdfCosineIBL(lo, v["N"], V, v["F0"], L),
        }
        for name, gpu in (("plain", out["plain"]), ("coatd", out["coatd"]),
                          ("aniso", aout["aniso"]), ("anisoIbl", aout["anisoIbl"])):
            assert np.isfinite(gpu).all() and np.isfinite(twins[name]).all(), (label, name)
            if V is exact:
                assert (gpu == 0).all() and (twins[name] == 0).all(), (label, name)
            else:  # D is sharp here: float32 half vectors of nearly opposite unit vectors
                assert np.allclose(gpu, twins[name], rtol=2e-2, atol=1e-3), (label, name)


# --- lights_block.glsl, ibl_inputs.glsl, surface.glsl ------------------------------------


def _all_kinds(rng, count):
    kinds = ["point", "directional", "sphere", "tube"]
    out = []
    for i in range(count):
        out.append(Light(
            kind=kinds[i % 4], position=tuple(rng.uniform(-3, 3, 3)),
            direction=tuple(unit_vectors(rng, 1)[0]), color=tuple(rng.uniform(0, 1, 3)),
            intensity=float(rng.uniform(1, 20)), influence_radius=float(rng.uniform(2, 8)),
            source_radius=float(rng.uniform(0, 0.3)), source_length=float(rng.uniform(0, 1)),
        ))  # fmt: skip
    return out


def test_lights_block_round_trips_through_std140(ctx, rng):
    scene = _all_kinds(rng, 16)
    idx = np.arange(N_ELEMS) % 17
    body = """
        int i = int(idx);
        if (i < lightCount()) {
            Light l = getLight(i);
            a = vec4(l.position, float(l.type)); b = vec4(l.color, l.intensity);
            c = vec4(l.direction, l.influenceRadius);
            d = vec4(l.sourceRadius, l.sourceLength, float(lightCount()), 0.0);
        } else {
            a = vec4(-1.0); b = vec4(-1.0); c = vec4(-1.0); d = vec4(-1.0);
        }
    """
    out = gpu_eval_many(ctx, body, {"idx": idx}, dict.fromkeys("abcd", "vec4"),
                        includes=["lights_block.glsl"],
                        uniform_blocks={"LightsBlock": pack_lights(scene)})  # fmt: skip
    for j in range(17):
        row = idx == j
        if j == 16:
            assert np.all(out["a"][row] == -1.0)
            continue
        l = scene[j]
        want = [
            (*l.position, l.type),
            (*l.color, l.intensity),
            (*l.direction, l.influence_radius),
            (l.source_radius, l.source_length, 16, 0),
        ]
        for key, w in zip("abcd", want):
            np.testing.assert_array_equal(out[key][row], np.broadcast_to(
                np.float32(w), out[key][row].shape))  # fmt: skip


def _lut_texture(ctx, lut):
    tex = ctx.texture((lut.shape[1], lut.shape[0]), 2, lut.astype(np.float32).tobytes(),
                      dtype="f4")  # fmt: skip
    tex.repeat_x = tex.repeat_y = False
    tex.filter = (ctx.LINEAR, ctx.LINEAR)
    return tex


def test_split_sum_lookups(ctx, rng):
    n = N_ELEMS
    mips = f32(rng.uniform(0, 4, (6, 3)))
    cube = _constant_cube(ctx, mips)
    lut = f32(rng.uniform(0, 1, (8, 8, 2)))
    lutex = _lut_texture(ctx, lut)
    R = f32(unit_vectors(rng, n))
    r = unit01(rng, n)
    NoV = unit01(rng, n)
    F0 = f32(rng.uniform(0, 1, (n, 3)))
    try:
        out = gpu_eval_many(
            ctx, "pre = prefilteredRadiance(env, R, r, 6.0); ab = environmentBRDF(lut, NoV, r);"
            "ss = splitSumSpecular(pre, ab, F0);",
            {"R": R, "r": r, "NoV": NoV, "F0": F0}, {"pre": "vec3", "ab": "vec2", "ss": "vec3"},
            includes=["ibl.glsl"], preamble="uniform samplerCube env; uniform sampler2D lut;",
            textures={"env": cube, "lut": lutex},
        )  # fmt: skip
    finally:
        cube.release()
        lutex.release()

    def env(_dirs, lod):
        lo = np.clip(np.floor(lod).astype(int), 0, 5)
        hi = np.minimum(lo + 1, 5)
        t = (lod - lo)[..., None]
        return mips[lo] * (1 - t) + mips[hi] * t

    pre = ibl.prefilteredRadiance(env, R, r, 6.0)
    ab = ibl.environmentBRDF(lut, NoV, r)
    # Texture filtering weights are implementation precision (8 fractional bits on many
    # GPUs and llvmpipe): 1/256 of the span of the texel values.
    check("prefilteredRadiance", out["pre"], pre, rtol=0, atol=4.0 / 256)
    check("environmentBRDF", out["ab"], ab, rtol=0, atol=1.0 / 256)
    # splitSumSpecular against numpy on the GPU's own lookups: pure arithmetic.
    check("splitSumSpecular", out["ss"], ibl.splitSumSpecular(f32(out["pre"]), f32(out["ab"]),
                                                              F0))  # fmt: skip


def test_sh_irradiance(ctx, rng):
    n = N_ELEMS
    sh = f32(rng.uniform(-1, 1, (n, 9, 3)))
    sh[:, 0] += 2.0
    N = f32(unit_vectors(rng, n))
    dc = f32(rng.uniform(0, 1, (n, 3)))
    inputs = {f"c{i}": sh[:, i] for i in range(9)} | {"N": N, "dc": dc}
    body = ("vec3 sh[9] = vec3[9](c0, c1, c2, c3, c4, c5, c6, c7, c8);"
            "e = irradianceSH9(sh, N); d = diffuseIrradianceSH9(sh, N, dc);")  # fmt: skip
    out = gpu_eval_many(ctx, body, inputs, {"e": "vec3", "d": "vec3"}, includes=["ibl.glsl"])
    # Nine signed terms of size ~1 cancel: absolute 1e-5 on results of size ~1.
    check("irradianceSH9", out["e"], ibl.irradianceSH9(sh, N), atol=1e-5)
    check("diffuseIrradianceSH9", out["d"], ibl.diffuseIrradianceSH9(sh, N, dc), atol=1e-5)


def test_reference_ibl_under_constant_environment(ctx, rng):
    n = 1024
    c = np.float32([0.8, 1.0, 1.3])
    cube = _constant_cube(ctx, [c])
    cube.filter = (ctx.LINEAR, ctx.LINEAR)
    N, V = normal_and_view(rng, n)
    r = roughness(rng, n, lo=0.0)
    F0 = f32(rng.uniform(0, 1, (n, 3)))
    dc = f32(rng.uniform(0, 1, (n, 3)))
    off = f32(rng.uniform(0, 1, (n, 2)))
    inputs = {"N": N, "V": V, "r": r, "F0": F0, "dc": dc, "off": off}
    try:
        out = gpu_eval_many(
            ctx, "ref = referenceIBL(env, dc, F0, r, N, V, 64u, off);"
                 "xi = rotatedHammersley(7u, 64u, off);",
            inputs, {"ref": "vec3", "xi": "vec2"}, includes=["ibl.glsl"],
            preamble="uniform samplerCube env;", textures={"env": cube},
        )  # fmt: skip
    finally:
        cube.release()

    def env(d):
        return np.broadcast_to(c, np.shape(d))

    def twin(**v):
        return ibl.referenceIBL(env, v["dc"], v["F0"], v["r"], v["N"], v["V"], 64, v["off"])

    check("rotatedHammersley", out["xi"], ibl.rotatedHammersley(7, 64, off), rtol=0, atol=2e-7)
    # 64 samples each with weight G VoH / (NoH NoV); sharp lobes at grazing NoV make a
    # weight sensitive to float32 rounding of H: perturbation slack (module doc).
    check("referenceIBL", out["ref"], twin(**inputs), rtol=1e-4, atol=1e-5,
          slack=perturbation_spread(twin, inputs, rng))  # fmt: skip


# --- env_sampling.glsl, and the reference with multiple importance sampling ---------------


def _random_distribution(rng, h=16, w=32):
    """A sampling table of a lumpy luminance image: a few bright pixels, black rows."""
    lum = 10.0 ** rng.uniform(-2, 1, (h, w))
    lum[3] = 0.0  # a black row: zero width in the marginal CDF
    lum[5, :7] = 0.0  # zero-width columns
    lum[9, 20] = 5e4  # a "sun"
    return build_distribution(lum).table


def _distribution_texture(ctx, table):
    tex = ctx.texture((table.shape[1], table.shape[0]), 2,
                      np.ascontiguousarray(table, np.float32).tobytes(), dtype="f4")
    tex.filter = (ctx.NEAREST, ctx.NEAREST)
    tex.repeat_x = tex.repeat_y = False
    return tex


def test_environment_sampling(ctx, rng):
    n = N_ELEMS
    table = _random_distribution(rng)
    tex = _distribution_texture(ctx, table)
    u = f32(rng.uniform(0, 1, (n, 2)))
    u[:8] = [[0, 0], [0, 0.99999994], [0.99999994, 0], [0.5, 0.5], [0.25, 0.1], [0.9, 0.7],
             [0.1, 0.999], [0.999, 0.4]]
    L = f32(unit_vectors(rng, n))
    try:
        out = gpu_eval_many(
            ctx, "d = sampleEnvironmentDirection(dist, u, p); back = environmentPdf(dist, d);"
                 "q = environmentPdf(dist, L); e = equirectDirection(u);"
                 "uv = directionToEquirect(L);",
            {"u": u, "L": L}, {"d": "vec3", "p": "float", "back": "float", "q": "float",
                               "e": "vec3", "uv": "vec2"},
            includes=["env_sampling.glsl"], preamble="uniform sampler2D dist;",
            textures={"dist": tex},
        )  # fmt: skip
    finally:
        tex.release()
    d, p = env_sampling.sampleEnvironmentDirection(table, u)
    check("equirectDirection", out["e"], env_sampling.equirectDirection(u), atol=2e-6)
    # atan and acos of float32 inputs: a few ulps of pi
    check("directionToEquirect", out["uv"], env_sampling.directionToEquirect(L), rtol=0,
          atol=2e-6)
    check("sampleEnvironmentDirection", out["d"], d, rtol=0, atol=2e-6)
    # pdf: p(u, v) / sin(theta), float32 sin of a float32 angle; near the poles a float32
    # v (ulp 6e-8) moves sin(theta) by pi ulp(v) / sin(theta) relatively: slack 8 times that
    sin_t = np.sin(np.pi * env_sampling.directionToEquirect(d)[:, 1])
    check("sampleEnvironmentDirection.pdf", out["p"], p, rtol=2e-5, atol=1e-6,
          slack=8.0 * p * np.pi * 6e-8 / np.maximum(sin_t, 1e-7))
    # the pdf of the sample itself, by the other function: the same pixel and Jacobian,
    # except where the sample lies on a pixel edge (u = 0 is the seam u = 1)
    seam = np.abs(out["back"] - p) > 1e-4 * p + 1e-6
    assert seam.mean() < 2e-3, seam.sum()
    check("environmentPdf(sample)", out["back"][~seam], p[~seam], rtol=1e-4, atol=1e-6)
    # directions near a pixel edge may land in the neighbour in float32: allow a few
    q = env_sampling.environmentPdf(table, L)
    mismatched = np.abs(out["q"] - q) > 1e-4 * np.abs(q) + 1e-6
    assert mismatched.mean() < 2e-3, mismatched.sum()
    check("environmentPdf", out["q"][~mismatched], q[~mismatched])


def _reference_surface_inputs(rng, n):
    N, V = normal_and_view(rng, n)
    return {"N": N, "V": V, "dc": f32(rng.uniform(0, 1, (n, 3))),
            "F0": f32(rng.uniform(0, 1, (n, 3))), "r": roughness(rng, n, lo=0.0),
            "ss": f32(rng.uniform(1, 1.5, (n, 3)))}


_SURFACE = "ReferenceSurface s = makeReferenceSurface(N, V, dc, F0, r, ss);"


def test_reference_brdf(ctx, rng):
    n = N_ELEMS
    inputs = _reference_surface_inputs(rng, n)
    inputs["Xi"] = f32(rng.uniform(0, 1, (n, 2)))
    inputs["Lr"] = f32(unit_vectors(rng, n))
    out = gpu_eval_many(
        ctx, _SURFACE + "float ps; Ls = referenceBrdfSample(s, Xi, ps); pdf = ps;"
        "fL = referenceBrdfCosine(s, Lr); pL = referenceBrdfPdf(s, Lr);"
        "c = referenceSpecularChance(s);",
        inputs, {"Ls": "vec3", "pdf": "float", "fL": "vec3", "pL": "float", "c": "float"},
        includes=["ibl.glsl"],
    )  # fmt: skip

    def surf(v):
        return ibl.makeReferenceSurface(v["N"], v["V"], v["dc"], v["F0"], v["r"], v["ss"])

    def cosine(**v):
        return ibl.referenceBrdfCosine(surf(v), v["Lr"])

    def pdf(**v):
        return ibl.referenceBrdfPdf(surf(v), v["Lr"])

    def sample(**v):
        return ibl.referenceBrdfSample(surf(v), v["Xi"])[0]

    check("referenceSpecularChance", out["c"], ibl.referenceSpecularChance(surf(inputs)),
          atol=1e-6)
    # GGX of narrow lobes (alpha down to 1e-3) on half vectors: perturbation slack
    check("referenceBrdfCosine", out["fL"], cosine(**inputs), rtol=1e-4, atol=1e-6,
          slack=perturbation_spread(cosine, inputs, rng))
    check("referenceBrdfPdf", out["pL"], pdf(**inputs), rtol=1e-4, atol=1e-6,
          slack=perturbation_spread(pdf, inputs, rng))
    # the lobe choice Xi.x < c may differ where they are within float32 rounding
    c = ibl.referenceSpecularChance(surf(inputs))
    clear = np.abs(inputs["Xi"][:, 0] - c) > 1e-5
    Ls = sample(**inputs)
    check("referenceBrdfSample", out["Ls"][clear], Ls[clear], rtol=1e-4, atol=1e-5,
          slack=perturbation_spread(sample, inputs, rng)[clear])
    pdf_s = ibl.referenceBrdfPdf(surf(inputs), f32(out["Ls"]))
    assert np.all(np.isfinite(out["pdf"]))
    # the sample's pdf is referenceBrdfPdf of it (evaluated here at the GPU's direction)
    check("referenceBrdfSample.pdf", out["pdf"][clear], pdf_s[clear], rtol=2e-3, atol=1e-5)


def test_reference_environment_ibl(ctx, rng):
    """The MIS estimator under a constant environment with a lumpy distribution: the
    distribution changes where samples go and their weights, not the value's expectation."""
    n = 1024
    c = np.float32([0.8, 1.0, 1.3])
    cube = _constant_cube(ctx, [c])
    cube.filter = (ctx.LINEAR, ctx.LINEAR)
    table = _random_distribution(rng)
    tex = _distribution_texture(ctx, table)
    inputs = _reference_surface_inputs(rng, n)
    inputs["off"] = f32(rng.uniform(0, 1, (n, 2)))
    try:
        out = gpu_eval_many(
            ctx, _SURFACE + "ref = referenceEnvironmentIBL(env, dist, s, 64u, off);",
            inputs, {"ref": "vec3"}, includes=["ibl.glsl"],
            preamble="uniform samplerCube env; uniform sampler2D dist;",
            textures={"env": cube, "dist": tex},
        )  # fmt: skip
    finally:
        cube.release()
        tex.release()

    def env(d):
        return np.broadcast_to(c, np.shape(d))

    def twin(**v):
        s = ibl.makeReferenceSurface(v["N"], v["V"], v["dc"], v["F0"], v["r"], v["ss"])
        return ibl.referenceEnvironmentIBL(env, table, s, 64, v["off"])

    ref = twin(**inputs)
    # 128 weighted samples a pixel. A lobe choice, a CDF comparison or a sample's side of
    # the horizon that float32 rounding flips moves one whole sample; at grazing view
    # (NoV ~ 1e-4) a GGX sample's weight is ~1 / NoV, so one flip there changes the pixel
    # by any amount. Elsewhere: perturbation slack, or one flipped sample's share (1 %).
    check_monte_carlo("referenceEnvironmentIBL", out["ref"], ref,
                      perturbation_spread(twin, inputs, rng), inputs["N"], inputs["V"])


def check_monte_carlo(name, got, ref, spread, N, V):
    """`check` for the MIS estimator, but a few pixels (< 3 %) may differ by one flipped
    sample: anything at grazing view (NoV < 1e-3), else under 1 %."""
    err = np.abs(got - ref)
    flipped = (err > 1e-4 * np.abs(ref) + 1e-5 + spread).any(axis=1)
    assert flipped.mean() < 0.03, flipped.sum()
    grazing = np.sum(N * V, axis=1) < 1e-3
    rel = (err / (np.abs(ref) + 1e-5)).max(axis=1)
    assert np.all(grazing[flipped] | (rel[flipped] < 0.01)), rel[flipped & ~grazing]
    check(name, got[~flipped], ref[~flipped], rtol=1e-4, atol=1e-5, slack=spread[~flipped])


@pytest.mark.parametrize("mode", [ibl.IBL_MODE_SPLIT_SUM, ibl.IBL_MODE_REFERENCE,
                                  ibl.IBL_MODE_NONE])  # fmt: skip
def test_shade_surface(ctx, rng, mode):
    n = 1024
    scene = _all_kinds(rng, 16)
    env_c = np.float32([0.5, 0.7, 1.1])
    pref_c = np.float32([0.9, 0.6, 0.4])
    ab = np.float32([0.7, 0.05])
    sh = f32(rng.uniform(-0.2, 0.2, (9, 3)))
    sh[0] += 1.5
    block = ibl.pack_ibl_block(sh, mip_count=5, intensity=1.7, samples=32, mode=mode,
                               sample_offset=(0.25, 0.6))  # fmt: skip
    env = _constant_cube(ctx, [env_c])
    env.filter = (ctx.LINEAR, ctx.LINEAR)
    table = _random_distribution(rng)
    dist = _distribution_texture(ctx, table)
    pref = _constant_cube(ctx, [pref_c] * 5)
    lut = _lut_texture(ctx, np.broadcast_to(ab, (4, 4, 2)).copy())
    N, V = normal_and_view(rng, n)
    P = f32(rng.uniform(-1, 1, (n, 3)))
    base = f32(rng.uniform(0, 1, (n, 3)))
    metal, rough, cav = unit01(rng, n), roughness(rng, n, lo=0.0), unit01(rng, n)
    emis = f32(rng.uniform(0, 2, (n, 3)))
    inputs = {"P": P, "N": N, "V": V, "base": base, "metal": metal, "rough": rough,
              "cav": cav, "emis": emis}  # fmt: skip
    body = """
        MaterialAttributes m = defaultMaterialAttributes();
        m.baseColor = base; m.metallic = metal; m.roughness = rough; m.cavity = cav;
        m.emissive = emis;
        result = shadeSurface(m, P, N, V);
    """
    try:
        got = gpu_eval_many(
            ctx, body, inputs, {"result": "vec3"}, includes=["surface.glsl"],
            uniform_blocks={"LightsBlock": pack_lights(scene), "IblBlock": block},
            textures={"uPrefilteredEnv": pref, "uBrdfLut": lut, "uEnvironment": env,
                      "uEnvDistribution": dist},
        )["result"]  # fmt: skip
    finally:
        for t in (env, pref, lut, dist):
            t.release()

    ibl_in = surface.IblInputs(
        sh=sh, prefiltered=pref_c, mip_count=5, brdf_lut=ab, lut_values=True,
        environment=lambda d: np.broadcast_to(env_c, np.shape(d)),
        environment_distribution=table, intensity=1.7,
        samples=32, sample_offset=(0.25, 0.6), mode=mode,
    )  # fmt: skip

    def twin(**v):
        m = material.MaterialAttributes(baseColor=v["base"], metallic=v["metal"],
                                        roughness=v["rough"], cavity=v["cav"],
                                        emissive=v["emis"])  # fmt: skip
        return surface.shadeSurface(m, v["P"], v["N"], v["V"], scene, ibl_in)

    packed = [_f32_light(l) for l in scene]
    scene[:] = packed  # numpy sees the float32 values the block holds
    ref = twin(**inputs)
    if mode == ibl.IBL_MODE_REFERENCE:  # Monte Carlo: see check_monte_carlo
        check_monte_carlo(f"shadeSurface[mode {mode}]", got, ref,
                          perturbation_spread(twin, inputs, rng), N, V)
        return
    check(f"shadeSurface[mode {mode}]", got, ref, rtol=1e-4, atol=1e-5,
          slack=perturbation_spread(twin, inputs, rng))  # fmt: skip


def _f32_light(l: Light) -> Light:
    return Light(kind=l.kind, position=tuple(f32(l.position)), direction=tuple(f32(l.direction)),
                 color=tuple(f32(l.color)), intensity=float(f32(l.intensity)),
                 influence_radius=float(f32(l.influence_radius)),
                 source_radius=float(f32(l.source_radius)),
                 source_length=float(f32(l.source_length)))  # fmt: skip


# --- output.glsl ---------------------------------------------------------------------------


def test_output_transform(ctx, rng):
    n = N_ELEMS
    hdr = f32(10.0 ** rng.uniform(-5, 3, (n, 3)))
    hdr[:8] = 0.0
    ev = f32(rng.uniform(-4, 4, n))
    ldr = unit01(rng, 3 * n).reshape(n, 3)
    out = gpu_eval_many(
        ctx, "e = applyExposure(hdr, ev); t = tonemapACES(hdr); s = linearToSRGB(ldr);"
             "d = displayTransform(hdr, ev);",
        {"hdr": hdr, "ev": ev, "ldr": ldr}, dict.fromkeys("etsd", "vec3"),
        includes=["output.glsl"],
    )  # fmt: skip
    check("applyExposure", out["e"], output.applyExposure(hdr, ev))
    check("tonemapACES", out["t"], output.tonemapACES(hdr), atol=1e-7)
    # pow(c, 1/2.4) in float32 is exp2(log2(c) / 2.4): a few ulps near c = 0.0031.
    check("linearToSRGB", out["s"], output.linearToSRGB(ldr), rtol=2e-6 * 50, atol=1e-7)
    check("displayTransform", out["d"], output.displayTransform(hdr, ev), atol=1e-6)


@pytest.mark.parametrize("kind", ["sphere", "tube"])
def test_representative_point_behind_the_surface_gives_zero_not_nan(ctx, kind):
    # V = N and the light straight behind: the representative point lands on L = -V, where
    # the half vector is undefined. Regression: this produced NaN on the GPU.
    n = 64
    N = np.tile(f32([[0.0, 0.0, 1.0]]), (n, 1))
    s = {
        "P": np.zeros((n, 3)), "N": N, "V": N, "pos": np.tile([0.0, 0.0, -0.7], (n, 1)),
        "dir": np.tile([1.0, 0.0, 0.0], (n, 1)), "col": np.ones((n, 3)), "I": np.full(n, 10.0),
        "R": np.full(n, 5.0), "srcR": np.linspace(0.0, 0.3, n), "srcL": np.full(n, 0.0),
        "dc": np.full((n, 3), 0.5), "F0": np.full((n, 3), 0.04), "rough": np.linspace(0, 1, n),
    }  # fmt: skip
    out = gpu_eval(
        ctx,
        f"{kind}Light(makeShadingContext(P, N, V, dc, F0, rough),"
        f" makeLight({lights.LIGHT_TYPES[kind]}, pos, dir, col, I, R, srcR, srcL))",
        s, "vec3", includes=["lights.glsl"], preamble=_MAKE_LIGHT,
    )  # fmt: skip
    c = lights.makeShadingContext(s["P"], N, N, s["dc"], s["F0"], s["rough"])
    np.testing.assert_array_equal(out, 0.0)
    np.testing.assert_array_equal(lights.evaluateLight(c, _np_light(kind, s)), 0.0)
