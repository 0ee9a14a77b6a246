"""Write a bake to files (the `matedit bake-ibl` layout) and the LUT (`matedit brdf-lut`).

DIR/prefiltered_mip{m}.exr   mip m (m = 0 .. M-1, roughness m / (M-1)), float32 RGB,
                             a horizontal cube cross 4s x 3s (s = size >> m):
                                     [+Y]
                                [-X] [+Z] [+X] [-Z]
                                     [-Y]
                             faces as OpenGL stores them, row 0 of each at the top, so
                             every edge of the cross is continuous (matedit/ibl/cubemap.py)
DIR/brdf_lut.exr             the environment BRDF LUT (layout below)
DIR/sh.json                  nine irradiance SH coefficients (matedit/ibl/sh.py)
DIR/ibl.json                 what the files are: sizes, roughness per mip, settings

LUT EXR (docs/shading.md#file-conventions): N x N, channels R = A, G = B and B = the
Charlie sheen's directional albedo E (brdf_lut.frag); row k (row 0 the first
OpenImageIO reads) holds roughness (k + 0.5) / N, column i holds NoV = (i + 0.5) / N.
"""

from __future__ import annotations

import json
import os
from dataclasses import asdict
from pathlib import Path

import numpy as np

from matedit.ibl.bake import IBLBake
from matedit.ibl.cubemap import faces_to_cross
from matedit.io.atomic import atomic_write_text, staged_outputs
from matedit.io.images import write_image

SH_BASIS_NAMES = (
    "Y00",
    "Y1-1 y",
    "Y10 z",
    "Y11 x",
    "Y2-2 xy",
    "Y2-1 yz",
    "Y20 3z^2-1",
    "Y21 xz",
    "Y22 x^2-y^2",
)


def write_lut(path: str | os.PathLike, lut: np.ndarray) -> Path:
    """Write a (N, N, 3) LUT as a float32 EXR: R = A, G = B, B = the sheen's albedo E."""
    path = Path(path)
    write_image(path, np.asarray(lut, dtype=np.float32)[..., :3])
    return path


def _write_json(path: Path, data: dict) -> None:
    atomic_write_text(path, json.dumps(data, indent=2, sort_keys=True) + "\n")


def write_bake(result: IBLBake, folder: str | os.PathLike) -> list[Path]:
    """Write every file of the layout above into `folder` (created), together or not at all
    (`staged_outputs`, the manifest moved into place last); returns the paths."""
    folder = Path(folder)
    with staged_outputs(folder) as stage:
        _write_bake(result, folder, stage.path)
    return stage.written


def _write_bake(result: IBLBake, folder: Path, to) -> None:
    for m, mip in enumerate(result.mips):
        write_image(to(folder / f"prefiltered_mip{m}.exr"), faces_to_cross(mip))
    write_lut(to(folder / "brdf_lut.exr"), result.lut)
    _write_json(
        to(folder / "sh.json"),
        {
            "format": "matedit.sh-irradiance",
            "version": 1,
            "basis": list(SH_BASIS_NAMES),
            "coordinates": "world, +Y up",
            "use": "E(N) = sum_i coefficients[i] * Y_i(N); diffuse = diffuseColor * E(N) / pi",
            "coefficients": [[float(v) for v in row] for row in np.asarray(result.sh)],
        },
    )
    _write_json(
        to(folder / "ibl.json"),
        {
            "format": "matedit.ibl",
            "version": 1,
            "layout": "horizontal cross: row 0 [_, +Y, _, _], row 1 [-X, +Z, +X, -Z], "
            "row 2 [_, -Y, _, _]",
            "mips": [
                {
                    "file": f"prefiltered_mip{m}.exr",
                    "face_size": int(mip.shape[1]),
                    "roughness": result.roughness(m),
                }
                for m, mip in enumerate(result.mips)
            ],
            "brdf_lut": "brdf_lut.exr",
            "sh": "sh.json",
            "settings": asdict(result.settings),
        },
    )

