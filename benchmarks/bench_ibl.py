"""Benchmark the IBL bake against Filament's cmgen on the same input (not a test).

    .venv/bin/python benchmarks/bench_ibl.py [--size 256] [--samples 256] [--lut 128]

Both tools bake the built-in studio environment, written as a 2048 x 1024 EXR, to a
`size`^2 prefiltered cube with mips and a `lut`^2 DFG / environment BRDF LUT. Printed:
wall times and their ratio, and each tool's error against brute force: the prefiltered
texels (a sample of texels at every level, against a direct GGX-weighted sum over the
equirect source at the level's roughness) and the LUT (at a 32 x 32 subset of texel
centres, against a midpoint integration of each tool's own visibility term: Schlick-Smith
k = a/2 for matedit, height-correlated Smith for Filament). cmgen is Debian's
libfilament-tools; without it only matedit's side runs.
"""

from __future__ import annotations

import argparse
import glob
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from matedit.ibl import BakeSettings, load_environment
from matedit.ibl.bake import PREFILTER_GROWTH
from matedit.ibl.builtin import studio
from matedit.ibl.cubemap import FACE_NAMES, equirect_directions, face_directions, faces_to_cross
from matedit.ibl.gpu import Baker
from matedit.ibl.sh import sh_irradiance
from matedit.io.images import read_image, write_image
from matedit.render.context import headless_context

# -- brute force ------------------------------------------------------------------------------


