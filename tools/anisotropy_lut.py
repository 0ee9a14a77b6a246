"""The anisotropic environment BRDF table (matedit/ibl/anisotropy_lut.py) shipped in the package.

    python tools/anisotropy_lut.py --regen   recompute it and rewrite matedit/ibl/anisotropy_dfg.npy
    python tools/anisotropy_lut.py --check   recompute it and compare with the shipped file

Deterministic quadrature in float64, stored as float32 (~60 s on one core).
tests/test_ibl_anisotropy_lut.py recomputes sample cells and compares them with the file.
"""

from __future__ import annotations

import io
import sys
import time

import numpy as np


def main(argv: list[str]) -> int:
    from matedit.ibl.anisotropy_lut import ANISOTROPY_LUT_PATH, generate
    from matedit.io.atomic import atomic_write_bytes

    if not argv or argv[0] not in ("--regen", "--check"):
        print(__doc__)
        return 2
    t0 = time.perf_counter()
    table = generate()
    print(f"generated {table.shape} in {time.perf_counter() - t0:.1f} s")
    if argv[0] == "--regen":
        buf = io.BytesIO()
        np.save(buf, table)
        atomic_write_bytes(ANISOTROPY_LUT_PATH, buf.getvalue())
        print(f"wrote {ANISOTROPY_LUT_PATH}")
        return 0
    shipped = np.load(ANISOTROPY_LUT_PATH)
    same = shipped.shape == table.shape and np.array_equal(shipped, table)
    print("same" if same else f"differs: max |diff| {np.abs(shipped - table).max():.3g}")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
