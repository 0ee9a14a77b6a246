"""Reference mode under a sun and sky: per-pixel error of BRDF-only sampling (the estimator
before environment importance sampling, still in ibl.glsl as referenceIBL) and of the MIS
estimator (referenceEnvironmentIBL), against an independent brute-force quadrature.

    .venv/bin/python benchmarks/bench_env_sampling.py [--samples 2048] [--grid 24]

The "pixels" are those of a sphere seen orthographically along -Z (N over the visible
hemisphere, V = +Z); the samples are accumulated as the renderer does: frames of 32, each
rotated by the R2 offset of its index. The environment: tests/env_reference.sun_sky (a
0.5-degree sun 3e4 times the horizon sky) resampled to a 128^2 cube by the IBL baker, read
with NEAREST filtering so that the quadrature (tests/env_reference.CubeQuadrature) is of
exactly what the GPU reads. Also prints the sampling table's build time.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT))

from env_reference import CubeQuadrature, sun_sky  # noqa: E402
from gpu_eval import gpu_eval_many  # noqa: E402

from matedit.ibl.gpu import Baker  # noqa: E402
from matedit.ibl.importance import distribution_from_cube  # noqa: E402
from matedit.render.context import headless_context  # noqa: E402
from matedit.render.environment import upload_distribution  # noqa: E402
from matedit.render.frames import r2_offset  # noqa: E402

BODY = """
    ReferenceSurface s = makeReferenceSurface(N, V, dc, F0, r, vec3(1.0));
    neu = referenceEnvironmentIBL(env, dist, s, COUNTu, off);
    old = referenceIBL(env, dc, F0, r, N, V, COUNTu, off);
"""


def sphere_pixels(grid: int):
    c = (np.arange(grid) + 0.5) / grid * 2 - 1
    x, y = np.meshgrid(c, -c)
    inside = x * x + y * y < 0.98
    N = np.stack([x[inside], y[inside], np.sqrt(1 - x[inside] ** 2 - y[inside] ** 2)], -1)
    return N


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--samples", type=int, default=2048)
    ap.add_argument("--grid", type=int, default=24)
    ap.add_argument("--size", type=int, default=128)
    args = ap.parse_args()
    ctx = headless_context()
    img = sun_sky()
    baker = Baker(ctx)
    faces = baker.equirect_to_cube(img, args.size).astype(np.float32)
    baker.close()
    t = time.perf_counter()
    distribution_from_cube(faces)
    print(f"table build for a {args.size}^2 cube: {1e3 * (time.perf_counter() - t):.1f} ms")
    baker = Baker(ctx)
    faces_256 = baker.equirect_to_cube(img, 256).astype(np.float32)
    baker.close()
    t = time.perf_counter()
    big = distribution_from_cube(faces_256)
    print(f"table build for a 256^2 cube: {1e3 * (time.perf_counter() - t):.1f} ms "
          f"({big.table.shape[1] - 1} x {big.table.shape[0]})")

    cube = ctx.texture_cube((args.size, args.size), 3, dtype="f4")
    for f in range(6):
        cube.write(f, np.ascontiguousarray(faces[f]).tobytes())
    cube.filter = (ctx.NEAREST, ctx.NEAREST)
    dist = upload_distribution(ctx, faces)
    quad = CubeQuadrature(faces)
    materials = {"gold r0.3": ([0.0] * 3, [1.0, 0.78, 0.34], 0.3),
                 "plastic r0.6": ([0.5, 0.1, 0.1], [0.04] * 3, 0.6),
                 "chrome r0.05": ([0.0] * 3, [0.95, 0.95, 0.95], 0.05)}
    N = sphere_pixels(args.grid)
    V = np.tile([0.0, 0.0, 1.0], (len(N), 1))
    per_frame = min(32, args.samples)
    frames = max(1, args.samples // per_frame)
    for name, (dc, F0, r) in materials.items():
        t = time.perf_counter()
        truth = np.array([quad.integrate(n, v, np.array(dc), np.array(F0), r)
                          for n, v in zip(N, V)])
        tq = time.perf_counter() - t
        inputs = {"N": N.astype(np.float32), "V": V.astype(np.float32),
                  "dc": np.tile(dc, (len(N), 1)), "F0": np.tile(F0, (len(N), 1)),
                  "r": np.full(len(N), r)}
        acc = {"neu": 0.0, "old": 0.0}
        t = time.perf_counter()
        body = BODY.replace("COUNT", str(per_frame))
        for fr in range(frames):
            inputs["off"] = np.tile(r2_offset(fr), (len(N), 1))
            out = gpu_eval_many(ctx, body, inputs, {"neu": "vec3", "old": "vec3"},
                                includes=["ibl.glsl"],
                                preamble="uniform samplerCube env; uniform sampler2D dist;",
                                textures={"env": cube, "dist": dist})
            for k in acc:
                acc[k] = acc[k] + out[k].astype(np.float64)
        tg = time.perf_counter() - t
        lum = np.array([0.2126, 0.7152, 0.0722])
        print(f"\n{name}: {len(N)} pixels, {frames} x {per_frame} samples "
              f"(GPU {tg:.1f} s, quadrature {tq:.1f} s)")
        for k, label in (("old", "BRDF sampling only (before)"), ("neu", "MIS (after)")):
            est = acc[k] / frames
            rel = np.abs(est - truth) @ lum / (truth @ lum)
            print(f"  {label:28s} relative error: max {rel.max():.4f}  p95 "
                  f"{np.percentile(rel, 95):.4f}  median {np.median(rel):.4f}")
    cube.release()
    dist.release()


if __name__ == "__main__":
    main()