class EquirectSource:
    """The environment as weighted point samples: every pixel of a (downsampled) equirect."""

    def __init__(self, image: np.ndarray, factor: int = 2) -> None:
        h, w = image.shape[:2]
        img = image.reshape(h // factor, factor, w // factor, factor, 3).mean(axis=(1, 3))
        h, w = img.shape[:2]
        self.dirs = equirect_directions(h, w).reshape(-1, 3)
        theta = np.pi * (np.arange(h) + 0.5) / h
        omega = (2 * np.pi / w) * (np.pi / h) * np.sin(theta)[:, None] * np.ones(w)
        self.omega = omega.reshape(-1)
        self.radiance = img.reshape(-1, 3).astype(np.float64)

    def prefiltered(self, r: np.ndarray, roughness: float) -> np.ndarray:
        """sum L D(H) NoL dOmega / sum D(H) NoL dOmega with N = V = r
        (docs/shading.md#image-based-lighting)."""
        nol = self.dirs @ r
        keep = nol > 0
        h = self.dirs[keep] + r
        noh = (h @ r) / np.linalg.norm(h, axis=1)
        a2 = roughness**4
        d = a2 / (np.pi * (noh * noh * (a2 - 1) + 1) ** 2)
        w = d * nol[keep] * self.omega[keep]
        return (self.radiance[keep] * w[:, None]).sum(axis=0) / w.sum()


def brute_lut(novs, roughnesses, model: str, n_theta: int = 512, n_phi: int = 128) -> np.ndarray:
    """(A, B) by a midpoint rule over half vectors (log-spaced theta), for a G model."""
    out = np.zeros((len(roughnesses), len(novs), 2))
    nov = np.asarray(novs)[:, None, None]
    sin_v = np.sqrt(1 - nov * nov)
    phi = (np.arange(n_phi) + 0.5) * np.pi / n_phi
    cos_phi = np.cos(phi)[None, None, :]
    for k, rough in enumerate(roughnesses):
        a = max(rough * rough, 1e-4)
        a2 = a * a
        x0, x1 = np.log(a * 1e-3), np.log(np.pi / 2)
        x = x0 + (np.arange(n_theta) + 0.5) * (x1 - x0) / n_theta
        th = np.exp(x)
        dth = th * (x1 - x0) / n_theta
        ch, sh = np.cos(th)[None, :, None], np.sin(th)[None, :, None]
        voh = sin_v * sh * cos_phi + nov * ch
        nol = 2 * voh * ch - nov
        nl = np.maximum(nol, 0)
        if model == "schlick":
            kk = a / 2
            g = nl / (nl * (1 - kk) + kk) * nov / (nov * (1 - kk) + kk)
        else:  # height-correlated Smith: G = 4 NoL NoV V
            lam_v = nl * np.sqrt(nov * nov * (1 - a2) + a2)
            lam_l = nov * np.sqrt(nl * nl * (1 - a2) + a2)
            g = 4 * nl * nov * 0.5 / np.maximum(lam_v + lam_l, 1e-30)
        d = a2 / (np.pi * (ch * ch * (a2 - 1) + 1) ** 2)
        f = np.where(nol > 0, g * voh * d / nov * sh * dth[None, :, None] * 2 * np.pi / n_phi, 0)
        fc = (1 - voh) ** 5
        out[k, :, 0] = ((1 - fc) * f).sum(axis=(1, 2))
        out[k, :, 1] = (fc * f).sum(axis=(1, 2))
    return out


def prefilter_errors(levels, source: EquirectSource, per_level: int = 48, seed: int = 2):
    """[(roughness, mean rel. error, max rel. error)] for levels [(roughness, dirs, values)]."""
    rng = np.random.default_rng(seed)
    rows = []
    for roughness, dirs, values in levels:
        if roughness <= 0:
            continue
        idx = rng.choice(len(dirs), size=min(per_level, len(dirs)), replace=False)
        ref = np.array([source.prefiltered(dirs[i], roughness) for i in idx])
        rel = np.abs(values[idx] - ref) / np.maximum(ref, 1e-6)
        rows.append((roughness, float(rel.mean()), float(rel.max())))
    return rows


# -- the two tools ------------------------------------------------------------------------------


def run_matedit(path: Path, out: Path, size: int, samples: int, lut_size: int) -> dict:
    t0 = time.perf_counter()
    settings = BakeSettings(size=size, samples=samples, lut_size=lut_size).resolved()
    env = load_environment(path)
    ctx = headless_context()  # inside the timing: the bake's cost includes its context
    with Baker(ctx) as baker:
        cube = baker.equirect_to_cube(env.equirect, size)
        mips = baker.prefilter(
            cube, settings.levels, samples, settings.lod_bias, growth=PREFILTER_GROWTH[0],
            max_growth=PREFILTER_GROWTH[1], grow_after=PREFILTER_GROWTH[2],
        )
        t_prefilter = time.perf_counter()
        sh_irradiance(cube)
        for m, mip in enumerate(mips):
            write_image(out / f"prefiltered_mip{m}.exr", faces_to_cross(mip), half=True)
        t1 = time.perf_counter()
        lut = baker.brdf_lut(lut_size, settings.lut_samples)
        write_image(out / "brdf_lut.exr", lut)
        t2 = time.perf_counter()
    levels = [
        (m / (len(mips) - 1), face_directions(mip.shape[1]).reshape(-1, 3), mip.reshape(-1, 3))
        for m, mip in enumerate(mips)
    ]
    ctx.release()
    return {
        "prefilter_s": t1 - t0,
        "prefilter_only_s": t_prefilter - t0,
        "lut_s": t2 - t1,
        "levels": levels,
        "lut": lut,
    }


def _dihedral(a: np.ndarray):
    for t in (False, True):
        b = a.transpose(1, 0, 2) if t else a
        for fy in (1, -1):
            for fx in (1, -1):
                yield (t, fy, fx), b[::fy, ::fx]


def cmgen_face_map(cmgen: str, tmp: Path) -> dict[str, tuple[int, tuple]]:
    """Which of our faces, and which flip, each cmgen face file holds (found by baking dirs)."""
    probe = tmp / "dirs.exr"
    write_image(probe, (equirect_directions(256, 512) + 2.0).astype(np.float32))
    subprocess.run(
        [cmgen, "--quiet", "--format=exr", "--size=16", f"--extract={tmp / 'ext'}", str(probe)],
        check=True,
    )
    ours = face_directions(16)
    mapping = {}
    for name in FACE_NAMES:
        img = read_image(glob.glob(str(tmp / "ext" / "*" / f"{name}.exr"))[0]).pixels[..., :3]
        img = (img - 2.0) / np.linalg.norm(img - 2.0, axis=-1, keepdims=True)
        best = min(
            (float(np.abs(cand - img).max()), f, tr)
            for f in range(6)
            for tr, cand in _dihedral(ours[f])
        )
        mapping[name] = (best[1], best[2])
    return mapping


def run_cmgen(cmgen: str, path: Path, tmp: Path, size: int, lut_size: int) -> dict:
    out = tmp / "cmgen"
    t0 = time.perf_counter()
    subprocess.run(
        [cmgen, "--quiet", "--format=exr", f"--size={size}", f"--ibl-ld={out}", str(path)],
        check=True,
    )
    t1 = time.perf_counter()
    subprocess.run(
        [cmgen, "--quiet", f"--size={lut_size}", f"--ibl-dfg={tmp / 'dfg.exr'}"], check=True
    )
    t2 = time.perf_counter()
    mapping = cmgen_face_map(cmgen, tmp)
    files = sorted(glob.glob(str(out / "*" / "m*_px.exr")))
    count = len(files)
    levels = []
    for m in range(count):
        dirs, values = [], []
        for name in FACE_NAMES:
            img = read_image(glob.glob(str(out / "*" / f"m{m}_{name}.exr"))[0]).pixels[..., :3]
            face, (t, fy, fx) = mapping[name]
            d = face_directions(img.shape[0])[face]
            d = d.transpose(1, 0, 2) if t else d
            dirs.append(d[::fy, ::fx].reshape(-1, 3))
            values.append(img.reshape(-1, 3))
        # Filament: level m is for perceptual roughness lodToPerceptualRoughness(m / (M - 1)).
        lod = m / (count - 1)
        rough = 1 - np.sqrt(1 - lod) if lod > 0 else 0.0
        levels.append((float(rough), np.concatenate(dirs), np.concatenate(values)))
    return {
        "prefilter_s": t1 - t0,
        "lut_s": t2 - t1,
        "levels": levels,
        "lut": read_image(tmp / "dfg.exr").pixels,
    }


def lut_error(lut: np.ndarray, model: str) -> tuple[float, str]:
    """Max |error| at a 32 x 32 subset of texel centres; tries the plausible layouts."""
    n = lut.shape[0]
    idx = np.arange(max(1, n // 64), n, max(1, n // 32))[:32]  # row 0 of cmgen's is not used
    centres = (idx + 0.5) / n
    ref = brute_lut(centres, centres, model)
    # cmgen (Filament's CubemapIBL::DFG) gives its row y, top first, the perceptual roughness
    # saturate((N - y + 0.5) / N): the roughness (j + 0.5) / N is row N - j, one row off a
    # plain flip (lut[::-1] reads row N - 1 - j, roughness (j + 1.5) / N)
    down = np.roll(lut[::-1], 1, axis=0)  # down[j] = lut[N - j] (j >= 1)
    candidates = {
        "rows=roughness up, R=A G=B": lut,
        "rows=roughness down, row y at (N-y+0.5)/N (cmgen), R=A G=B": down,
    }
    best = None
    for name, cand in candidates.items():
        got = cand[np.ix_(idx, idx)][..., :2]
        err = float(np.abs(got - ref).max())
        if best is None or err < best[0]:
            best = (err, name)
    return best


def compare(size: int = 256, samples: int = 256, lut: int = 128, repeat: int = 1) -> dict:
    """Both tools on the same input; times are medians over `repeat` runs (errors from the
    last run). Returns {"matedit": {...}, "cmgen": {...} or absent, "errors": {...}}."""
    import statistics

    with tempfile.TemporaryDirectory() as tmpname:
        tmp = Path(tmpname)
        image = studio(2048)
        path = tmp / "studio_2048x1024.exr"
        write_image(path, image)
        source = EquirectSource(image)
        ours_out = tmp / "matedit"
        ours_out.mkdir()
        runs = [run_matedit(path, ours_out, size, samples, lut) for _ in range(repeat)]
        results = {"matedit": runs[-1]}
        cmgen = shutil.which("cmgen")
        if cmgen:
            cruns = [run_cmgen(cmgen, path, tmp, size, lut) for _ in range(repeat)]
            results["cmgen"] = cruns[-1]
            runs_by = {"matedit": runs, "cmgen": cruns}
        else:
            runs_by = {"matedit": runs}
        for name, rs in runs_by.items():
            for key in ("prefilter_s", "lut_s"):
                results[name][key] = statistics.median(r[key] for r in rs)
                results[name][key + "_all"] = [r[key] for r in rs]
        for name, r in list(results.items()):
            r["prefilter_errors"] = prefilter_errors(r["levels"], source)
            r["lut_error"] = lut_error(r["lut"], "schlick" if name == "matedit" else "correlated")
    return results


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--samples", type=int, default=256)
    parser.add_argument("--lut", type=int, default=128)
    parser.add_argument("--repeat", type=int, default=1, help="runs per tool (median time)")
    args = parser.parse_args(argv)
    print(f"input: studio, 2048x1024 EXR; cube {args.size}^2 with mips; LUT {args.lut}^2")
    results = compare(args.size, args.samples, args.lut, args.repeat)
    ours = results["matedit"]
    if "cmgen" not in results:
        print("cmgen not found (apt-get install libfilament-tools): skipping Filament's side")
    print()
    print(f"{'tool':8} {'prefilter s':>12} {'LUT s':>8}  levels (roughness)")
    for name, r in results.items():
        rough = ", ".join(f"{lv[0]:.3f}" for lv in r["levels"])
        print(f"{name:8} {r['prefilter_s']:12.2f} {r['lut_s']:8.2f}  {rough}")
    if "cmgen" in results:
        c = results["cmgen"]
        ratio_prefilter = c["prefilter_s"] / ours["prefilter_s"]
        ratio_lut = c["lut_s"] / ours["lut_s"]
        print(f"time ratio cmgen / matedit: prefilter {ratio_prefilter:.2f}, LUT {ratio_lut:.2f}")
    print("\nprefiltered texels vs brute force (relative error: mean / max over 48 texels)")
    for name, r in results.items():
        for rough, mean, worst in r["prefilter_errors"]:
            print(f"  {name:8} roughness {rough:.3f}: {mean:.4f} / {worst:.4f}")
    print("\nLUT vs brute force of each tool's own G (max |error| at 32x32 texel centres)")
    err, layout = ours["lut_error"]
    print(f"  matedit (Schlick-Smith k=a/2): {err:.2e}  [{layout}]")
    if "cmgen" in results:
        err, layout = results["cmgen"]["lut_error"]
        print(f"  cmgen (height-correlated Smith): {err:.2e}  [{layout}]")
    return 0

if __name__ == "__main__":
    sys.exit(main())
