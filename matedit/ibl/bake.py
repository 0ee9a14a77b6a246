"""Bake an environment for the split-sum shading, with a disk cache.

`bake()` turns an environment into an `IBLBake`: the GGX-prefiltered cube mips, the
environment BRDF LUT and the SH irradiance, all numpy arrays. A second bake of the same
pixels with the same settings reads the cache and does no GPU work.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Callable
from dataclasses import asdict, dataclass, field, replace
from pathlib import Path

import numpy as np

from matedit.ibl import cache, gpu
from matedit.ibl.environment import DEFAULT_ENVIRONMENT, Environment, load_environment
from matedit.ibl.sh import sh_irradiance

Progress = Callable[[float, str], None]

# Mips after the third number get the first times more samples per mip than the one
# before, up to the second times `samples` (gpu.Baker.prefilter). With the source-mip
# selection (filtered importance sampling) the error depends on the sample count more than
# on the lobe's width, and mip 1 holds 3/4 of the texels of the mips that are sampled, so
# mip 2 takes no more samples than mip 1: on the studio of benchmarks/bench_ibl.py, mean
# relative error 4.2 % at roughness 1/6, 2.2 % at 1/3, 0.5-1.1 % beyond, for 17 % less
# time than (2, 4, 1) (4.2 %, 0.9 %, 0.5-0.8 %).
PREFILTER_GROWTH = (2, 4, 2)
# Channels of the environment BRDF LUT: A, B and the Charlie sheen's albedo (brdf_lut.frag);
# in the cache keys, so entries of the two-channel LUT are never read as this one.
LUT_CHANNELS = 3


@dataclass(frozen=True)
class BakeSettings:
    """What a bake computes; every field is part of the cache key.

    size: face size of mip 0 (a power of two, 8 to 4096). levels: number of prefiltered
    mips, mip m for roughness m / (levels - 1); None means down to 4 x 4 faces
    (log2(size) - 1). samples: GGX samples per texel of prefiltered mips 1 and 2; each
    rougher mip takes 2 times more, up to 4 times (`PREFILTER_GROWTH`). lod_bias: offset of
    each sample's source mip (filtered importance sampling; positive blurs more, negative
    less: `gpu.DEFAULT_LOD_BIAS`). lut_size, lut_samples:
    the environment BRDF LUT (see matedit/ibl/lut.py).
    """

    size: int = 256
    samples: int = 256
    levels: int | None = None
    lod_bias: float = gpu.DEFAULT_LOD_BIAS
    lut_size: int = 128
    lut_samples: int = 1024

    def resolved(self) -> BakeSettings:
        """Check the values; fill in `levels`. Raises ValueError on nonsense."""
        if self.size < 8 or self.size > 4096 or self.size & (self.size - 1):
            raise ValueError(f"cube size must be a power of two from 8 to 4096, not {self.size}")
        if not 1 <= self.samples <= 65536:
            raise ValueError(f"samples must be 1 to 65536, not {self.samples}")
        if not 2 <= self.lut_size <= 4096:
            raise ValueError(f"LUT size must be 2 to 4096, not {self.lut_size}")
        if not 64 <= self.lut_samples <= 65536:
            raise ValueError(f"LUT samples must be 64 to 65536, not {self.lut_samples}")
        max_levels = int(math.log2(self.size)) + 1
        levels = self.levels if self.levels is not None else max(2, max_levels - 2)
        if not 1 <= levels <= max_levels:
            raise ValueError(f"levels must be 1 to {max_levels} for size {self.size}, not {levels}")
        return replace(self, levels=levels)


@dataclass
class IBLBake:
    """A baked environment, ready to upload (`matedit.ibl.textures.upload`) or write out.

    mips[m]: (6, size >> m, size >> m, 3) float32 cube faces in OpenGL face order
        (+X -X +Y -Y +Z -Z, rows as `TextureCube.write` takes them), prefiltered for
        roughness m / (len(mips) - 1); mips[0] is the environment itself.
    lut: (N, N, 3) float32, lut[k, i] = (A, B, E_sheen) at roughness (k + 0.5) / N and
        NoV (i + 0.5) / N; upload as is and sample with texture(lut, vec2(NoV, roughness)).
    sh: (9, 3) irradiance coefficients: E(N) = sum_i sh[i] * Y_i(N) (matedit.ibl.sh).
    """

    mips: list[np.ndarray]
    lut: np.ndarray
    sh: np.ndarray
    settings: BakeSettings
    key: str = ""
    from_cache: bool = False
    warnings: list[str] = field(default_factory=list)

    @property
    def levels(self) -> int:
        return len(self.mips)

    def roughness(self, level: int) -> float:
        return level / (self.levels - 1) if self.levels > 1 else 0.0


def _cache_dir(cache_dir: str | os.PathLike | None) -> Path:
    return Path(cache_dir) if cache_dir is not None else cache.ibl_cache_dir()


def bake_brdf_lut(
    size: int = 128,
    samples: int = 1024,
    *,
    baker: gpu.Baker | None = None,
    ctx=None,
    use_cache: bool = True,
    cache_dir: str | os.PathLike | None = None,
    problems: list[str] | None = None,
) -> np.ndarray:
    """The environment BRDF LUT (size, size, 3), from the cache when possible; a miss is
    computed with `baker`, or in the moderngl context `ctx`. A damaged cache entry is
    discarded and computed again, and why is appended to `problems`."""
    BakeSettings(lut_size=size, lut_samples=samples).resolved()  # validates
    key = cache.make_key("brdf-lut", size=size, samples=samples, method="quadrature",
                         channels=LUT_CHANNELS)
    path = _cache_dir(cache_dir) / f"lut-{key}.npz"
    if use_cache:
        hit = cache.load(path, {"lut": cache.Spec((size, size, LUT_CHANNELS), "<f4")}, problems)
        if hit is not None:
            return hit["lut"]
    own = baker is None
    b = baker if baker is not None else gpu.Baker(ctx)
    try:
        lut = b.brdf_lut(size, samples)
    finally:
        if own:
            b.close()
    if use_cache:
        try:
            cache.save(path, {"lut": np.asarray(lut, dtype=np.float32)})
        except OSError:
            pass  # a read-only cache only costs time
    return lut


def _pack(result: IBLBake) -> dict[str, np.ndarray]:
    arrays = {f"mip{m}": np.asarray(mip, dtype=np.float32) for m, mip in enumerate(result.mips)}
    arrays["lut"] = np.asarray(result.lut, dtype=np.float32)
    arrays["sh"] = np.asarray(result.sh, dtype=np.float64)
    arrays["settings"] = np.array(json.dumps(asdict(result.settings), sort_keys=True))
    return arrays


def _schema(settings: BakeSettings) -> dict[str, cache.Spec]:
    """What a cached bake of `settings` holds (the arrays `_pack` writes)."""
    out = {f"mip{m}": cache.Spec((6, settings.size >> m, settings.size >> m, 3), "<f4")
           for m in range(settings.levels)}
    out["lut"] = cache.Spec((settings.lut_size, settings.lut_size, LUT_CHANNELS), "<f4")
    out["sh"] = cache.Spec((9, 3), "<f8")
    out["settings"] = cache.Spec((), "U")
    return out


def _unpack(arrays: dict[str, np.ndarray], settings: BakeSettings, key: str) -> IBLBake | None:
    """The bake in a cache entry that `cache.load` checked against `_schema(settings)`;
    None when it was baked with other settings."""
    if str(arrays["settings"]) != json.dumps(asdict(settings), sort_keys=True):
        return None
    mips = [arrays[f"mip{m}"] for m in range(settings.levels)]
    return IBLBake(mips=mips, lut=arrays["lut"], sh=arrays["sh"], settings=settings, key=key,
                   from_cache=True)


def cache_paths(env: Environment, settings: BakeSettings,
                cache_dir: str | os.PathLike | None = None) -> dict[str, Path]:
    """The cache files a bake of `env` with `settings` reads and writes: "ibl", "lut"."""
    settings = settings.resolved()
    folder = _cache_dir(cache_dir)
    key = cache.make_key(
        "ibl", env=env.content_hash(), settings=asdict(settings), growth=PREFILTER_GROWTH,
        lut_channels=LUT_CHANNELS, prefilter=gpu.PREFILTER_SCHEME,
    )
    lut = cache.make_key("brdf-lut", size=settings.lut_size, samples=settings.lut_samples,
                         method="quadrature", channels=LUT_CHANNELS)
    return {"ibl": folder / f"ibl-{key}.npz", "lut": folder / f"lut-{lut}.npz"}


def bake(
    env: Environment | str | os.PathLike = DEFAULT_ENVIRONMENT,
    settings: BakeSettings | None = None,
    *,
    ctx=None,
    use_cache: bool = True,
    cache_dir: str | os.PathLike | None = None,
    progress: Progress | None = None,
) -> IBLBake:
    """Bake `env` (an Environment, a file path or a built-in name) on the GPU, or load it.

    ctx: the moderngl context to bake in (needed unless the bake is cached); it gets its
    framebuffer binding and viewport back, but is left with BLEND, DEPTH_TEST and CULL_FACE
    disabled and seamless cube filtering enabled.
    progress(fraction, message) is called as work proceeds. Raises EnvironmentMapError
    for unusable files and ValueError for bad settings.
    """
    settings = (settings or BakeSettings()).resolved()
    if not isinstance(env, Environment):
        env = load_environment(env, settings.size)
    folder = _cache_dir(cache_dir)
    path = cache_paths(env, settings, folder)["ibl"]
    key = path.stem.removeprefix("ibl-")
    problems: list[str] = []  # damaged cache entries, discarded and baked again
    if use_cache:
        hit = cache.load(path, _schema(settings), problems)
        result = _unpack(hit, settings, key) if hit is not None else None
        if result is not None:
            result.warnings = list(env.warnings)
            if progress:
                progress(1.0, "loaded from cache")
            return result

    def report(lo: float, hi: float) -> Progress | None:
        if progress is None:
            return None
        return lambda f, msg: progress(lo + (hi - lo) * f, msg)

    baker = gpu.Baker(ctx)
    try:
        if progress:
            progress(0.0, "environment to cube")
        if env.equirect is not None:
            cube = baker.equirect_to_cube(env.equirect, settings.size)
        else:
            cube = baker.resample_cube(env.faces, settings.size)
        mips = baker.prefilter(
            cube,
            settings.levels,
            settings.samples,
            settings.lod_bias,
            report(0.05, 0.95),
            growth=PREFILTER_GROWTH[0],
            max_growth=PREFILTER_GROWTH[1],
            grow_after=PREFILTER_GROWTH[2],
        )
        if progress:
            progress(0.95, "BRDF LUT")
        lut = bake_brdf_lut(
            settings.lut_size,
            settings.lut_samples,
            baker=baker,
            use_cache=use_cache,
            cache_dir=folder,
            problems=problems,
        )
    finally:
        baker.close()
    sh = sh_irradiance(cube)
    result = IBLBake(
        mips=mips, lut=lut, sh=sh, settings=settings, key=key,
        warnings=list(env.warnings) + problems,
    )
    if use_cache:
        try:
            cache.save(path, _pack(result))
        except OSError as exc:
            result.warnings.append(f"{folder}: cannot write the IBL cache: {exc.strerror or exc}")
    if progress:
        progress(1.0, "done")
    return result
